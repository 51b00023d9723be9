"""A fold (or a period doubling) of periodic orbits continued in two parameters as one
extended system, through its turning points, with the cusps of a fold curve located (issue 21,
item 4).

``fold_curve(params, "omega", "omega_s", start=branch) -> xarray.Dataset``
``period_doubling_curve(params, "omega", "F0", start=branch) -> xarray.Dataset``
``grazing_curve(params, "omega", "F0", start=branch) -> xarray.Dataset``

The unknowns are the section point z of a k-periodic orbit and the two parameters (l1, l2);
the equations are the orbit condition and the fold condition,

    P^k(z; l1, l2) - z = 0,    g = det(M - I) = 0    (M = dP^k/dz, the monodromy),

n + 1 equations in n + 2 unknowns: a curve, followed by pseudo-arclength steps (the same
predictor, corrector and step control as :func:`nonsmooth.continuation`, ``continuation._follow``)
in (z, l2, l1). The monodromy comes from the tangent kernel; the derivatives of P in l1, l2 are
central differences of the kernel's map, those of g forward differences of the monodromy
(the corrector converges with them; the residual it drives to zero is exact). Unlike
:func:`nonsmooth.two_parameter_curve`, which re-locates the fold on a fresh branch at each value
of the second parameter and stops where a fold vanishes, the curve turns where it turns in
either parameter and runs through a **cusp**, where two folds meet and the hysteresis between
them vanishes: there the curve's projection on (l1, l2) reverses, both parameter components of
its tangent changing sign within one step. A cusp is reported at the zero of the parameter
speed, interpolated between the two points that bracket it.

A period doubling is followed on the same system with the flip condition det(M + I) = 0 in
place of the fold's, a grazing with max X - contact level = 0. The fold condition det(M - I) = 0 also holds at a multiplier 1 that is not a fold (a
transcritical or pitchfork point): the curve follows whatever has a multiplier 1.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from .. import status as st
from ..errors import ParameterError
from ..io import apply_state_units, components, provenance_attrs
from ..kernels import new_state, output_buffers, run
from ..models.base import KERNEL_GENERIC
from ..simulate import component_variables
from ..tangent import TangentSetup, period_map
from .continuation import (FOLD, GRAZING, LOCATE_TOL, NEIMARK_SACKER, PERIOD_DOUBLING,
                           _accepted, _follow, bordered_step, branch_arguments, locate_on_arc)
from .stability import _active, _section_state


class _FoldBranch:
    """The extended system at parameter indices (i1, i2): coordinates y = (z, l2), then l1."""

    def __init__(self, setup: TangentSetup, p0, i1: int, i2: int, k: int, tol: float,
                 mu: float = 1.0):
        self.setup, self.p0, self.i1, self.i2, self.k, self.tol = setup, p0, i1, i2, k, tol
        self.mu = mu  # the critical multiplier: 1 (fold), -1 (period doubling), None (NS)
        self.N = setup.N + 1
        self.template = None

    def p(self, l1, l2):
        p = self.p0.copy()
        p[self.i1] = l1
        p[self.i2] = l2
        return p

    def _map(self, z, l1, l2):
        """(P(z) - z, M, g, start state) or None."""
        p = self.p(l1, l2)
        s0 = _section_state(self.setup, p, z, self.template)
        s1, M, code, bufs = period_map(self.setup, p, s0, self.k)
        if code != st.OK:
            return None
        return self.setup.z_of(s1) - z, M, self._test(M, bufs, l1, l2), s0

    def _test(self, M, bufs, l1, l2):
        """The curve's test function g at a point (monodromy M, the period's outputs)."""
        act = _active(M, self.setup.n)
        Ma = M[np.ix_(act, act)]
        if self.mu is None:  # Neimark-Sacker: a pair of multipliers with product 1
            ev = np.linalg.eigvals(Ma)
            g = 1.0
            for i in range(len(ev)):
                for j in range(i + 1, len(ev)):
                    g *= ev[i] * ev[j] - 1.0
            return float(np.real(g))
        return float(np.linalg.det(Ma - self.mu * np.eye(len(Ma))))

    def _ends(self, z, l1, l2, s0):
        s = _section_state(self.setup, self.p(l1, l2), z, s0)
        if run(KERNEL_GENERIC, self.setup.fns, self.p(l1, l2), self.setup.opts, s, 1, self.k,
               0, *output_buffers(0)) != st.OK:
            return None
        return self.setup.z_of(s)

    def evaluate(self, w, l1):
        """(G, J, None, start state, M): G = (P - z, g) at (z, l2) = w and l1 (g =
        det(M - mu I)), J its Jacobian
        in (z, l2, l1) ((N + 1) x (N + 2)); None when a trajectory fails."""
        Nz = self.setup.N
        z, l2 = w[:Nz], float(w[Nz])
        base = self._map(z, l1, l2)
        if base is None:
            return None
        F, M, g, s0 = base
        J = np.zeros((Nz + 1, Nz + 2))
        J[:Nz, :Nz] = M - np.eye(Nz)
        for col, (a, b) in ((Nz, (0.0, 1.0)), (Nz + 1, (1.0, 0.0))):  # l2, then l1
            h = 1e-7 * max(1.0, abs(l1 if a else l2))
            hi = self._ends(z, l1 + a * h, l2 + b * h, s0)
            lo = self._ends(z, l1 - a * h, l2 - b * h, s0)
            if hi is None or lo is None:
                return None
            J[:Nz, col] = (hi - lo) / (2.0 * h)
        for j in range(Nz + 2):  # dg: forward differences of det(M - mu I)
            h = 1e-6 * max(1.0, abs(z[j]) if j < Nz else abs(l2 if j == Nz else l1))
            zz = z.copy()
            ll1, ll2 = l1, l2
            if j < Nz:
                zz[j] += h
            elif j == Nz:
                ll2 += h
            else:
                ll1 += h
            other = self._map(zz, ll1, ll2)
            if other is None:
                return None
            J[Nz, j] = (other[2] - g) / h
        return np.r_[F, g], J, None, s0, M

    def correct(self, y_pred, t, base=None, max_iter=12):
        """Newton onto G = 0 in the hyperplane t . (y - y_pred) = 0: (y, evaluation, its) or
        None."""
        y = y_pred.copy()
        N = self.N
        for it in range(1, max_iter + 1):
            ev = self.evaluate(y[:N], y[N])
            if ev is None:
                return None
            G, J = ev[0], ev[1]
            d = bordered_step(J, t, G, t @ (y - y_pred))
            if d is None:
                return None
            y += d
            small = np.linalg.norm(G) <= self.tol * (1.0 + np.linalg.norm(y[:N - 1]))
            if small and np.linalg.norm(d) <= 1e3 * self.tol * (1.0 + np.linalg.norm(y)):
                return _accepted(self, y, it)
        return None

    def tangent(self, ev, t_prev):
        J = ev[1]
        try:
            v = np.linalg.solve(np.vstack([J, t_prev[None, :]]), np.r_[np.zeros(len(J)), 1.0])
        except np.linalg.LinAlgError:
            v = t_prev.copy()
        return v / np.linalg.norm(v)

    def features(self, y, ev, t):
        M = ev[4]
        act = _active(M, self.setup.n)
        mu = np.linalg.eigvals(M[np.ix_(act, act)])
        mu = mu[np.argsort(-np.abs(mu), kind="stable")]
        return dict(mu=mu, t=t.copy(), tests={FOLD: math.nan, PERIOD_DOUBLING: math.nan,
                                              NEIMARK_SACKER: math.nan, GRAZING: math.nan})


class _GrazingBranch(_FoldBranch):
    """The extended system of a grazing: the orbit condition and g = max X over the orbit
    (its interior extrema, located by the kernel) - the model's contact level."""

    def __init__(self, setup, p0, i1, i2, k, tol, level):
        super().__init__(setup, p0, i1, i2, k, tol)
        self.level = level  # (l1, l2) -> the contact level there

    def _test(self, M, bufs, l1, l2):
        return float(np.max(bufs[4])) - self.level(l1, l2)


#: codimension-two points on a curve: (kind of curve, test crossing zero) -> name. The tests,
#: over the multipliers R other than the curve's critical one: prod(R - 1) (another multiplier
#: 1), prod(R + 1) (another -1), prod over complex pairs of (mu_i mu_j - 1) (a pair on the unit
#: circle).
CODIM2_NAMES = ("one_to_one_resonance", "fold_flip", "fold_neimark_sacker",
                "one_to_two_resonance", "flip_neimark_sacker", "grazing_fold", "grazing_flip",
                "grazing_neimark_sacker")
_CODIM2 = {(FOLD, 0): 0, (FOLD, 1): 1, (FOLD, 2): 2,
           (PERIOD_DOUBLING, 0): 1, (PERIOD_DOUBLING, 1): 3, (PERIOD_DOUBLING, 2): 4,
           (GRAZING, 0): 5, (GRAZING, 1): 6, (GRAZING, 2): 7}


def _codim2_tests(mu, kind):
    """The three test functions of a point's multipliers (see CODIM2_NAMES)."""
    mu = np.asarray(mu)
    if kind in (FOLD, PERIOD_DOUBLING) and len(mu):
        crit = 1.0 if kind == FOLD else -1.0
        mu = np.delete(mu, int(np.argmin(np.abs(mu - crit))))
    real = mu[np.abs(mu.imag) <= 1e-12 * np.maximum(1.0, np.abs(mu))].real
    pairs = mu[mu.imag > 1e-12 * np.maximum(1.0, np.abs(mu))]
    return (float(np.prod(real - 1.0)), float(np.prod(real + 1.0)),
            float(np.prod(np.abs(pairs) ** 2 - 1.0)) if len(pairs) else math.nan)


def _codim2(br, pts, kind, N):
    """(type, l1, l2, index) of each codimension-two point: a test of CODIM2_NAMES changes
    sign between points i and i + 1; located by the Illinois method on the arclength from
    point i along its tangent, every trial point corrected onto the curve (as the special
    points of ``continuation``), to LOCATE_TOL in the arclength; by linear interpolation of
    the test where a trial point does not converge."""
    out = []
    tests = [_codim2_tests(f["mu"], kind) for _, f in pts]
    for i in range(len(pts) - 1):
        for j in range(3):
            a, b = tests[i][j], tests[i + 1][j]
            if math.isfinite(a) and math.isfinite(b) and a * b < 0.0:
                y = _locate_codim2(br, pts[i], pts[i + 1][0], kind, j, a, b)
                if y is None:
                    s = a / (a - b)
                    y = pts[i][0] + s * (pts[i + 1][0] - pts[i][0])
                out.append((_CODIM2[(kind, j)], float(y[N]), float(y[N - 1]), i))
    return out


class _NotFinite(Exception):
    pass


def _locate_codim2(br, start, y_end, kind, j, a, b):
    """The point between ``start`` = (y0, features) and ``y_end`` where codimension-two test
    ``j`` is zero (``continuation.locate_on_arc`` along the start's tangent), or None."""
    y0, f0 = start
    t0 = f0["t"]
    ds = float(t0 @ (y_end - y0))  # the corrector keeps t0 . (y - y0) = the step
    if not ds > 0.0:
        return None

    def test(f):
        g = _codim2_tests(f["mu"], kind)[j]
        if not math.isfinite(g):
            raise _NotFinite
        return g
    try:
        got = locate_on_arc(br, y0, t0, ds, a, b, test, lambda width, y: width <= LOCATE_TOL)
    except _NotFinite:
        return None
    return None if got is None else got[0]


def _cusps(pts, N):
    """(l1, l2, index) of each cusp: the curve's velocity in (l1, l2) (the parameter part of
    its unit tangent) turns by more than a right angle between points i and i + 1 (at a cusp
    it vanishes and reverses; at an ordinary turning point only one component vanishes and it
    turns smoothly); the cusp at the interpolated zero of its component along the velocity at
    point i."""
    out = []
    for i in range(len(pts) - 1):
        (ya, fa), (yb, fb) = pts[i], pts[i + 1]
        va = np.array([fa["t"][N], fa["t"][N - 1]])
        vb = np.array([fb["t"][N], fb["t"][N - 1]])
        da, db = float(va @ va), float(va @ vb)
        if db < 0.0 < da:
            s = da / (da - db)
            y = ya + s * (yb - ya)
            out.append((float(y[N]), float(y[N - 1]), i))
    return out


def fold_curve(params, param: str, param2: str, *, start, special: int | None = None,
               direction: str = "up", step: float = 0.01, max_step: float | None = None,
               bounds=None, bounds2=None, max_points: int = 300, tol: float = 1e-9,
               rtol: float = 1e-10, atol: float = 1e-12) -> xr.Dataset:
    """The fold of ``start`` (a :func:`nonsmooth.continuation` Dataset in ``param`` of the same
    model and method: its fold special point ``special``, default the first) continued in
    (``param``, ``param2``) as the extended system of the module documentation, from the
    value of ``param2`` in ``params``, ``direction`` "up" (``param2`` increasing at first) or
    "down", with arclength steps from ``step`` (adapted up to ``max_step``, default 10 x) until
    ``param`` leaves ``bounds`` or ``param2`` leaves ``bounds2`` (default: unbounded),
    ``max_points`` or the corrector fails. The branch's section phase is kept.

    Codimension-two points are located where another multiplier crosses 1 (a 1:1 resonance),
    -1 (fold-flip) or a complex pair the unit circle (fold-Neimark-Sacker): over ``codim2``,
    ``codim2_type`` (flags), ``codim2_<param>``, ``codim2_<param2>``, ``codim2_after_point``;
    the period-doubling and grazing curves likewise (fold-flip, 1:2 resonance,
    flip-Neimark-Sacker; grazing-fold, grazing-flip, grazing-Neimark-Sacker).

    Returns a Dataset over ``point``: ``<param>``, ``<param2>``, the section point
    (``X_section``, ``V_section``, ...), the multipliers (``multiplier_real/imag/abs``, one of
    them 1 on the curve), and over ``cusp`` the located cusps (``cusp_<param>``,
    ``cusp_<param2>``, ``cusp_after_point``); attrs ``status``."""
    return _special_curve(FOLD, params, param, param2, start, special, direction, step,
                          max_step, bounds, bounds2, max_points, tol, rtol, atol)


def period_doubling_curve(params, param: str, param2: str, *, start,
                          special: int | None = None, direction: str = "up", step: float = 0.01,
                          max_step: float | None = None, bounds=None, bounds2=None,
                          max_points: int = 300, tol: float = 1e-9, rtol: float = 1e-10,
                          atol: float = 1e-12) -> xr.Dataset:
    """A period doubling (flip) of ``start``'s branch continued in (``param``, ``param2``):
    as :func:`fold_curve` with the flip condition det(M + I) = 0 (a multiplier -1) in place of
    the fold's. The same arguments and Dataset (``cusp`` empty: cusps are meetings of folds;
    the multiplier -1 is in ``multiplier_real``)."""
    return _special_curve(PERIOD_DOUBLING, params, param, param2, start, special, direction,
                          step, max_step, bounds, bounds2, max_points, tol, rtol, atol)


def neimark_sacker_curve(params, param: str, param2: str, *, start,
                         special: int | None = None, direction: str = "up", step: float = 0.01,
                         max_step: float | None = None, bounds=None, bounds2=None,
                         max_points: int = 300, tol: float = 1e-9, rtol: float = 1e-10,
                         atol: float = 1e-12) -> xr.Dataset:
    """A Neimark-Sacker (torus) bifurcation of ``start``'s branch continued in (``param``,
    ``param2``): as :func:`fold_curve` with the condition prod_{i<j} (mu_i mu_j - 1) = 0 (a
    pair of multipliers with product 1: a complex pair on the unit circle; its derivatives by
    differences of the eigenvalues, which are smooth away from a double multiplier) in place
    of the fold's. A real pair with product 1 (a neutral saddle) satisfies it too."""
    return _special_curve(NEIMARK_SACKER, params, param, param2, start, special, direction,
                          step, max_step, bounds, bounds2, max_points, tol, rtol, atol)


def grazing_curve(params, param: str, param2: str, *, start, special: int | None = None,
                  direction: str = "up", step: float = 0.01, max_step: float | None = None,
                  bounds=None, bounds2=None, max_points: int = 300, tol: float = 1e-9,
                  rtol: float = 1e-10, atol: float = 1e-12) -> xr.Dataset:
    """A grazing of ``start``'s branch (the orbit's largest X reaches the model's contact
    level, ``Model.contact_level``) continued in (``param``, ``param2``): as :func:`fold_curve`
    with the grazing condition max X - level = 0 (max X over the orbit, interior extrema
    located by the kernel; its derivatives by forward differences, taken on whichever side of
    the contact they fall) in place of the fold's. This is the first contact of an orbit that
    has none (as ``continuation`` locates it): an orbit already in contact has other extrema
    that graze, which this condition does not follow. The same arguments and Dataset (``cusp``
    empty; ``max_X`` per point)."""
    return _special_curve(GRAZING, params, param, param2, start, special, direction, step,
                          max_step, bounds, bounds2, max_points, tol, rtol, atol)


def _special_curve(kind, params, param, param2, start, special, direction, step, max_step,
                   bounds, bounds2, max_points, tol, rtol, atol):
    from ..kernels import Solver
    from ..simulate import check_params
    what = {FOLD: "fold", PERIOD_DOUBLING: "period doubling", GRAZING: "grazing",
            NEIMARK_SACKER: "Neimark-Sacker point"}[kind]
    params = check_params(params)
    m = params.model
    p1, p2 = m.param(param).name, m.param(param2).name
    if p1 == p2:
        raise ParameterError(f"param2: must differ from param ({p1})")
    if not isinstance(start, xr.Dataset) or "special_type" not in start or \
            start.attrs.get("param") != p1:
        raise ParameterError(f"start: expected the Dataset of continuation(..., {p1!r}, ...) "
                             f"with a {what}")
    if start.attrs.get("model") != m.name:
        raise ParameterError(f"start: a branch of model {start.attrs.get('model')}, not {m.name}")
    found = np.flatnonzero(start.special_type.values == kind)
    if special is None:
        if found.size == 0:
            raise ParameterError(f"start: the branch has no {what}")
        special = int(found[0])
    elif not (0 <= special < start.sizes["special"]) or start.special_type.values[special] != kind:
        raise ParameterError(f"special: {special!r} is not a {what} of the branch ({what}s: "
                             f"{found.tolist()})")
    if "section_moved" in start.attrs or "section" in start.attrs:
        raise ParameterError("start: a branch whose section moved, or of limit cycles, is not "
                             "supported here")
    if kind == GRAZING and m.contact_level is None:
        raise ParameterError(f"start: model {m.name} declares no contact level "
                             f"(Model.contact_level): no grazing to follow")
    _, _, max_points, step, max_step, tol, lo, hi = branch_arguments(
        params, p1, 1, max_points, step, max_step, tol, direction, bounds, False)
    lo2, hi2 = branch_arguments(params, p2, 1, max_points, step, max_step, tol, direction,
                                 bounds2, False)[6:] if bounds2 is not None else (-math.inf,
                                                                                  math.inf)
    k = int(start.attrs.get("k", 1))
    method = str(start.attrs.get("method", "exact"))
    solver = Solver(method=method, rtol=rtol, atol=atol, model=m,
                    section_phase=float(start.attrs.get("section_phase", 0.0)))
    setup = TangentSetup(solver)
    l1 = float(start[f"special_{p1}"].values[special])
    l2 = float(getattr(params, p2))
    params = params.replace(**{p1: l1})
    p0 = params.pack()
    if kind == GRAZING:
        base = params

        def level(a, b):
            return float(m.contact_level(base.replace(**{p1: a, p2: b})))
        br = _GrazingBranch(setup, p0, m.index[p1], m.index[p2], k, tol, level)
    else:
        br = _FoldBranch(setup, p0, m.index[p1], m.index[p2], k, tol,
                         mu={FOLD: 1.0, PERIOD_DOUBLING: -1.0}.get(kind))
    Nz = setup.N
    z0 = np.zeros(Nz)
    zc = np.asarray(components(start, "special_", "_section").values[special], dtype=float)
    z0[:len(zc)] = zc  # (continuous memory, if any, starts from 0 and is mapped at once)
    br.template = new_state(0.0, 0.0)  # mode -1: classified at each point
    # the point from the branch, refined on the extended system at fixed l2 (a step of zero
    # length along l2)
    t = np.zeros(Nz + 2)
    t[Nz] = 1.0
    y = np.r_[z0, l2, l1]
    got = br.correct(y, t)
    if got is None:
        raise ParameterError(f"start: the {what} at {p1} = {l1:g} does not converge on the "
                             f"extended system")
    y, ev, _ = got
    sign = 1.0 if direction == "up" else -1.0
    t = br.tangent(ev, sign * t)
    if t[Nz] * sign < 0:
        t = -t
    pts = [(y, br.features(y, ev, t))]
    _, _, _, status = _follow(br, pts, t, step, max_step, max_points, lo, hi,
                              bounds2=(Nz, lo2, hi2))
    if status == "left bounds2":
        status = f"left the bounds of {p2}"
    cusps = _cusps(pts, Nz + 1) if kind == FOLD else []
    ds = _dataset(params, solver, p1, p2, k, pts, cusps, status, Nz,
                  {FOLD: "fold_curve", PERIOD_DOUBLING: "period_doubling_curve",
                   GRAZING: "grazing_curve", NEIMARK_SACKER: "neimark_sacker_curve"}[kind])
    c2 = _codim2(br, pts, kind, Nz + 1) if kind != NEIMARK_SACKER else []
    s1, s2 = m.param(p1), m.param(p2)
    ds["codim2_type"] = ("codim2", np.array([c[0] for c in c2], np.int8), {
        "long_name": "codimension-two point on the curve",
        "flag_values": np.arange(len(CODIM2_NAMES), dtype=np.int8),
        "flag_meanings": " ".join(CODIM2_NAMES)})
    ds["codim2_" + p1] = ("codim2", np.array([c[1] for c in c2], float), {
        "long_name": f"{p1} at the codimension-two point", "units": s1.units})
    ds["codim2_" + p2] = ("codim2", np.array([c[2] for c in c2], float), {
        "long_name": f"{p2} at the codimension-two point", "units": s2.units})
    ds["codim2_after_point"] = ("codim2", np.array([c[3] for c in c2], np.int64), {
        "long_name": "the point lies between this point and the next"})
    ds.attrs["n_codim2"] = len(c2)
    if kind == GRAZING:  # max X on the curve: the contact level there, to the tolerance
        def max_x(y):
            got = br._map(y[:Nz], y[Nz + 1], y[Nz])
            return br.level(y[Nz + 1], y[Nz]) + got[2] if got is not None else math.nan
        ds["max_X"] = ("point", np.array([max_x(y) for y, _ in pts]), {
            "long_name": "largest X over the orbit (interior extrema included)"})
    return ds


def _dataset(params, solver, p1, p2, k, pts, cusps, status, Nz, analysis):
    m = params.model
    ys = np.array([y for y, _ in pts])
    mu = np.array([f["mu"] for _, f in pts])
    U = ys[:, :min(Nz, m.n)]
    s1, s2 = m.param(p1), m.param(p2)
    ds = xr.Dataset(
        {
            p1: ("point", ys[:, Nz + 1], {"long_name": s1.long_name or p1, "units": s1.units}),
            p2: ("point", ys[:, Nz], {"long_name": s2.long_name or p2, "units": s2.units}),
            "X_section": ("point", U[:, 0], {"long_name": "X at the section (t = kT)"}),
            "V_section": ("point", U[:, 1], {"long_name": "V at the section (t = kT)"}),
            "multiplier_real": (("point", "multiplier"), mu.real, {"units": "1"}),
            "multiplier_imag": (("point", "multiplier"), mu.imag, {"units": "1"}),
            "multiplier_abs": (("point", "multiplier"), np.abs(mu), {"units": "1"}),
            "cusp_" + p1: ("cusp", np.array([c[0] for c in cusps], float),
                           {"long_name": f"{p1} at the cusp", "units": s1.units}),
            "cusp_" + p2: ("cusp", np.array([c[1] for c in cusps], float),
                           {"long_name": f"{p2} at the cusp", "units": s2.units}),
            "cusp_after_point": ("cusp", np.array([c[2] for c in cusps], np.int64),
                                 {"long_name": "the cusp lies between this point and the next"}),
        },
        coords={"point": np.arange(len(pts)), "multiplier": np.arange(1, mu.shape[1] + 1),
                "cusp": np.arange(len(cusps))},
        attrs=provenance_attrs(params, solver, swept=(p1, p2), analysis=analysis,
                               param=p1, param2=p2, k=k, status=status, n_cusps=len(cusps)),
    )
    ds.update(component_variables(m, ("point",), U, suffix="_section",
                                  what=" at the section (t = kT)"))
    return apply_state_units(ds, m)
