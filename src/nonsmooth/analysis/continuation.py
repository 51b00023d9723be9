"""Continuation of periodic orbits in one parameter, through folds, with their stability and
special points (fold, period doubling, Neimark-Sacker, grazing), for every model.

A k-periodic orbit is a fixed point z of the k-fold stroboscopic map P^k(z; lam) (z: the section
point, :mod:`nonsmooth.tangent`). Pseudo-arclength continuation follows the curve
F(z, lam) = P^k(z; lam) - z = 0 in (z, lam): the tangent t spans the null space of
[dF/dz, dF/dlam] = [M - I, dP/dlam] (M the monodromy from the tangent kernel, saltation matrices
included; dP/dlam by central differences of the map), the predictor steps ds along t, and
Newton's corrector solves F = 0 with t . (y - y_pred) = 0, so the branch turns at folds and
goes on along the unstable part. The step adapts to the corrector's iterations.

Special points are sign changes of test functions between consecutive points, located by the
Illinois method on the arclength (each trial point corrected onto the branch):

* fold (saddle-node): the lam-component of the tangent (a multiplier crosses +1);
* period doubling: det(M + I) (a multiplier crosses -1);
* Neimark-Sacker: mu_1 mu_2 - 1 over the complex pair (a pair crosses the unit circle);
* grazing: max X - contact level (the model's ``contact_level``; the orbit first touches the
  switching surface): the multipliers may jump there, as the contact sequence changes.

``special_jump`` says when the multipliers jumped across a located point instead of passing
through the unit circle (a non-smooth transition: the test function changed sign by a jump).

Where the orbit starts or stops visiting a mode (a sliding bifurcation), the branch has a corner
and the corrector fails along the old tangent at every step; :func:`_corner` finds the other
side, locates the corner by bisection and records it as a fold (the parameter turns back) or a
grazing, with ``special_jump`` = 1.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from .. import status as st
from ..checks import check_positive
from ..errors import ParameterError
from ..integrate.roots import illinois_point, illinois_update
from ..io import apply_state_units, provenance_attrs
from ..kernels import output_buffers, run
from ..models.base import KERNEL_GENERIC
from ..simulate import (check_float, check_int, component_variables, start_trajectory,
                        state_u)
from ..tangent import TangentSetup, period_map
from .stability import NEUTRAL, _active, _section_state, periodic_orbit

#: Special-point types (CF flag values of ``special``).
FOLD, PERIOD_DOUBLING, NEIMARK_SACKER, GRAZING = 1, 2, 3, 4
SPECIAL_NAMES = {0: "none", FOLD: "fold", PERIOD_DOUBLING: "period_doubling",
                 NEIMARK_SACKER: "neimark_sacker", GRAZING: "grazing"}
LOCATE_TOL = 1e-10  # special points: |delta lam| of the bracketing pair
#: A located fold / PD / NS whose critical multiplier is farther than this from +1 / -1 / the
#: unit circle was crossed by a jump of the multipliers (a non-smooth, border-collision
#: transition, e.g. at a grazing), not through the circle.
JUMP_TOL = 1e-4
MIN_STEP = 1.0 / 4096  # smallest arclength step, relative to ``step``
_SAMPLES = 100  # samples per period of the orbit for max/min X and the contact fraction


def _accepted(br, y, it):
    """A converged corrector's point y (after ``it`` iterations) of branch ``br``, evaluated
    once more: (y, evaluation, it), its start state the next corrections' template; None if
    the evaluation fails."""
    ev = br.evaluate(y[:br.N], y[br.N])
    if ev is None:
        return None
    br.template = ev[3]
    return y, ev, it


def bordered_step(J, t, F, h):
    """The Newton step d of the bordered system [J; t] d = -[F; h] (the corrector in the
    hyperplane normal to the tangent t), or None when it is singular or not finite."""
    try:
        d = np.linalg.solve(np.vstack([J, t[None, :]]), -np.r_[F, h])
    except np.linalg.LinAlgError:
        return None
    return d if np.all(np.isfinite(d)) else None


class _Branch:
    """The map, its derivatives and the corrector at one parameter index."""

    def __init__(self, setup: TangentSetup, p0: np.ndarray, index: int, k: int, tol: float,
                 level):
        self.setup, self.p0, self.index, self.k, self.tol, self.level = (setup, p0, index, k,
                                                                         tol, level)
        self.N = setup.N  # coordinates of a point: the section point (state and memory)
        self.template = None

    def p(self, lam):
        p = self.p0.copy()
        p[self.index] = lam
        return p

    def evaluate(self, z, lam):
        """F, M (N x N), dF/dlam, the end state and the per-period buffers at (z, lam), or
        None when a trajectory fails."""
        s0 = _section_state(self.setup, self.p(lam), z, self.template)
        s1, M, code, bufs = period_map(self.setup, self.p(lam), s0, self.k)
        if code != st.OK:
            return None
        h = 1e-7 * max(1.0, abs(lam))
        ends = []
        for sg in (1.0, -1.0):
            s = _section_state(self.setup, self.p(lam + sg * h), z, s0)
            if run(KERNEL_GENERIC, self.setup.fns, self.p(lam + sg * h), self.setup.opts, s, 1,
                   self.k, 0, *output_buffers(0)) != st.OK:
                return None
            ends.append(self.setup.z_of(s))
        Fl = (ends[0] - ends[1]) / (2.0 * h)
        return self.setup.z_of(s1) - z, M, Fl, s0, bufs

    def correct(self, y_pred, t, base=None, max_iter=12):
        """Newton's corrector onto F = 0 in the hyperplane t . (y - y_pred) = 0. Returns (y,
        evaluation, iterations) or None. With ``base`` (the corrected point the prediction
        steps from) the corrected point must lie within three steps (|y_pred - base|) of its
        prediction: a corrector that wanders farther may land on another branch (a forced
        Stribeck branch in F0 jumped 0.77 in one step of 0.045), and a shorter step is tried
        instead. (Near a grazing a correction of 1.9 steps is genuine: table3's branch in
        omega.)"""
        y = y_pred.copy()
        N = self.setup.N
        reach = math.inf if base is None else (
            3.0 * np.linalg.norm(y_pred - base)
            + 1e3 * self.tol * (1.0 + np.linalg.norm(y_pred)))
        for it in range(1, max_iter + 1):
            ev = self.evaluate(y[:N], y[N])
            if ev is None:
                return None
            F = ev[0]
            act, ia, J = self.jacobian(ev)
            tt = np.concatenate([t[ia], t[N:]])
            d = bordered_step(J, tt, F[ia], tt @ (np.concatenate([y[ia], y[N:]])
                                                  - np.concatenate([y_pred[ia], y_pred[N:]])))
            if d is None:
                return None
            y[ia] += d[:-1]
            y[N] += d[-1]
            ina = np.flatnonzero(~act)
            y[ina] += F[ina]  # memory rewritten before it is read: its mapped value
            if np.hypot(np.linalg.norm(y[ia] - y_pred[ia]), y[N] - y_pred[N]) > reach:
                return None  # wandered off: a shorter step is tried
            small = np.linalg.norm(F[ia]) <= self.tol * (1.0 + np.linalg.norm(y[:N]))
            if small and np.linalg.norm(d) <= 1e3 * self.tol * (1.0 + np.linalg.norm(y)):
                return _accepted(self, y, it)
        return None

    def jacobian(self, ev):
        """(active mask, active indices, [M - I, dF/dlam] on the active coordinates) of an
        evaluation (memory rewritten before it is read is not a coordinate, see ``_active``)."""
        F, M, Fl, s0, _ = ev
        act = _active(M, self.setup.n)
        ia = np.flatnonzero(act)
        return act, ia, np.hstack([(M - np.eye(len(M)))[np.ix_(ia, ia)], Fl[ia, None]])

    def tangent(self, ev, t_prev):
        """Unit tangent at a corrected point, oriented along t_prev."""
        N = self.setup.N
        act, ia, J = self.jacobian(ev)
        tp = np.concatenate([t_prev[ia], t_prev[N:]])
        try:
            v = np.linalg.solve(np.vstack([J, tp[None, :]]), np.r_[np.zeros(len(ia)), 1.0])
        except np.linalg.LinAlgError:
            v = tp.copy()
        v /= np.linalg.norm(v)
        t = np.zeros(N + 1)
        t[ia] = v[:-1]
        t[N] = v[-1]
        return t

    def features(self, y, ev, t):
        """Multipliers, test functions and orbit features of a corrected point."""
        F, M, Fl, s0, bufs = ev
        act = _active(M, self.setup.n)
        Ma = M[np.ix_(act, act)]
        mu = np.linalg.eigvals(Ma)
        mu = mu[np.argsort(-np.abs(mu), kind="stable")]
        n_s = self.k * _SAMPLES
        ob = output_buffers(n_s)
        s = s0.copy()
        code = run(KERNEL_GENERIC, self.setup.fns, self.p(y[-1]), self.setup.opts, s, _SAMPLES,
                   0, n_s, *ob)
        Xs, Vs, R, Mk, Xmax, Xmin = ob
        cm = self.setup.model.contact_modes
        contact = float(np.mean(((1 << R.astype(np.int64)) & cm) != 0)) if cm else 0.0
        mx = float(np.max(Xmax)) if code == st.OK else math.nan
        visited = int(np.bitwise_or.reduce(Mk)) if code == st.OK else None
        mn = float(np.min(Xmin)) if code == st.OK else math.nan
        ns_test = 1.0  # prod_{i<j} (mu_i mu_j - 1): real; zero when a pair's product is 1
        for i in range(len(mu)):
            for j in range(i + 1, len(mu)):
                ns_test *= mu[i] * mu[j] - 1.0
        ns_test = float(np.real(ns_test))
        tests = {FOLD: t[-1],
                 PERIOD_DOUBLING: float(np.real(np.prod(mu + 1.0))),
                 NEIMARK_SACKER: ns_test,
                 GRAZING: mx - self.level if self.level is not None else math.nan}
        sec = (bufs[0][:self.k], bufs[1][:self.k], bufs[6][:self.k])
        return dict(mu=mu, max_X=mx, min_X=mn, contact=contact, tests=tests, section=sec,
                    modes=visited)


def continuation(params, param: str, *, start=None, k: int = 1, x0: float = 0.0,
                 v0: float = 0.0, transient: int = 0, direction: str = "up", step: float = 0.01,
                 max_step: float | None = None, bounds=None, max_points: int = 400,
                 method: str = "exact", tol: float = 1e-10, rtol: float = 1e-10,
                 atol: float = 1e-12, section_phase: float = 0.0, u0=None, section=None,
                 max_time: float = 1e4) -> xr.Dataset:
    """Follow a branch of k-periodic orbits in ``param`` from ``params``.

    A self-excited system (a model without forcing, or ``section`` given: an expression or
    (expression, direction) as for :func:`~nonsmooth.limit_cycle`, default "V") has its limit
    cycles followed instead, on that section surface, with their periods as unknowns
    (:func:`nonsmooth.analysis.autonomous.cycle_continuation`: the same arclength steps,
    special points and Dataset, plus ``period``; ``k`` = crossings per cycle, ``transient`` =
    crossings before the first cycle's Newton search, 0: 20; ``max_time`` bounds the time to
    the next crossing).

    The first point is the orbit Newton's shooting finds from (x0, v0) (or ``u0``, every
    component, see ``simulate``; after ``transient`` periods) at ``params``; with ``start=(branch, i)``, a period-doubling point ``i`` of an
    earlier branch Dataset instead (branch switching: the 2k-periodic orbit born there, found
    from the period-k orbit displaced along the eigenvector of the multiplier -1 on the side of
    the PD where it exists; ``k`` is then the earlier branch's k doubled and ``direction`` is
    away from the PD). The branch then runs ``direction`` ("up": ``param`` increasing
    at first, "down") with arclength steps starting at ``step`` (in the units of the
    parameter and the section point, adapted between step x MIN_STEP and ``max_step``, default
    10 x step) until it leaves ``bounds`` (lo, hi), reaches ``max_points``, comes back to its
    first point (a closed branch, an isola: status "closed loop") or cannot continue; it
    turns at corners (a sliding bifurcation, :func:`_corner`).
    Where the corrector fails at every step, the section may sit on an event of the orbit (an
    impact at t = kT makes the map non-smooth): the section is then moved a quarter, a half or
    three quarters of a period on (``_moved_section``) and the branch goes on there; the
    points then have a ``section_phase`` variable and the attrs a ``section_moved`` text.

    Returns a Dataset over ``point``: the parameter, the section points (``X_section``,
    ``V_section`` over ``point``, ``j``; a model with more state components has
    ``<name>_section`` for each), the Floquet multipliers (``multiplier_real/imag/abs``),
    ``stable``, ``max_X``, ``min_X``, ``contact_fraction``, and the located ``special`` points
    over ``special`` (``special_type`` with CF flags, ``special_<param>``, the multiplier
    nearest the crossing and the point index after which it lies); attrs ``status`` (why the
    branch ended)."""
    from ..simulate import check_params
    if section is not None or check_params(params).model.autonomous:
        from .autonomous import cycle_continuation
        if start is not None or section_phase != 0.0:
            raise ParameterError(f"{'start' if start is not None else 'section_phase'}: "
                                 f"branch switching and section phases are for forced orbits, "
                                 f"not limit cycles on a section surface")
        return cycle_continuation(params, param, "V" if section is None else section, k=k,
                                  x0=x0, v0=v0, u0=u0, transient=transient,
                                  direction=direction, step=step, max_step=max_step,
                                  bounds=bounds, max_points=max_points, method=method, tol=tol,
                                  rtol=rtol, atol=atol, max_time=max_time)
    params, solver, p0, opts, state = start_trajectory(params, x0, v0, method, rtol, atol,
                                                       section_phase, u0)
    u_start = state_u(params.model, state)
    param, k, max_points, step, max_step, tol, lo, hi = branch_arguments(
        params, param, k, max_points, step, max_step, tol, direction, bounds, start is None)
    bounds = (lo, hi)
    lam0 = float(getattr(params, param))
    setup = TangentSetup(solver)
    index = params.model.index[param]
    level = params.model.contact_level(params) if params.model.contact_level else None
    br = _Branch(setup, p0, index, k, tol, level)

    if start is not None:
        orb, lam0, k, direction = _doubled_orbit(params, param, start, method, tol, rtol, atol,
                                                       section_phase)
        if not lo <= lam0 <= hi:
            raise ParameterError(f"bounds: ({lo:g}, {hi:g}) exclude the period doubling at "
                                 f"{param} = {lam0:g}")
        params = params.replace(**{param: lam0})
        p0 = params.pack()
        br = _Branch(setup, p0, index, k, tol, level)
    else:
        orb = periodic_orbit(params, k=k, u0=u_start, method=method, transient=transient,
                             tol=tol, rtol=rtol, atol=atol, samples_per_period=1,
                             section_phase=section_phase)
        if orb.attrs["status"] != "converged":
            where = (f"(x0, v0) = ({u_start[0]:g}, {u_start[1]:g})" if len(u_start) == 2
                     else f"u0 = ({', '.join(f'{x:g}' for x in u_start)})")
            raise ParameterError(f"start: no period-{k} orbit found from {where} at {param} = "
                                 f"{lam0:g} ({orb.attrs['status']}); try another start")
    N = setup.N
    s_start = _section_state(setup, p0, setup.z_of(_start_state(setup, p0, orb, state)), state)
    br.template = s_start
    y = np.r_[setup.z_of(s_start), lam0]
    ev = br.evaluate(y[:N], y[N])
    t = np.zeros(N + 1)
    t[N] = 1.0 if direction == "up" else -1.0
    t = br.tangent(ev, t)
    if t[N] * (1.0 if direction == "up" else -1.0) < 0:
        t = -t
    phase = solver.section_phase
    f_start = br.features(y, ev, t)
    f_start["phase"] = phase
    pts = [(y, f_start)]
    moved_to = {"solver": solver}

    def relocate(br, y0, t):
        # an event on the section (e.g. an impact at t = kT) makes the map non-smooth there:
        # move the section by a quarter period and go on from the same orbit
        moved = _moved_section(br, moved_to["solver"], y0, t, step)
        if moved is None:
            return None
        moved_to["solver"], _, br, y0, t, got, ds = moved
        return br, y0, t, got, ds, moved_to["solver"].section_phase

    br, specials, moves, status = _follow(br, pts, t, step, max_step, max_points, lo, hi,
                                          relocate)
    solver = moved_to["solver"]
    ds = _dataset(params, solver, param, k, pts, specials, status, N, direction, bounds)
    if moves:
        ds["section_phase"] = ("point", np.array([f["phase"] for _, f in pts]), {
            "long_name": "forcing phase omega t_s of the section of each point (moved off "
                         "events that fell on the section)", "units": "rad"})
        ds.attrs["section_moved"] = "; ".join(f"after point {i}: to {ph:.6g} rad"
                                              for i, ph in moves)
        ds["special_section_phase"] = ("special", np.array([sp[-1] for sp in specials], float),
                                       {"long_name": "forcing phase of the section where the "
                                                     "special point was located", "units": "rad"})
        ds.attrs["section_phase"] = float(section_phase)
    return ds


def _follow(br, pts, t, step, max_step, max_points, lo, hi, relocate=None, bounds2=None):
    """Pseudo-arclength steps from the last of ``pts`` ((y, features) pairs; y = the branch's
    coordinates, then the parameter) along the unit tangent ``t``, appending each corrected
    point, until ``max_points``, the parameter leaves (lo, hi) (or coordinate i leaves
    (lo2, hi2), ``bounds2`` = (i, lo2, hi2): status "left bounds2"), the branch comes back to its
    first point (:func:`_closes`: "closed loop"), a point's features end it (``end``), or the
    corrector fails even at step x MIN_STEP and neither ``relocate(br, y, t)`` (if given:
    it returns (branch, y, t, corrected point, step, section phase)) nor a corner
    (:func:`_corner`) offers a way on. The step adapts to the corrector's
    iterations; sign changes of the test functions between points are located
    (:func:`_locate`). ``br`` has ``N`` (coordinates), ``correct``, ``tangent`` and
    ``features`` (see :class:`_Branch`). Returns (branch, specials, moves, status)."""
    N = br.N
    phase = pts[-1][1].get("phase")
    specials = []
    moves = []  # (point index, new section phase): where the section was moved off an event
    ds = step
    status = "max_points"
    first, t_first, reach = pts[0][0], t.copy(), 0.0
    while len(pts) < max_points:
        y0, f0 = pts[-1]
        got = None
        while ds >= step * MIN_STEP:
            got = br.correct(y0 + ds * t, t, y0)
            if got is not None:
                break
            ds *= 0.5
        corner = None
        if got is None:
            moved = relocate(br, y0, t) if relocate is not None else None
            if moved is None:
                corner = _corner(br, y0, f0, t, step, 2.0 * ds)
                if corner is None:
                    status = f"cannot continue (the corrector fails even at step x {MIN_STEP:g})"
                    break
                got, ds, t1, sp = corner
                specials.append((sp[0], len(pts) - 1, *sp[1:], phase))
            else:
                br, y0, t, got, ds, phase = moved
                moves.append((len(pts) - 1, phase))
        y1, ev1, iters = got
        if corner is None:
            t1 = br.tangent(ev1, t)
        f1 = br.features(y1, ev1, t1)
        if f1.get("end"):  # the branch ends here (see the branch's ``features``)
            status = f1["end"]
            break
        f1["phase"] = phase
        for typ in (FOLD, PERIOD_DOUBLING, NEIMARK_SACKER, GRAZING):
            a, b = f0["tests"][typ], f1["tests"][typ]
            if corner is None and math.isfinite(a) and math.isfinite(b) and a * b < 0:
                sp = _locate(br, typ, y0, t, ds, a, b)
                if sp is not None and _confirmed(typ, sp[1]):
                    specials.append((typ, len(pts) - 1, *sp, phase))
        pts.append((y1, f1))
        t = t1
        reach = max(reach, float(np.linalg.norm(y0 - first)))
        if not moves and _closes(y0, y1, first, t_first, reach):
            status = "closed loop (the branch came back to its first point: an isola)"
            break
        if not lo <= y1[N] <= hi:
            status = "left the bounds"
            break
        if bounds2 is not None and not bounds2[1] <= y1[bounds2[0]] <= bounds2[2]:
            status = "left bounds2"
            break
        ds = min(max_step, ds * 1.5) if iters <= 3 else (ds * 0.5 if iters > 6 else ds)
    return br, specials, moves, status


def _closes(y0, y1, first, t_first, reach):
    """Does the step from y0 to y1 pass through the branch's first point ``first`` in the
    direction the branch left it (``t_first``), after the branch went away from it (``reach``:
    the largest distance of an earlier point from it, at least twice the step)? Then the branch
    is a closed curve (an isola) and going on would trace it again. The first point must lie
    between the chord's ends, within 25 % of its length of it (the arc bulges by about its
    curvature x length^2 / 8)."""
    d = y1 - y0
    L2 = float(d @ d)
    if L2 == 0.0 or float(d @ t_first) <= 0.0 or reach < 2.0 * math.sqrt(L2):
        return False
    s = float((first - y0) @ d) / L2
    off = first - (y0 + s * d)
    return -0.01 <= s <= 1.01 and float(np.linalg.norm(off)) <= 0.25 * math.sqrt(L2)


def _corner(br, y0, f0, t0, step, s_fail):
    """Where the corrector fails at every step and the section cannot be moved, the branch may
    have a corner: a point where the orbit starts or stops visiting a mode (a sliding
    bifurcation: a stick phase shrinks to nothing), so the map's derivative jumps there and
    the branch goes on in another direction, often back in the parameter (a non-smooth fold:
    a stable stick-slip cycle meets an unstable slip cycle). The other side is sought by
    correcting with one coordinate (or the parameter) held at y0's plus or minus ds, ds from
    ``step`` down to ``step`` x MIN_STEP; a point counts if it leaves the line of the branch
    (y0, t0) and the map's derivative there differs from y0's (a jump). The corner is then
    located by bisection along t0 in (0, s_fail) (``s_fail``: a step at which the corrector
    failed), a trial point being on y0's side where its derivative is nearer y0's than the
    other side's, to LOCATE_TOL in arclength. A corner must change the set of modes the orbit
    visits (``features``' ``modes``, y0's in ``f0``): an orbit that shrinks onto an equilibrium
    (a Hopf point ends a branch of cycles) is no corner. Returns (corrected point on the other
    side, its distance from y0, the tangent there, the special point (FOLD where the parameter
    turns back, else GRAZING; lam, the multiplier nearest +1 (fold) or the largest of the
    other side, y, jump = True, max X)), or None."""
    N = br.N
    if f0.get("modes") is None:
        return None
    ev0 = br.evaluate(y0[:N], y0[N])
    if ev0 is None:
        return None
    d0 = ev0[1]
    tol_d = JUMP_TOL * (1.0 + np.linalg.norm(d0))
    found = None
    ds = step
    while found is None and ds >= step * MIN_STEP:
        for i in range(N + 1):
            for sg in (1.0, -1.0):
                e = np.zeros(N + 1)
                e[i] = sg
                got = br.correct(y0 + ds * e, e, y0)
                if got is None:
                    continue
                dy = got[0] - y0
                off = dy - (dy @ t0) * t0
                if (np.linalg.norm(off) > 0.1 * np.linalg.norm(dy)
                        and np.linalg.norm(got[1][1] - d0) > tol_d):
                    t1 = br.tangent(got[1], dy / np.linalg.norm(dy))
                    f1 = br.features(got[0], got[1], t1)
                    if f1.get("modes") not in (None, f0["modes"]):
                        found = got
                        break
            if found is not None:
                break
        ds *= 0.25
    if found is None:
        return None
    y1, ev1, _ = found
    d1 = ev1[1]
    dy = y1 - y0
    lo, hi = 0.0, s_fail
    y_lo, ev_lo = y0, ev0
    for _ in range(60):
        if hi - lo <= LOCATE_TOL * max(1.0, abs(y0[N])):
            break
        s = 0.5 * (lo + hi)
        got = br.correct(y0 + s * t0, t0, y0)
        if got is not None and (np.linalg.norm(got[1][1] - d0)
                                < np.linalg.norm(got[1][1] - d1)):
            lo, y_lo, ev_lo = s, got[0], got[1]
        else:
            hi = s
    br.template = ev1[3]  # the next corrections start from the other side
    f_lo = br.features(y_lo, ev_lo, t0)
    mu = np.r_[f_lo["mu"], f1["mu"]]
    typ = FOLD if t0[N] * t1[N] < 0 else GRAZING
    m = mu[np.argmin(np.abs(mu - 1.0))] if typ == FOLD else mu[len(f_lo["mu"])]
    return found, float(np.linalg.norm(dy)), t1, (typ, float(y_lo[N]), complex(m), y_lo, True,
                                                 f_lo["max_X"])


def branch_arguments(params, param, k, max_points, step, max_step, tol, direction, bounds,
                     check_start: bool = True):
    """The checked arguments of a branch: (param, k, max_points, step, max_step, tol, lo, hi);
    one-line ParameterErrors naming the field (``check_start``: the bounds must contain the
    parameter's value in ``params``)."""
    if not isinstance(param, str):
        raise ParameterError(f"param: expected a parameter name, got {param!r}")
    param = params.model.param(param).name
    k = check_int("k", k, 1)
    max_points = check_int("max_points", max_points, 2)
    step = check_positive("step", step)
    max_step = 10.0 * step if max_step is None else check_float("max_step", max_step)
    if not max_step >= step:
        raise ParameterError(f"max_step: must be >= step = {step:g}, got {max_step:g}")
    tol = check_positive("tol", tol)
    if direction not in ("up", "down"):
        raise ParameterError(f"direction: expected 'up' or 'down', got {direction!r}")
    lam0 = float(getattr(params, param))
    if bounds is None:
        bounds = (-math.inf, math.inf)
    try:
        lo, hi = (float(b) for b in bounds)
    except (TypeError, ValueError):
        raise ParameterError(f"bounds: expected (low, high), got {bounds!r}") from None
    if math.isnan(lo) or math.isnan(hi) or not lo < hi:
        raise ParameterError(f"bounds: expected low < high, got ({lo:g}, {hi:g})")
    if check_start and not lo <= lam0 <= hi:
        raise ParameterError(f"bounds: ({lo:g}, {hi:g}) exclude the start {param} = {lam0:g}")
    return param, k, max_points, step, max_step, tol, lo, hi


def _moved_section(br, solver, y, t, step):
    """Where the corrector fails at every step, the section may sit on an event of the orbit
    (an impact at t = kT: the map is not smooth there). Try the section a quarter, a half and
    three quarters of a period later: the branch point y (section point, parameter) is carried
    there by the flow, its tangent by central differences of that flow, and a first step of
    ``step`` (halved as usual) must then succeed. Returns (solver, setup, branch, y, t,
    corrected point, step) at the new section, or None."""
    import dataclasses
    N = br.setup.N
    for q in (1, 2, 3):
        new = (solver.section_phase + q * 0.5 * math.pi) % (2.0 * math.pi)
        s2 = dataclasses.replace(solver, section_phase=new)
        setup2 = TangentSetup(s2)

        def carry(yy):
            s = _section_state(br.setup, br.p(yy[N]), yy[:N], br.template)
            if run(KERNEL_GENERIC, br.setup.fns, br.p(yy[N]), br.setup.opts, s, 4, q, 0,
                   *output_buffers(0)) != st.OK:
                return None, None
            return setup2.z_of(s), s

        z, s_new = carry(y)
        h = 1e-6 * max(1.0, float(np.linalg.norm(y)))
        zp, _ = carry(y + h * t)
        zm, _ = carry(y - h * t)
        if z is None or zp is None or zm is None:
            continue
        t2 = np.r_[(zp - zm) / (2.0 * h), t[N]]
        t2 /= np.linalg.norm(t2)
        y2 = np.r_[z, y[N]]
        br2 = _Branch(setup2, br.p0, br.index, br.k, br.tol, br.level)
        br2.template = s_new
        if br2.correct(y2, t2) is None:  # the point itself, at the new section
            continue
        ds = step
        while ds >= step * MIN_STEP:
            got = br2.correct(y2 + ds * t2, t2, y2)
            if got is not None:
                return s2, setup2, br2, y2, t2, got, ds
            ds *= 0.5
    return None


def _doubled_orbit(params, param, start, method, tol, rtol, atol, section_phase=0.0):
    """Branch switching at a period doubling: (the 2k orbit's periodic_orbit Dataset, its
    parameter value, 2k, direction away from the PD)."""
    try:
        src, i = start
        typ = int(src.special_type[i])
    except (TypeError, ValueError, KeyError, IndexError):
        raise ParameterError("start: expected (branch Dataset, index of a special point)") from None
    if typ != PERIOD_DOUBLING:
        raise ParameterError(f"start: special point {i} is a {SPECIAL_NAMES.get(typ, typ)}, "
                             f"not a period doubling")
    # the phase of the section where the point was located (the branch may have moved it)
    sp_phase = (float(src["special_section_phase"][i]) if "special_section_phase" in src
                else float(src.attrs.get("section_phase", 0.0)))
    if sp_phase != section_phase:
        raise ParameterError(f"start: the period doubling was located with the section at "
                             f"phase {sp_phase:.17g}, not {section_phase:g}: give "
                             f"section_phase={sp_phase:.17g}")
    if src.attrs.get("param") != param:
        raise ParameterError(f"start: the branch was continued in {src.attrs.get('param')}, "
                             f"not in {param}")
    k = int(src.attrs["k"])
    lam = float(src[f"special_{param}"][i])
    from ..io import components
    z = np.asarray(components(src, "special_", "_section").values[i], dtype=float)
    n = params.model.n
    if len(z) != n:
        raise ParameterError(f"start: the branch has {len(z)} state components, the model "
                             f"{n}")
    base = params.replace(**{param: lam})
    orb = periodic_orbit(base, k=k, u0=z, method=method, tol=tol, rtol=rtol,
                         atol=atol, samples_per_period=1, section_phase=section_phase)
    M = orb.monodromy.values[:n, :n]
    w, V = np.linalg.eig(M)
    v = np.real(V[:, int(np.argmin(np.abs(w + 1.0)))])
    v /= np.linalg.norm(v)
    scale = 1.0 + float(np.linalg.norm(z))
    for dl in (1e-4, 1e-3):
        for sg in (1.0, -1.0):
            lam_t = lam + sg * dl * max(1.0, abs(lam))
            for amp in (1e-2, 3e-2, 1e-1):
                zt = z + amp * scale * v
                o2 = periodic_orbit(params.replace(**{param: lam_t}), k=2 * k, u0=zt,
                                    method=method, tol=tol, rtol=rtol, atol=atol,
                                    samples_per_period=1, section_phase=section_phase)
                if o2.attrs["status"] != "converged":
                    continue
                us = components(o2, suffix="_section").values
                spread = float(np.linalg.norm(us[0] - us[k]))
                if spread > 1e-6 * scale:  # a genuine 2k orbit, not the k orbit again
                    return o2, lam_t, 2 * k, "up" if sg > 0 else "down"
    raise ParameterError(f"start: no period-{2 * k} orbit found near the period doubling at "
                         f"{param} = {lam:.10g}")


def _confirmed(typ, mu) -> bool:
    """A located Neimark-Sacker point must be a complex pair on the unit circle (a real pair
    with product 1, a neutral saddle, also zeroes its test function)."""
    if typ == NEIMARK_SACKER:
        return abs(mu.imag) > 1e-9 and abs(abs(mu) - 1.0) < 1e-4
    return True


def _start_state(setup, p, orb, state):
    """The kernel state at the converged section point of ``orb`` (mode classified)."""
    z = np.zeros(setup.N)
    from ..io import components
    z[:setup.n] = components(orb, suffix="_section").values[0]
    s = setup.state_of(z, state)
    s[3] = -1.0
    run(KERNEL_GENERIC, setup.fns, p, setup.opts, s, 1, 0, 0, *output_buffers(0))
    return s


def locate_on_arc(br, y0, t0, ds, a, b, test, close, seen=None):
    """Illinois on the arclength s in (0, ds) from y0 along t0 for a zero of ``test(features)``
    (``a`` at 0 and ``b`` at ds, of opposite signs), every trial point corrected onto the
    branch ``br``; stops once ``close(hi - lo, y)`` or the test is 0; ``seen(features, below)``
    is told each trial point's side. Returns (y, features) of the last trial point, or None
    where the corrector fails."""
    # Illinois in the normalised test g = f sign(f(ds)): g(0) > 0 (lo side), g(ds) < 0 (hi)
    sg = -1.0 if b > 0 else 1.0
    lo, hi, glo, ghi = 0.0, ds, sg * a, sg * b
    side = 0
    best = None
    for _ in range(60):
        s = illinois_point(lo, hi, glo, ghi)
        got = br.correct(y0 + s * t0, t0, y0)
        if got is None:
            return None
        y, ev, _ = got
        f = br.features(y, ev, br.tangent(ev, t0))
        gs = sg * test(f)
        best = (y, f)
        if seen is not None:
            seen(f, gs < 0.0)
        lo, hi, glo, ghi, side = illinois_update(lo, hi, glo, ghi, side, s, gs)
        if close(hi - lo, y) or gs == 0.0:
            break
    return best


def _locate(br, typ, y0, t0, ds, a, b):
    """Illinois on the arclength s in (0, ds) from y0 along t0 for a zero of test ``typ``;
    returns (lam, multiplier nearest the crossing, y) or None."""
    mu_sides = [None, None]  # multipliers at the last point found on each side

    def seen(f, below):
        mu_sides[1 if below else 0] = f["mu"]
    got = locate_on_arc(br, y0, t0, ds, a, b, lambda f: f["tests"][typ],
                        lambda width, y: abs(t0[-1]) * width <= LOCATE_TOL * max(1.0, abs(y[-1])),
                        seen)
    if got is None:
        return None
    y, f = got
    mu = f["mu"]
    target = {FOLD: 1.0, PERIOD_DOUBLING: -1.0}.get(typ)
    if target is not None:
        m = mu[np.argmin(np.abs(mu - target))]
    elif typ == NEIMARK_SACKER:
        m = mu[np.argmin(np.abs(np.abs(mu) - 1.0) + (np.abs(mu.imag) <= 1e-12))]
    else:
        m = mu[0]
    if target is not None:
        jump = abs(m - target) > JUMP_TOL
    elif typ == NEIMARK_SACKER:
        jump = abs(abs(m) - 1.0) > JUMP_TOL
    else:  # grazing: do the multipliers on either side of it differ?
        a_, b_ = mu_sides
        jump = (a_ is not None and b_ is not None and len(a_) == len(b_)
                and float(np.max(np.abs(np.sort_complex(a_) - np.sort_complex(b_)))) > 1e-3)
    return float(y[-1]), complex(m), y, bool(jump), f["max_X"]


def _dataset(params, solver, param, k, pts, specials, status, N, direction, bounds):
    from ..io import flag_attrs
    lam = np.array([y[-1] for y, _ in pts])
    mus = [f["mu"] for _, f in pts]
    nm = max(len(m) for m in mus)
    MU = np.full((len(pts), nm), np.nan + 0j)
    for i, m in enumerate(mus):
        MU[i, :len(m)] = m
    absmu = np.abs(MU)
    stable = np.array([bool(np.all(np.abs(m) < 1.0 - NEUTRAL)) for m in mus], np.int8)
    XS = np.array([f["section"][0] for _, f in pts])
    VS = np.array([f["section"][1] for _, f in pts])
    n = params.model.n
    US = np.array([f["section"][2] for _, f in pts]).reshape(len(pts), k, n)
    spec = params.model.param(param)
    sp_type = np.array([s[0] for s in specials], np.int8)
    sp_lam = np.array([s[2] for s in specials], float)
    sp_mu = np.array([s[3] for s in specials], complex)
    sp_after = np.array([s[1] for s in specials], np.int64)
    sp_z = np.array([s[4][:n] for s in specials]).reshape(len(specials), n)
    sp_jump = np.array([s[5] for s in specials], np.int8)
    sp_mx = np.array([s[6] for s in specials], float)
    ds = xr.Dataset(
        {
            param: ("point", lam, {"long_name": spec.long_name, "units": spec.units}),
            "X_section": (("point", "j"), XS, {"long_name": "section points X(jT)",
                                              "units": "1"}),
            "V_section": (("point", "j"), VS, {"long_name": "section points V(jT)",
                                              "units": "1/s"}),
            **component_variables(params.model, ("point", "j"), US, suffix="_section",
                                  what=" at the section points"),
            "multiplier_real": (("point", "multiplier"), MU.real, {"units": "1"}),
            "multiplier_imag": (("point", "multiplier"), MU.imag, {"units": "1"}),
            "multiplier_abs": (("point", "multiplier"), absmu, {"units": "1"}),
            "stable": ("point", stable, flag_attrs(("not_stable", "stable"), dtype=np.int8,
                                                   long_name="every |mu| < 1 - 1e-6")),
            "max_X": ("point", np.array([f["max_X"] for _, f in pts]),
                      {"long_name": "largest X over the orbit", "units": "1"}),
            "min_X": ("point", np.array([f["min_X"] for _, f in pts]),
                      {"long_name": "smallest X over the orbit", "units": "1"}),
            "contact_fraction": ("point", np.array([f["contact"] for _, f in pts]), {
                "long_name": "fraction of the orbit's samples in contact modes", "units": "1"}),
            "special_type": ("special", sp_type, flag_attrs(
                [SPECIAL_NAMES[i] for i in sorted(SPECIAL_NAMES)], dtype=np.int8,
                long_name="type of the special point")),
            f"special_{param}": ("special", sp_lam, {"long_name": f"{param} at the special "
                                                                  f"point", "units": spec.units}),
            "special_multiplier_real": ("special", sp_mu.real, {"units": "1"}),
            "special_multiplier_imag": ("special", sp_mu.imag, {"units": "1"}),
            "special_X_section": ("special", sp_z[:, 0], {
                "long_name": "first section point X at the special point", "units": "1"}),
            "special_V_section": ("special", sp_z[:, 1], {
                "long_name": "first section point V at the special point", "units": "1/s"}),
            **component_variables(params.model, "special", sp_z, prefix="special_",
                                  suffix="_section", what=" at the special point"),
            "special_max_X": ("special", sp_mx, {"long_name": "largest X over the orbit at "
                                                              "the special point", "units": "1"}),
            "special_jump": ("special", sp_jump, flag_attrs(
                ("through_the_unit_circle", "multipliers_jump"), dtype=np.int8,
                long_name="1: the multipliers jump across the point (a non-smooth transition, "
                          "e.g. at a grazing; a fold / PD / NS test changed sign without a "
                          "multiplier on the unit circle)")),
            "special_after_point": ("special", sp_after, {
                "long_name": "the special point lies between this point and the next"}),
        },
        coords={"point": np.arange(len(pts)), "j": np.arange(k),
                "multiplier": np.arange(1, nm + 1), "special": np.arange(len(specials))},
        attrs=provenance_attrs(params, solver, swept=(param,), analysis="continuation",
                               param=param, k=k, direction=direction, status=status,
                               bounds_low=float(bounds[0]), bounds_high=float(bounds[1])),
    )
    return apply_state_units(ds, params.model)


def two_parameter_curve(params, param: str, param2: str, values2, *, special: str = "fold",
                        k: int = 1, x0: float = 0.0, v0: float = 0.0, bounds=None,
                        step: float = 0.01, max_points: int = 400, method: str = "exact",
                        tol: float = 1e-10, section_phase: float = 0.0,
                        u0=None, direction: str = "up", section=None,
                        max_time: float = 1e4) -> xr.Dataset:
    """A curve of special points in two parameters: for each value of ``param2`` in
    ``values2``, the branch in ``param`` is continued from the same start (``params``' value
    of ``param``, Newton from (x0, v0) or ``u0``) over ``bounds`` and every located point of type
    ``special`` ("fold", "period_doubling", "neimark_sacker" or "grazing") is recorded, so
    that e.g. the fold pair omega_b, omega_c of Fig. 6 is followed as omega_s changes, or the
    grazing curve of the contact-free orbit in (omega, F0).

    Returns a Dataset over (``param2``, ``n``): ``<param>`` at the n-th such point of the branch
    (in ascending order; NaN where fewer were found), the critical multiplier and
    ``special_jump``; ``status`` per value of ``param2`` (how the branch ended). Each point is
    located to 1e-10 on its branch; the curve is as fine as ``values2``. Each branch runs
    ``direction`` ("up", "down") from the start. A self-excited system (a model without
    forcing, or ``section`` given) has the special points of its limit cycles on that section
    followed instead (see :func:`continuation`)."""
    from ..simulate import check_params
    check_params(params)
    names = {v: kk for kk, v in SPECIAL_NAMES.items()}
    if special not in names or names[special] == 0:
        raise ParameterError(f"special: expected one of fold, period_doubling, "
                             f"neimark_sacker, grazing, got {special!r}")
    typ = names[special]
    if not isinstance(param2, str):
        raise ParameterError(f"param2: expected a parameter name, got {param2!r}")
    param2 = params.model.param(param2).name
    if param2 == param:
        raise ParameterError(f"param2: must differ from param ({param})")
    values2 = np.asarray(values2, dtype=float).ravel()
    if values2.size == 0 or not np.all(np.isfinite(values2)):
        raise ParameterError(f"values2: expected finite values of {param2}, got {values2!r}")
    rows, stat = [], []
    for v in values2:
        p = params.replace(**{param2: float(v)})
        br = continuation(p, param, k=k, x0=x0, v0=v0, u0=u0, bounds=bounds, step=step,
                          max_points=max_points, method=method, tol=tol,
                          section_phase=section_phase, direction=direction, section=section,
                          max_time=max_time)
        sel = br.special_type.values == typ
        lam = br[f"special_{param}"].values[sel]
        mu = (br.special_multiplier_real.values + 1j * br.special_multiplier_imag.values)[sel]
        jump = br.special_jump.values[sel]
        order = np.argsort(lam)
        rows.append((lam[order], mu[order], jump[order]))
        stat.append(br.attrs["status"])
    n = max([len(r[0]) for r in rows] + [1])
    L = np.full((len(values2), n), np.nan)
    MU = np.full((len(values2), n), np.nan + 0j)
    JP = np.full((len(values2), n), -1, np.int8)
    for i, (lam, mu, jump) in enumerate(rows):
        L[i, :len(lam)] = lam
        MU[i, :len(mu)] = mu
        JP[i, :len(jump)] = jump
    s1, s2 = params.model.param(param), params.model.param(param2)
    return xr.Dataset(
        {param: ((param2, "n"), L, {"long_name": f"{param} at the {special} points",
                                    "units": s1.units}),
         "multiplier_real": ((param2, "n"), MU.real, {"units": "1"}),
         "multiplier_imag": ((param2, "n"), MU.imag, {"units": "1"}),
         "special_jump": ((param2, "n"), JP, {"long_name": "1: the multipliers jump there (-1: "
                                                           "no point)"}),
         "status": (param2, np.array(stat, dtype=object).astype(str),
                    {"long_name": "how each branch ended"})},
        coords={param2: (param2, values2, {"long_name": s2.long_name, "units": s2.units}),
                "n": np.arange(n)},
        attrs=provenance_attrs(params, None, swept=(param, param2), section_phase=section_phase,
                               analysis="two_parameter_curve", param=param, param2=param2,
                               special=special, k=k, direction=direction,
                               **({"section": br.attrs["section"]} if "section" in br.attrs
                                  else {})),
    )
