"""Roots shared by the kernels: low-degree polynomials (extrema of Hermite cubics) and the
Illinois (modified regula falsi) bracketing steps of event location."""

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


@nb.njit(cache=True, inline="always")
def illinois_point(lo, hi, glo, ghi):
    """Next trial in the bracket [lo, hi] (values glo, ghi of opposite signs): the secant
    point, or the midpoint when that falls outside the bracket."""
    den = ghi - glo
    sm = (lo * ghi - hi * glo) / den if den != 0.0 else 0.5 * (lo + hi)
    if not (lo < sm < hi):
        sm = 0.5 * (lo + hi)
    return sm


@nb.njit(cache=True, inline="always")
def illinois_update(lo, hi, glo, ghi, side, sm, gm):
    """The bracket after the trial (sm, gm): g < 0 on the ``hi`` side, g >= 0 on the ``lo``
    side. The value kept at an end that stays twice in a row is halved (Illinois), so the
    bracket shrinks from both sides. Returns (lo, hi, glo, ghi, side)."""
    if gm < 0.0:
        hi = sm
        ghi = gm
        if side == -1:
            glo *= 0.5
        side = -1
    else:
        lo = sm
        glo = gm
        if side == 1:
            ghi *= 0.5
        side = 1
    return lo, hi, glo, ghi, side
