"""The eta audit: which band half-widths eta let the smoothed switch model reproduce the exact
non-smooth dynamics (the paper's Fig. 4 question, answered against the eta = 0 solution).

``eta_study(params, etas)`` integrates, from the same initial state, the smoothed model
(``method="smooth"``) for every eta and the exact event-driven model (``method="exact"``)
once, discards ``transient`` forcing periods and records ``points`` stroboscopic section points
(t = kT, forcing phase 0) plus a phase portrait of ``portrait_periods`` periods.

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

Attribute ``recommended_eta``: the largest eta that agrees with the exact model (NaN if none).
The exact orbit's section, portrait, period and contact flag are stored as ``exact_*``.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from ..errors import ParameterError
from ..io import provenance_attrs
from ..kernels import Solver, new_state
from ..models.switch import GAMMA_PLUS, REGION_LEGEND
from ..params import Params
from ..sweep import run_trajectories
from .periodicity import detect_period, section_tolerance

#: Largest period looked for in the section points.
MAX_PERIOD = 64
#: Tolerances the exact model's section is classified with (it is exact to round-off; a
#: settled periodic orbit repeats to ~1e-13, so this is far from both round-off and chaos).
EXACT_RTOL = 1e-10
EXACT_ATOL = 1e-12


def check_etas(etas) -> np.ndarray:
    """The eta values as a float array; one-line ParameterError naming ``eta`` otherwise."""
    if etas is None or isinstance(etas, (str, bytes)):
        raise ParameterError(f"eta: expected a list of band half-widths, got {etas!r}")
    try:
        vals = [float(e) for e in np.atleast_1d(np.asarray(etas, dtype=object)).ravel()]
    except (TypeError, ValueError):
        raise ParameterError(f"eta: expected numbers, got {etas!r}") from None
    if not vals:
        raise ParameterError("eta: give at least one value (0 < eta < 0.5)")
    for v in vals:
        if not (math.isfinite(v) and 0.0 < v < 0.5):
            raise ParameterError(f"eta: every value must satisfy 0 < eta < 0.5, got {v!r}")
    if len(set(vals)) != len(vals):
        raise ParameterError(f"eta: values must be distinct, got {vals}")
    return np.array(vals, dtype=np.float64)


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


def _integrate(P, solver, x0, v0, transient, points, portrait_periods, spp, workers):
    """Section (per period) and portrait (spp per period) of each row of P."""
    n = P.shape[0]
    states = np.tile(new_state(x0, v0), (n, 1))
    sec = run_trajectories(P, solver, states, per_period=1, n_skip=transient, n_out=points,
                           workers=workers)
    por = run_trajectories(P, solver, sec["state"], per_period=spp, n_skip=0,
                           n_out=portrait_periods * spp, workers=workers)
    status = np.where(sec["status"] != 0, sec["status"], por["status"])
    return sec, por, status


def eta_study(params: Params, etas, *, transient: int = 300, points: int = 200,
              portrait_periods: int = 10, samples_per_period: int = 200, x0: float = 0.0,
              v0: float = 0.0, rtol: float = 1e-8, atol: float = 1e-10,
              distance_tol: float = 1e-3, transition: str = "eq13",
              workers: int | None = None) -> xr.Dataset:
    """Audit the band half-width eta of the smoothed model against the exact model.

    See the module documentation for the variables and the agreement criterion.
    """
    if not isinstance(params, Params):
        raise ParameterError(f"params: expected nonsmooth.Params, got {type(params).__name__}")
    eta_vals = check_etas(etas)
    transient = _check_count("transient", transient, 0)
    points = _check_count("points", points, 2)
    portrait_periods = _check_count("portrait_periods", portrait_periods, 1)
    spp = _check_count("samples_per_period", samples_per_period, 1)
    for name, v in (("x0", x0), ("v0", v0), ("distance_tol", distance_tol)):
        if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)) \
                or not math.isfinite(float(v)):
            raise ParameterError(f"{name}: expected a finite number, got {v!r}")
    if distance_tol < 0:
        raise ParameterError(f"distance_tol: must be >= 0, got {distance_tol}")
    smooth = Solver(method="smooth", rtol=rtol, atol=atol, transition=transition)
    exact = Solver(method="exact")

    P = np.stack([params.replace(eta=float(e)).pack() for e in eta_vals])
    sec, por, status = _integrate(P, smooth, float(x0), float(v0), transient, points,
                                  portrait_periods, spp, workers)
    esec, epor, estatus = _integrate(params.pack()[None, :], exact, float(x0), float(v0),
                                     transient, points, portrait_periods, spp, workers)
    om = params.omega

    # ---- exact reference ----
    eX, eV = esec["X"][0], esec["V"][0]
    e_ok = int(estatus[0]) == 0
    e_contact = int(bool(np.any(esec["M"][0] & (1 << GAMMA_PLUS)))) if e_ok else 0
    e_period = _period(eX, eV, EXACT_RTOL, EXACT_ATOL) if e_ok else 0
    h = points // 2
    e_self = set_distance(eX[:h], eV[:h] / om, eX[h:], eV[h:] / om) if e_ok else float("nan")
    if e_period > 0:
        e_self = 0.0

    # ---- per eta ----
    n = len(eta_vals)
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
        reach[i] = int(bool(visited[i] & (1 << GAMMA_PLUS)))
        period[i] = _period(X, V, rtol, atol)
        if e_ok:
            dist[i] = set_distance(X, V / om, eX, eV / om)
            agrees[i] = int(reach[i] == e_contact and period[i] == e_period
                            and dist[i] <= distance_tol + 2.0 * e_self)
    good = eta_vals[agrees == 1]
    recommended = float(good.max()) if good.size else float("nan")

    t_sec = (transient + np.arange(1, points + 1)) * params.period
    ds = xr.Dataset(
        {
            "reaches_gamma_plus": ("eta", reach, {
                "long_name": "settled smoothed orbit enters Gamma+ (1) or not (0)"}),
            "period": ("eta", period, {"long_name": "period of the section points (0 = none)",
                                       "units": "forcing periods"}),
            "distance_to_exact": ("eta", dist, {
                "long_name": "symmetric mean nearest-neighbour distance of the section points "
                             "to the exact ones in (X, V/omega)", "units": "1 (gap)"}),
            "agrees": ("eta", agrees, {"long_name": "same contact, same period and distance "
                                                    "within tolerance (1) or not (0)"}),
            "regions_visited": ("eta", visited, {
                "long_name": "regions visited during the recorded periods",
                "legend": "bit mask, bit r set = region code r visited; " + REGION_LEGEND}),
            "status": ("eta", np.asarray(status, np.int64), {"long_name": "kernel status (0 = ok)"}),
            "section_X": (("eta", "n"), sec["X"], {"long_name": "X at t = kT", "units": "1"}),
            "section_V": (("eta", "n"), sec["V"], {"long_name": "V at t = kT", "units": "1/s"}),
            "portrait_X": (("eta", "sample"), por["X"], {"long_name": "X", "units": "1"}),
            "portrait_V": (("eta", "sample"), por["V"], {"long_name": "V", "units": "1/s"}),
            "portrait_region": (("eta", "sample"), por["R"], {
                "long_name": "region at the sample", "legend": REGION_LEGEND}),
            "portrait_visited": (("eta", "sample"), por["M"], {
                "long_name": "regions visited since the previous sample",
                "legend": "bit mask, bit r set = region code r visited"}),
            "exact_section_X": ("n", eX, {"long_name": "exact model: X at t = kT", "units": "1"}),
            "exact_section_V": ("n", eV, {"long_name": "exact model: V at t = kT",
                                          "units": "1/s"}),
            "exact_portrait_X": ("sample", epor["X"][0], {"long_name": "exact model: X",
                                                          "units": "1"}),
            "exact_portrait_V": ("sample", epor["V"][0], {"long_name": "exact model: V",
                                                          "units": "1/s"}),
            "exact_portrait_region": ("sample", epor["R"][0], {
                "long_name": "exact model: mode at the sample (0 free flight, 3 contact)"}),
        },
        coords={
            "eta": ("eta", eta_vals, {"long_name": "band half-width eta (eq. 14)", "units": "1"}),
            "n": ("n", np.arange(points), {"long_name": "section point index"}),
            "sample": ("sample", np.arange(portrait_periods * spp),
                       {"long_name": "portrait sample index"}),
            "t_section": ("n", t_sec, {"long_name": "time of the section point", "units": "s"}),
        },
        attrs=provenance_attrs(
            params, smooth, analysis="eta_study", transient=transient, points=points,
            portrait_periods=portrait_periods, samples_per_period=spp, x0=float(x0),
            v0=float(v0), distance_tol=float(distance_tol),
            distance_definition="symmetric mean nearest-neighbour distance in (X, V/omega)",
            agreement_rule="reaches_gamma_plus and period equal to the exact model's and "
                           "distance_to_exact <= distance_tol + 2 exact_self_distance",
            recommended_eta=recommended, exact_status=int(estatus[0]),
            exact_period=int(e_period), exact_reaches_gamma_plus=int(e_contact),
            exact_self_distance=float(e_self), exact_method="exact",
            forcing_period=params.period, region_legend=REGION_LEGEND),
    )
    return ds
