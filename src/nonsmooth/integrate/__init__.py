"""Integrator kernels (compiled; arrays in, arrays and an integer status out)."""
