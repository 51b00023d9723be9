"""Integrator kernels (compiled; arrays in, arrays and an integer status out)."""

from .._numba_cache import configure as _configure_cache

_configure_cache()  # before any compiled module of this package is imported
