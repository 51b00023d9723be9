"""Cosine and sine of small angles, shared by the kernels (cheaper than libm for |x| <= 0.5,
where the truncated Taylor series is accurate to < 1e-16)."""

import math

import numba as nb

# Taylor coefficients for cos/sin of small angles (|x| <= 0.5: error < 1e-16)
_C2 = 1.0 / 2.0
_C4 = 1.0 / 12.0
_C6 = 1.0 / 30.0
_C8 = 1.0 / 56.0
_C10 = 1.0 / 90.0
_C12 = 1.0 / 132.0
_C14 = 1.0 / 182.0
_C16 = 1.0 / 240.0
_S3 = 1.0 / 6.0
_S5 = 1.0 / 20.0
_S7 = 1.0 / 42.0
_S9 = 1.0 / 72.0
_S11 = 1.0 / 110.0
_S13 = 1.0 / 156.0
_S15 = 1.0 / 210.0


@nb.njit(cache=True, inline="always")
def cos_sin_small(x):
    """(cos x, sin x); Taylor series for |x| <= 0.5 (error < 1e-16), libm otherwise."""
    if -0.1 <= x <= 0.1:
        x2 = x * x
        c = 1.0 - x2 * _C2 * (1.0 - x2 * _C4 * (1.0 - x2 * _C6 * (1.0 - x2 * _C8)))
        s = x * (1.0 - x2 * _S3 * (1.0 - x2 * _S5 * (1.0 - x2 * _S7 * (1.0 - x2 * _S9))))
        return c, s
    if -0.5 <= x <= 0.5:
        x2 = x * x
        c = 1.0 - x2 * _C2 * (1.0 - x2 * _C4 * (1.0 - x2 * _C6 * (1.0 - x2 * _C8 * (
            1.0 - x2 * _C10 * (1.0 - x2 * _C12 * (1.0 - x2 * _C14 * (1.0 - x2 * _C16)))))))
        s = x * (1.0 - x2 * _S3 * (1.0 - x2 * _S5 * (1.0 - x2 * _S7 * (1.0 - x2 * _S9 * (
            1.0 - x2 * _S11 * (1.0 - x2 * _S13 * (1.0 - x2 * _S15)))))))
        return c, s
    return math.cos(x), math.sin(x)
