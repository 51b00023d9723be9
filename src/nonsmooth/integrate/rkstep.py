"""Pieces of adaptive Runge-Kutta stepping shared by every RK kernel (the generic kernel of
:mod:`.hybrid` and the built-in models' specialised kernels): the step-size controller's
constants and fast power, and the cubic Hermite interpolant of a step with its interior
extrema. The method itself is its coefficient table (:mod:`.tableau`)."""

import math

import numba as nb

from .roots import quad_roots01
from .tableau import RKF45_A, RKF45_B5, RKF45_C, RKF45_E, RKF45_ORDER

_A = RKF45_A
_B = RKF45_B5
_E = RKF45_E
_C = RKF45_C
_NS = _C.shape[0]

_EXPO = 1.0 / (RKF45_ORDER + 1)  # elementary controller h_new = 0.9 h err^(-1/5)
_SAFETY = 0.9
_FM = {"contract", "reassoc"}  # let LLVM fuse and reassociate; NaN/inf semantics are kept
_FAC_MIN = 0.2
_FAC_MAX = 5.0

# log2(m) on [0.5, 1), least-squares quartic (error 2e-4)
_L4, _L3, _L2, _L1, _L0 = (-1.2665305831374971, 5.030988942552058, -8.324856642808804,
                           8.057095881755412, -3.496846056818563)


@nb.njit(cache=True, inline="always")
def pow_fast(x, a):
    """x**a for x > 0 to ~2e-4 relative: step-size factors need a smooth estimate, not libm's
    log and exp on the critical path of every step."""
    m, e = math.frexp(x)
    z = a * (e + (((_L4 * m + _L3) * m + _L2) * m + _L1) * m + _L0) * 0.6931471805599453
    k = math.floor(z * 1.4426950408889634 + 0.5)
    f = z - k * 0.6931471805599453
    ef = 1.0 + f * (1.0 + f * (0.5 + f * (1.0 / 6.0 + f * (1.0 / 24.0 + f * (1.0 / 120.0 + f * (
        1.0 / 720.0))))))
    return math.ldexp(ef, int(k))


@nb.njit(cache=True, inline="always")
def _cubic(a0, a1, a2, a3, s):
    return a0 + s * (a1 + s * (a2 + s * a3))


@nb.njit(cache=True, inline="always")
def _x_extrema(X, V, X1, V1, h, xmax, xmin):
    """(xmax, xmin) updated with the interior extrema of X on the step's cubic Hermite
    interpolant (where V changes sign)."""
    if V * V1 < 0.0:
        dX = X1 - X
        a1 = h * V
        a2 = 3.0 * dX - 2.0 * h * V - h * V1
        a3 = -2.0 * dX + h * V + h * V1
        q1, q2 = quad_roots01(a1, 2.0 * a2, 3.0 * a3)
        for q in (q1, q2):
            if q > 0.0:
                xq = _cubic(X, a1, a2, a3, q)
                xmax = max(xmax, xq)
                xmin = min(xmin, xq)
    return xmax, xmin


@nb.njit(cache=True, inline="always", fastmath=_FM)
def shrink_step(err2, hs, expo):
    """Step size after rejecting a step of length hs with squared error norm err2 (not
    <= 1), for an error estimate of order 1/expo - 1; returns (h, err2 finite)."""
    finite = math.isfinite(err2)
    fac = max(_FAC_MIN, _SAFETY * pow_fast(err2, -0.5 * expo)) if finite else _FAC_MIN
    return hs * fac, finite


@nb.njit(cache=True, inline="always", fastmath=_FM)
def control_step(err2, hs, h, last, rejected, expo):
    """Step-size control after an accepted step of length hs with squared error norm err2,
    for an error estimate of order 1/expo - 1; a shortened last step of an output interval
    does not shrink h. Returns the new h."""
    fac = _SAFETY * pow_fast(max(err2, 1e-30), -0.5 * expo)
    fac = min(_FAC_MAX, max(_FAC_MIN, fac))
    if rejected:
        fac = min(fac, 1.0)
    h_new = hs * fac
    return max(h, h_new) if last else h_new


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _shrink(err2, hs):
    """``shrink_step`` for the RKF45."""
    return shrink_step(err2, hs, _EXPO)


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _control(err2, hs, h, last, rejected):
    """``control_step`` for the RKF45."""
    return control_step(err2, hs, h, last, rejected, _EXPO)


@nb.njit(cache=True, inline="always", fastmath=_FM)
def tangent_stage(A, i, h, n, J, Y, W, KY, cmi):
    """Stage i of an explicit Runge-Kutta step applied to the variational equation Y' = J Y
    (J: the Jacobian at stage i's state; its columns n + slot the field's dependence on the
    continuous memory slots ``cmi``, whose rows of Y are constant in a mode): for each
    column c, KY[i, :, c] = J (Y[:, c] + h sum_{j < i} A[i, j] KY[j, :, c]) plus the memory
    columns times Y's memory rows."""
    ncm = len(cmi)
    for c in range(Y.shape[1]):
        for r in range(n):  # the stages before this one (A is strictly lower triangular)
            acc = 0.0
            for j in range(i):
                acc += A[i, j] * KY[j, r, c]
            W[r] = Y[r, c] + h * acc
        for r in range(n):
            acc = 0.0
            for q in range(n):
                acc += J[r, q] * W[q]
            for q in range(ncm):
                acc += J[r, n + cmi[q]] * Y[n + q, c]
            KY[i, r, c] = acc
