"""Models: vector fields, switching surfaces and regions as compiled scalar functions."""

from .._numba_cache import configure as _configure_cache

_configure_cache()  # before any compiled module of this package is imported
