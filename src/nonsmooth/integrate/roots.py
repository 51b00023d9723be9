"""Roots of low-degree polynomials, shared by the kernels (extrema of Hermite cubics)."""

import math

import numba as nb


@nb.njit(cache=True, inline="always")
def quad_roots01(c0, c1, c2):
    """Roots of c0 + c1 s + c2 s^2 in the open interval (0, 1); -1.0 where there is none."""
    r1 = -1.0
    r2 = -1.0
    if c2 == 0.0:
        if c1 != 0.0:
            s = -c0 / c1
            if 0.0 < s < 1.0:
                r1 = s
        return r1, r2
    disc = c1 * c1 - 4.0 * c2 * c0
    if disc < 0.0:
        return r1, r2
    sq = math.sqrt(disc)
    q = -0.5 * (c1 + sq) if c1 >= 0.0 else -0.5 * (c1 - sq)
    if q != 0.0:
        s = q / c2
        if 0.0 < s < 1.0:
            r1 = s
        s = c0 / q
        if 0.0 < s < 1.0:
            r2 = s
    return r1, r2
