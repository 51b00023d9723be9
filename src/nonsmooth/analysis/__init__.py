"""Analyses: one module each, a per-point core plus a sweep, each returning an xarray.Dataset."""
