"""The eta audit: which band half-widths eta let the smoothed switch model reproduce the exact
non-smooth dynamics (the paper's Fig. 4 question, answered against the eta = 0 solution).

``eta_study(params, etas)`` integrates, from the same initial state, the smoothed model
(``method="smooth"``, or another smoothed method of the model) for every eta and the exact event-driven model (``method="exact"``)
once, discards ``transient`` forcing periods and records ``record`` stroboscopic section points
(t = kT, forcing phase 0) plus an orbit (phase portrait) of ``orbit_periods`` periods.

Per eta (dimension ``eta``):

* ``reaches_gamma_plus``: 1 if the settled smoothed orbit enters Gamma+ (region code 3, bit 3
  of the kernels' visited mask) during the recorded periods;
* ``period``: period of the section points (``analysis.periodicity.detect_period`` with the
  solver's tolerance), 0 = not periodic;
* ``distance_to_exact``: symmetric mean nearest-neighbour distance between the smoothed and the
  exact section point sets, in the scaled plane (X, V / omega) (both in units of the gap):
  d(A, B) = (mean_a min_b |a - b| + mean_b min_a |a - b|) / 2. For two periodic orbits of the
  same period it is the mean distance between corresponding points; for chaotic attractors it
  measures how far one sample lies from the other set;
* ``agrees``: 1 when reaches_gamma_plus equals the exact model's contact flag, the periods are
  equal, and distance_to_exact <= ``distance_tol`` + 2 * ``exact_self_distance``, where
  ``exact_self_distance`` is the same set distance between the two halves of the exact section
  points (0 for a periodic orbit, the sampling resolution of a chaotic attractor, so that two
  samples of the same chaotic attractor agree);
* ``status``: kernel status (0 = ok); a failed trajectory gets NaN, period 0 and agrees 0.

Variable ``recommended_eta``: the largest eta that agrees with the exact model (NaN if none).
The exact orbit's section, orbit, period and contact flag are stored as ``exact_*``.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from ..checks import check_etas  # noqa: F401 (re-exported)
from ..errors import ParameterError
from ..io import provenance_attrs
from ..kernels import Solver, new_state
from ..models.base import ParamsBase
from ..sweep import run_trajectories
from .periodicity import detect_period, section_tolerance

#: Largest period looked for in the section points.
MAX_PERIOD = 64
#: Tolerances the exact model's section is classified with (it is exact to round-off; a
#: settled periodic orbit repeats to ~1e-13, so this is far from both round-off and chaos).
EXACT_RTOL = 1e-10
EXACT_ATOL = 1e-12


def _check_count(name, value, minimum):
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise ParameterError(f"{name}: expected a whole number, got {value!r}")
    if value < minimum:
        raise ParameterError(f"{name}: must be >= {minimum}, got {value}")
    return int(value)


def set_distance(ax, ay, bx, by) -> float:
    """Symmetric mean nearest-neighbour distance between point sets A and B (NaN if empty or
    non-finite)."""
    a = np.column_stack([ax, ay])
    b = np.column_stack([bx, by])
    if a.size == 0 or b.size == 0 or not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        return float("nan")
    d = np.sqrt(((a[:, None, :] - b[None, :, :]) ** 2).sum(axis=2))
    return float(0.5 * (d.min(axis=1).mean() + d.min(axis=0).mean()))


def _period(X, V, rtol, atol) -> int:
    if not (np.all(np.isfinite(X)) and np.all(np.isfinite(V))):
        return 0
    scale = float(max(np.abs(X).max(), np.abs(V).max(), 1.0))
    return int(detect_period(np.ascontiguousarray(X), np.ascontiguousarray(V),
                             section_tolerance(rtol, atol, scale), MAX_PERIOD))


def _integrate(P, solver, x0, v0, transient, record, orbit_periods, spp, workers, progress):
    """Section (per period) and orbit (spp per period) of each row of P."""
    n = P.shape[0]
    states = np.tile(new_state(x0, v0), (n, 1))
    sec = run_trajectories(P, solver, states, per_period=1, n_skip=transient, n_out=record,
                           workers=workers, progress=progress(0))
    por = run_trajectories(P, solver, sec["state"], per_period=spp, n_skip=0,
                           n_out=orbit_periods * spp, workers=workers,
                           progress=progress(n * (transient + record)))
    status = np.where(sec["status"] != 0, sec["status"], por["status"])
    return sec, por, status


#: Band half-widths per chunk (the unit of resumption, ``nonsmooth.chunks``); the exact
#: model is a chunk of its own.
ETA_CHUNK = 8


def _eta_chunk(spec, i, carry, workers=None, progress=None):
    """Chunk ``i`` of :func:`eta_study` (a ``chunks.Plan`` task): section, orbit and status
    of a block of etas (smoothed model), or of the exact model (the last chunk)."""
    from ..chunks import solver_from_spec
    bounds = spec["bounds"]
    if i < len(bounds):
        a, b = bounds[i]
        P, solver = spec["P"][a:b], solver_from_spec(spec["smooth"])
    else:
        P, solver = spec["p"][None, :], solver_from_spec(spec["exact"])
    total = P.shape[0] * (spec["transient"] + spec["record"] + spec["orbit_periods"])

    def stage(offset):
        return None if progress is None else (lambda d, _t: progress(offset + d, total))
    sec, por, status = _integrate(P, solver, spec["x0"], spec["v0"], spec["transient"],
                                  spec["record"], spec["orbit_periods"], spec["spp"], workers,
                                  stage)
    return {"sX": sec["X"], "sV": sec["V"], "sM": sec["M"], "oX": por["X"], "oV": por["V"],
            "oR": por["R"], "oM": por["M"], "status": np.asarray(status, np.int64)}


def eta_study(params: ParamsBase, etas, *, transient: int = 300, record: int | None = None,
              orbit_periods: int | None = None, samples_per_period: int = 200, x0: float = 0.0,
              v0: float = 0.0, rtol: float = 1e-8, atol: float = 1e-10,
              distance_tol: float = 1e-3, method: str = "smooth",
              workers: int | None = None, progress=None, points: int | None = None,
              portrait_periods: int | None = None, store=None, engine=None) -> xr.Dataset:
    """Audit the band half-width eta of the smoothed model against the exact model.

    From (x0, v0), every eta (smoothed ``method``: "smooth", or support's "smooth_eq12") and the exact model integrate ``transient``
    forcing periods, record ``record`` (default 200; ``points`` is its deprecated name)
    section points and then an orbit of ``orbit_periods`` (default 10; deprecated name
    ``portrait_periods``) periods at ``samples_per_period`` samples per period.
    ``progress`` (None or False: silent; True: a progress bar with a time estimate on a terminal,
    plain lines elsewhere; or a callable ``progress(done, total)``) is called between time slices.

    Returns an ``xarray.Dataset`` over ``eta`` (and ``n`` for section points, time
    ``t_section``; ``sample`` for orbit samples, time ``orbit_t``) with

    * ``reaches_gamma_plus``, ``period``, ``distance_to_exact``, ``agrees``, ``status``,
      ``regions_visited`` (definitions in the module documentation);
    * ``section_X``, ``section_V`` (eta, n), ``orbit_X``, ``orbit_V``, ``orbit_region``,
      ``orbit_visited`` (eta, sample);
    * the exact model's ``exact_section_X/V``, ``exact_orbit_X/V/region`` and the scalars
      ``exact_period``, ``exact_reaches_gamma_plus``, ``exact_status``,
      ``exact_self_distance``;
    * ``recommended_eta``: the largest eta that agrees with the exact model (NaN if none).

    ``store`` / ``engine``: chunked, resumable runs (:data:`ETA_CHUNK` etas per chunk, the
    exact model one more) and where they run (see ``nonsmooth.chunks``).
    """
    from ..simulate import check_forced
    check_forced(params, "eta_study")
    from ..sweep import progress_callback
    progress = progress_callback(progress, "eta study")
    from ..chunks import Plan, check_engine, chunk_bounds, execute, plan_solver
    from ..io import check_memory, flag_attrs, status_flags
    from ..simulate import check_params
    from ..simulate import renamed
    params = check_params(params)
    if "eta" not in params.model.param_names or "exact" not in params.model.methods \
            or "smooth" not in params.model.methods:
        raise ParameterError(f"params: eta_study needs a model with a band eta and both methods "
                             f"smooth and exact (model {params.model.name!r})")
    if not isinstance(method, str) or method == "exact" or method not in params.model.methods:
        raise ParameterError(f"method: eta_study audits a smoothed method of model "
                             f"{params.model.name!r} (one of: "
                             f"{', '.join(k for k in params.model.methods if k != 'exact')}), "
                             f"got {method!r}")
    full = params.model.contact_modes  # the modes of full contact (support: Gamma+)
    eta_vals = check_etas(etas)
    record = renamed("record", record, "points", points, default=200)
    orbit_periods = renamed("orbit_periods", orbit_periods, "portrait_periods",
                            portrait_periods, default=10)
    transient = _check_count("transient", transient, 0)
    record = _check_count("record", record, 2)
    orbit_periods = _check_count("orbit_periods", orbit_periods, 1)
    spp = _check_count("samples_per_period", samples_per_period, 1)
    for name, v in (("x0", x0), ("v0", v0), ("distance_tol", distance_tol)):
        if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)) \
                or not math.isfinite(float(v)):
            raise ParameterError(f"{name}: expected a finite number, got {v!r}")
    if distance_tol < 0:
        raise ParameterError(f"distance_tol: must be >= 0, got {distance_tol}")
    n = len(eta_vals)
    big = max((record, "record"), (orbit_periods, "orbit_periods"), (spp, "samples_per_period"))
    check_memory(34.0 * (n + 1) * (record + orbit_periods * spp), big[1],
                 "record fewer section points, orbit periods or samples per period",
                 size=(big[0], 1))
    smooth = Solver(method=method, rtol=rtol, atol=atol,
                    model=params.model)
    exact = Solver(method="exact", model=params.model)

    engine = check_engine(engine)
    P = np.stack([params.replace(eta=float(e)).pack() for e in eta_vals])
    bounds = chunk_bounds(n, ETA_CHUNK)
    spec = {"P": P, "p": params.pack(), "smooth": plan_solver(smooth, engine),
            "exact": plan_solver(exact, engine), "bounds": bounds, "x0": float(x0),
            "v0": float(v0), "transient": transient, "record": record,
            "orbit_periods": orbit_periods, "spp": spp}
    per = transient + record + orbit_periods
    plan = Plan("eta_study", {k: v for k, v in spec.items() if k not in ("bounds", "P", "p")} | {
        "params": dict(zip(params.model.param_names, spec["p"])), "etas": eta_vals,
        "chunk": ETA_CHUNK}, len(bounds) + 1, _eta_chunk, spec,
        weights=[(b - a) * per for a, b in bounds] + [per])
    parts = {}
    execute(plan, lambda i, res: parts.__setitem__(i, res), store=store, engine=engine,
            workers=workers, progress=progress)
    smooth_parts = [parts[i] for i in range(len(bounds))]
    sec = {k: np.concatenate([r["s" + k] for r in smooth_parts]) for k in "XVM"}
    por = {k: np.concatenate([r["o" + k] for r in smooth_parts]) for k in "XVRM"}
    status = np.concatenate([r["status"] for r in smooth_parts])
    ex = parts[len(bounds)]
    esec = {"X": ex["sX"], "V": ex["sV"], "M": ex["sM"]}
    epor = {"X": ex["oX"], "V": ex["oV"], "R": ex["oR"]}
    estatus = ex["status"]
    om = params.omega

    # ---- exact reference ----
    eX, eV = esec["X"][0], esec["V"][0]
    e_ok = int(estatus[0]) == 0
    e_contact = int(bool(np.any(esec["M"][0] & full))) if e_ok else 0
    e_period = _period(eX, eV, EXACT_RTOL, EXACT_ATOL) if e_ok else 0
    h = record // 2
    e_self = set_distance(eX[:h], eV[:h] / om, eX[h:], eV[h:] / om) if e_ok else float("nan")
    if e_period > 0:
        e_self = 0.0

    # ---- per eta ----
    reach = np.zeros(n, np.int8)
    period = np.zeros(n, np.int64)
    dist = np.full(n, np.nan)
    agrees = np.zeros(n, np.int8)
    visited = np.zeros(n, np.uint8)
    for i in range(n):
        if status[i] != 0:
            continue
        X, V, M = sec["X"][i], sec["V"][i], sec["M"][i]
        visited[i] = np.bitwise_or.reduce(M)
        reach[i] = int(bool(visited[i] & full))
        period[i] = _period(X, V, rtol, atol)
        if e_ok:
            dist[i] = set_distance(X, V / om, eX, eV / om)
            agrees[i] = int(reach[i] == e_contact and period[i] == e_period
                            and dist[i] <= distance_tol + 2.0 * e_self)
    good = eta_vals[agrees == 1]
    recommended = float(good.max()) if good.size else float("nan")

    T = params.period
    t_sec = (transient + np.arange(1, record + 1)) * T
    t_orb = (transient + record) * T + np.arange(1, orbit_periods * spp + 1) * (T / spp)
    regions = flag_attrs(params.model.mode_names, dtype=np.int8)
    masks = flag_attrs(params.model.mode_names, dtype=np.uint8, masks=True)
    yes_no = flag_attrs(("no", "yes"), dtype=np.int8)
    period_attrs = {"long_name": "period of the section points in forcing periods "
                                 "(0 = none)", "units": "1"}
    ds = xr.Dataset(
        {
            "reaches_gamma_plus": ("eta", reach, dict(
                yes_no, long_name="settled smoothed orbit enters Gamma+")),
            "period": ("eta", period, period_attrs),
            "distance_to_exact": ("eta", dist, {
                "long_name": "symmetric mean nearest-neighbour distance of the section points "
                             "to the exact ones in (X, V/omega), in units of the gap",
                "units": "1"}),
            "agrees": ("eta", agrees, dict(
                yes_no, long_name="same contact, same period and distance within tolerance")),
            "regions_visited": ("eta", visited, dict(
                masks, long_name="regions visited during the recorded periods")),
            "status": ("eta", np.asarray(status, np.int64), status_flags(
                long_name="kernel status")),
            "section_X": (("eta", "n"), sec["X"], {"long_name": "X at t_section", "units": "1"}),
            "section_V": (("eta", "n"), sec["V"], {"long_name": "V at t_section",
                                                   "units": "1/s"}),
            "orbit_X": (("eta", "sample"), por["X"], {"long_name": "X", "units": "1"}),
            "orbit_V": (("eta", "sample"), por["V"], {"long_name": "V", "units": "1/s"}),
            "orbit_region": (("eta", "sample"), por["R"], dict(
                regions, long_name="region at the sample")),
            "orbit_visited": (("eta", "sample"), por["M"], dict(
                masks, long_name="regions visited since the previous sample")),
            "exact_section_X": ("n", eX, {"long_name": "exact model: X at t_section",
                                          "units": "1"}),
            "exact_section_V": ("n", eV, {"long_name": "exact model: V at t_section",
                                          "units": "1/s"}),
            "exact_orbit_X": ("sample", epor["X"][0], {"long_name": "exact model: X",
                                                      "units": "1"}),
            "exact_orbit_V": ("sample", epor["V"][0], {"long_name": "exact model: V",
                                                      "units": "1/s"}),
            "exact_orbit_region": ("sample", epor["R"][0], dict(
                regions, long_name="exact model: mode at the sample (Gamma_minus free "
                                   "flight, Gamma_plus contact)")),
            "exact_period": ((), np.int64(e_period), dict(period_attrs, long_name=(
                "exact model: " + period_attrs["long_name"]))),
            "exact_reaches_gamma_plus": ((), np.int8(e_contact), dict(
                yes_no, long_name="exact model: the orbit reaches the support")),
            "exact_status": ((), np.int64(estatus[0]), status_flags(
                long_name="exact model: kernel status")),
            "exact_self_distance": ((), float(e_self), {
                "long_name": "distance between the two halves of the exact section points",
                "units": "1"}),
            "recommended_eta": ((), recommended, {
                "long_name": "largest eta that agrees with the exact model (NaN: none)",
                "units": "1"}),
        },
        coords={
            "eta": ("eta", eta_vals, {"long_name": "band half-width eta (eq. 14)", "units": "1"}),
            "n": ("n", np.arange(record), {"long_name": "section point index"}),
            "sample": ("sample", np.arange(orbit_periods * spp),
                       {"long_name": "orbit sample index"}),
            "t_section": ("n", t_sec, {"long_name": "time of the section point", "units": "s"}),
            "orbit_t": ("sample", t_orb, {"long_name": "time of the orbit sample",
                                          "units": "s"}),
        },
        attrs=provenance_attrs(
            params, smooth, analysis="eta_study", transient=transient, record=record,
            orbit_periods=orbit_periods, samples_per_period=spp, x0=float(x0),
            v0=float(v0), distance_tol=float(distance_tol),
            distance_definition="symmetric mean nearest-neighbour distance in (X, V/omega)",
            agreement_rule="reaches_gamma_plus and period equal to the exact model's and "
                           "distance_to_exact <= distance_tol + 2 exact_self_distance",
            exact_method="exact", forcing_period=T),
    )
    del ds.attrs["param_eta"]  # swept: the coordinate eta
    return ds
