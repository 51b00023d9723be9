"""Resonance curves (max X and min X of the settled response versus omega), swept up and down
with continuation, and the characteristic frequencies of the paper's Fig. 6.

Definitions (all on the ascending grid of ``omegas``; the continuation core is the one of
:mod:`.bifurcation`):

* The up and down branches *differ* at a grid value when
  |max_X_up - max_X_down| > ``branch_tol`` (default 1e-3 max(1, |max_X|)).
* **omega_b, omega_c** (hysteresis): the widest contiguous run of grid values where the
  branches differ is the hysteresis interval. Its upper end is where the *up* sweep jumps
  (omega_c: between the last value of the run and the next one), its lower end where the
  *down* sweep jumps (omega_b: between the first value of the run and the previous one).
  Each is refined by bisection with continuation: the branch that jumps is continued from its
  state at the last value where it existed, the other branch from its state at the first value
  past the jump, both to the midpoint, quasi-statically in steps of at most
  ``RAMP`` x ``resolution`` (at most ``MAX_RAMP_STEPS`` steps); if they still differ, the jumping branch still exists
  there, otherwise it has gone. Stops when the bracket is <= ``resolution``; the midpoint is
  reported, with the bracket in ``omega_b_bracket`` / ``omega_c_bracket``. An end of the run
  that touches the end of the grid gives NaN (jump outside the range); no differing value
  gives NaN for both.
* **omega_a** (contact starts): the smallest grid value at which a branch (up or down) has
  max_X >= 1 (the model's ``contact_level``: X = 1 for the support; NaN for a model without
  one) while the same branch had max_X < 1 at the previous value; refined by bisection
  on max_X - 1 along that (non-contact) branch, continued from its state at the last value
  below 1. NaN if no branch crosses 1 from below inside the grid.

All results depend on the transient like the sweeps themselves: close to a saddle-node the
vanishing branch drifts slowly (critical slowing down), so a too-short transient moves the
refined jump frequencies slightly past the true fold.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from ..errors import ParameterError
from ..kernels import Solver
from ..models.base import ParamsBase
from .bifurcation import (branches_dataset, check_sweep_memory, check_values, follow,
                          run_branches)
from .poincare import settle_tolerance

#: During refinement a branch is continued to each bisection midpoint in steps of at most
#: RAMP x resolution (quasi-static), so that the transient after a finite parameter step
#: cannot push it off its branch early (with light damping the response overshoots).
RAMP = 0.25
#: ... but in at most this many steps per midpoint (coarse grids: the first, long
#: continuations use longer steps; the last ones, which decide the result, are short).
MAX_RAMP_STEPS = 32


def _continue_to(params, solver, starts, target, states, transient, record, settle_tol,
                 workers, ramp):
    """Continue each row of ``states`` (at frequency ``starts[row]``) quasi-statically to
    ``target`` in equal steps of at most ``ramp`` (all rows take the same number of steps).
    Returns (max_X at ``target`` per row, states there, ok)."""
    nbr = states.shape[0]
    dist = max(abs(target - w) for w in starts)
    nstep = max(1, min(MAX_RAMP_STEPS, int(math.ceil(dist / ramp - 1e-9))))
    P = np.empty((nbr, nstep, params.pack().size))
    for b, w in enumerate(starts):
        path = np.linspace(w, target, nstep + 1)[1:]
        path[-1] = target
        P[b] = np.stack([params.replace(**{params.model.forcing_param: float(x)}).pack()
                         for x in path])
    states = np.array(states, dtype=np.float64, copy=True)
    out = follow(P, solver, states, states[0].copy(), transient, settle_tol, record,
                 workers=workers)
    return out["Xmax"][:, -1].max(axis=1), out["S"][:, -1], bool(np.all(out["status"] == 0))


def _differ(a, b, branch_tol):
    return abs(a - b) > branch_tol * max(1.0, abs(a), abs(b))


def _refine_jump(params, solver, w_keep, s_keep, w_gone, s_other, resolution, branch_tol,
                 run):
    """Bisection for the end of the branch that exists at w_keep and not at w_gone."""
    while abs(w_gone - w_keep) > resolution:
        mid = 0.5 * (w_keep + w_gone)
        mx, S, ok = _continue_to(params, solver, (w_keep, w_gone), mid,
                                 np.stack([s_keep, s_other]), *run)
        if not ok:
            return float("nan"), (float("nan"), float("nan"))
        if _differ(mx[0], mx[1], branch_tol):
            w_keep, s_keep = mid, S[0]
        else:
            w_gone, s_other = mid, S[1]
    lo, hi = sorted((w_keep, w_gone))
    return 0.5 * (lo + hi), (lo, hi)


def _refine_contact(params, solver, w_lo, s_lo, w_hi, resolution, run, level=1.0):
    """Bisection on max_X - level along a branch continued from its state at w_lo
    (max_X < level; ``level`` is where the model's contact starts, X = 1 for the support)."""
    while w_hi - w_lo > resolution:
        mid = 0.5 * (w_lo + w_hi)
        mx, S, ok = _continue_to(params, solver, (w_lo,), mid, s_lo[None, :], *run)
        if not ok:
            return float("nan"), (float("nan"), float("nan"))
        if mx[0] < level:
            w_lo, s_lo = mid, S[0]
        else:
            w_hi = mid
    return 0.5 * (w_lo + w_hi), (w_lo, w_hi)


def characteristic_frequencies(params, solver, omegas, out, *, transient, record, settle,
                               workers, resolution=1e-4, branch_tol=1e-3):
    """omega_a, omega_b, omega_c and their brackets from up/down branches ``out`` of
    :func:`run_branches` (branch 0 = up, 1 = down); see the module docstring."""
    run = (transient, record, settle_tolerance(solver, settle), workers, RAMP * resolution)
    mx = out["Xmax"].max(axis=2)  # (2, n)
    up, down = mx[0], mx[1]
    n = omegas.size
    res = {"omega_a": math.nan, "omega_b": math.nan, "omega_c": math.nan,
           "omega_a_bracket": (math.nan, math.nan), "omega_b_bracket": (math.nan, math.nan),
           "omega_c_bracket": (math.nan, math.nan), "n_hysteresis_intervals": 0,
           "omega_a_branch": ""}
    # hysteresis interval: widest run where the branches differ
    diff = np.array([np.isfinite(up[i]) and np.isfinite(down[i]) and
                     _differ(up[i], down[i], branch_tol) for i in range(n)])
    runs, i = [], 0
    while i < n:
        if diff[i]:
            j = i
            while j + 1 < n and diff[j + 1]:
                j += 1
            runs.append((i, j))
            i = j + 1
        else:
            i += 1
    res["n_hysteresis_intervals"] = len(runs)
    if runs:
        i0, i1 = max(runs, key=lambda r: (omegas[r[1]] - omegas[r[0]], -r[0]))
        S = out["S"]
        if i1 + 1 < n and np.all(out["status"][:, i1:i1 + 2] == 0):  # up sweep jumps
            res["omega_c"], res["omega_c_bracket"] = _refine_jump(
                params, solver, omegas[i1], S[0, i1], omegas[i1 + 1], S[1, i1 + 1],
                resolution, branch_tol, run)
        if i0 > 0 and np.all(out["status"][:, i0 - 1:i0 + 1] == 0):  # down sweep jumps
            res["omega_b"], res["omega_b_bracket"] = _refine_jump(
                params, solver, omegas[i0], S[1, i0], omegas[i0 - 1], S[0, i0 - 1],
                resolution, branch_tol, run)
    # contact onset: first upward crossing of the model's contact level (support: max_X = 1)
    level = solver.model.contact_level(params) if solver.model.contact_level else None
    best = None
    for b, name in ((0, "up"), (1, "down")):
        for i in range(1, n if level is not None else 1):
            if mx[b, i - 1] < level <= mx[b, i]:
                if best is None or i < best[1]:
                    best = (b, i, name)
                break
    if best is not None:
        b, i, name = best
        res["omega_a"], res["omega_a_bracket"] = _refine_contact(
            params, solver, omegas[i - 1], out["S"][b, i - 1], omegas[i], resolution, run,
            level)
        res["omega_a_branch"] = name
    return res


def resonance_curve(params: ParamsBase, omegas, *, method: str = "smooth", transient: int = 500,
                    record: int = 50, x0: float = 0.0, v0: float = 0.0, rtol: float = 1e-8,
                    atol: float = 1e-10, settle: bool = True,
                    resolution: float = 1e-4, branch_tol: float = 1e-3,
                    workers: int | None = None, progress=None,
                    branches: str = "stable", store=None, engine=None,
                    section_phase: float = 0.0, u0=None) -> xr.Dataset:
    """Resonance curve over the forcing frequencies ``omegas`` (sorted ascending), swept up and
    down with continuation (see :func:`.bifurcation.bifurcation_diagram` for transient, record,
    settle; ``u0`` for every component of the start, see ``simulate``). Returns a Dataset over (sweep, omega) with ``max_X``, ``min_X``, ``period``,
    ``contact``, ``status`` and the section ``X``, ``V``; attrs ``omega_a``, ``omega_b``,
    ``omega_c`` (NaN when absent) refined to ``resolution``, with ``*_bracket`` attrs
    (definitions in the module docstring).

    ``branches="all"``: also every branch of period-1 orbits, stable and unstable, by
    continuation (:func:`.continuation.continuation`) from the up sweep's orbit at the lowest
    frequency over the whole range: variables ``branch_<omega>``, ``branch_max_X``,
    ``branch_min_X``, ``branch_stable`` over ``branch_point``, and the attrs
    ``omega_a_continuation`` (the first grazing), ``omega_c_continuation`` and
    ``omega_b_continuation`` (the upper and the lower fold), located to 1e-10 instead of by
    sweeps (a sweep near a fold lingers on the vanishing orbit, so its jump comes late).

    ``store`` / ``engine``: chunked, resumable sweeps and where they run, as for
    :func:`.bifurcation.bifurcation_diagram` (the refinement of the characteristic
    frequencies runs locally after the sweeps).
    ``progress`` (None or False: silent; True: a progress bar with a time estimate on a terminal,
    plain lines elsewhere; or a callable ``progress(done, total)``): reports the work done.
    """
    from ..simulate import check_forced
    check_forced(params, "resonance_curve")
    from ..sweep import progress_callback
    progress = progress_callback(progress, "resonance")
    from ..chunks import check_engine
    from ..checks import check_positive
    from ..simulate import check_admissible, check_int, check_params, initial_u, start_attrs
    params = check_params(params)
    engine = check_engine(engine)
    transient = check_int("transient", transient, 0)
    record = check_int("record", record, 1)
    check_sweep_memory(np.size(omegas), 2, record)
    w_name = params.model.forcing_param  # the forcing frequency (support: omega) or period
    omegas = check_values(w_name, omegas)
    for w in (omegas[0], omegas[-1]):
        params.replace(**{w_name: float(w)})
    u = initial_u(params.model, x0, v0, u0)
    resolution = check_positive("resolution", resolution)
    branch_tol = check_positive("branch_tol", branch_tol)
    if branches not in ("stable", "all"):
        raise ParameterError(f"branches: expected 'stable' or 'all', got {branches!r}")
    solver = Solver(method=method, rtol=rtol, atol=atol,
                    model=params.model, section_phase=section_phase)
    check_admissible(solver, params, u)
    out = run_branches(params, w_name, omegas, solver, directions=["up", "down"],
                       transient=transient, record=record, x0=u[0], v0=u[1], extra=u[2:],
                       settle=settle, workers=workers, progress=progress, store=store,
                       engine=engine, analysis="resonance", first_window=True)
    # the jumps are refined from the sweeps' first recorded windows (as before the sections
    # still converging were extended)
    first = {"Xmax": out.pop("first_max_X")[..., None], "S": out.pop("first_S"),
             "status": out.pop("first_status")}
    freqs = characteristic_frequencies(params, solver, omegas, first, transient=transient,
                                       record=record, settle=settle, workers=workers,
                                       resolution=resolution, branch_tol=branch_tol)
    ds = branches_dataset(params, w_name, omegas, solver, ["up", "down"], out,
                          analysis="resonance", transient=transient, record=record,
                          **start_attrs(u), settle=settle, resolution=resolution, branch_tol=branch_tol,
                          **freqs)
    if branches == "all":
        _all_branches(ds, params, w_name, omegas, out, method, section_phase)
    if w_name != "omega":  # the same points named by the swept parameter (a period T: T_a ...)
        ds.attrs.update({k.replace("omega", w_name, 1): v for k, v in list(ds.attrs.items())
                         if k.startswith(("omega_a", "omega_b", "omega_c"))})
    return ds


def jump_names(ds) -> tuple:
    """The names of the jump points of a resonance Dataset: ("omega_a", "omega_b",
    "omega_c"), or those of the swept parameter where it is not omega ("T_a", ...)."""
    w = str(ds.attrs.get("swept_param", "omega"))
    w = w if f"{w}_a" in ds.attrs else "omega"
    return tuple(f"{w}_{k}" for k in "abc")


def _all_branches(ds, params, w_name, omegas, out, method, section_phase=0.0):
    """Add the continued period-1 branch (stable and unstable parts) and its special points."""
    from .continuation import FOLD, GRAZING, continuation
    up = 0
    x0, v0 = float(out["X"][up, 0, -1]), float(out["V"][up, 0, -1])
    u0 = None
    if params.model.n > 2:  # the state after the first value: every component
        from ..simulate import state_u
        u0, x0, v0 = state_u(params.model, out["S"][up, 0]), 0.0, 0.0
    br = continuation(params.replace(**{w_name: float(omegas[0])}), w_name, x0=x0, v0=v0, u0=u0,
                      bounds=(float(omegas[0]), float(omegas[-1])),
                      step=min(0.01, 0.05 * float(omegas[-1] - omegas[0])),
                      max_points=2000, method=method, section_phase=section_phase)
    spec = params.model.param(w_name)
    ds[f"branch_{w_name}"] = ("branch_point", br[w_name].values,
                              {"long_name": spec.long_name, "units": spec.units})
    ds["branch_max_X"] = ("branch_point", br.max_X.values,
                          {"long_name": "largest X on the period-1 orbit (continuation)",
                           "units": "1"})
    ds["branch_min_X"] = ("branch_point", br.min_X.values,
                          {"long_name": "smallest X on the period-1 orbit (continuation)",
                           "units": "1"})
    ds["branch_stable"] = ("branch_point", br.stable.values, br.stable.attrs)
    typ = br.special_type.values
    lam = br[f"special_{w_name}"].values
    graz, folds = lam[typ == GRAZING], lam[typ == FOLD]
    ds.attrs["omega_a_continuation"] = float(graz[0]) if graz.size else math.nan
    ds.attrs["omega_c_continuation"] = float(folds.max()) if folds.size >= 2 else math.nan
    ds.attrs["omega_b_continuation"] = float(folds.min()) if folds.size >= 2 else math.nan
    ds.attrs["branch_status"] = br.attrs["status"]
