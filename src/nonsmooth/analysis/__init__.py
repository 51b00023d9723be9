"""Analyses: one module each, a per-point core plus a sweep, each returning an xarray.Dataset."""

from .._numba_cache import configure as _configure_cache

_configure_cache()  # before any compiled module of this package is imported
