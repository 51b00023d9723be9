"""Attractors followed across a parameter, with their basin shares (issue 21, item 3).

``attractor_continuation(params, "omega", values, x=..., v=..., grid=40) -> xarray.Dataset``

At each value of the parameter the attractors are found by sampling a grid of initial
conditions (:func:`nonsmooth.basins`: periodic and chaotic attractors, no list supplied, each
with the share of the grid that reaches it). They are then matched to the attractors of the
previous value by the distance of their section sets,

    d(A, B) = max(mean_a min_b |a - b|, mean_b min_a |a - b|)

(points of the stroboscopic section in (X, V), and in every further state component of a model
with more: a mean Hausdorff distance, small between an orbit and its continuation, also through
a period doubling, where one section point splits into two). Pairs are matched greedily from the
nearest, each attractor at most once, and only within ``match_tol`` (default: a tenth of the
grid window's diagonal). An attractor left unmatched at a value is *born* there; one alive at
the previous value and unmatched is *dead* there. Each attractor keeps one label (``attractor``)
from its birth to its death.

This is the brute-force counterpart of :func:`nonsmooth.continuation` (which follows one orbit,
stable or not, through its folds): it sees only attractors, but all of them, with how likely
each one is from the window of initial conditions, and it needs no starting orbit. An attractor
whose basin misses every grid point at some value vanishes there and comes back as a new label;
a finer grid, or values closer together, keep it.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from ..errors import ParameterError
from ..io import apply_state_units, clean_attrs


def section_sets(ds) -> list:
    """The section points of each attractor of a basins Dataset: arrays (points, components)
    over X, V and every further ``attractor_<name>`` component, NaN padding dropped."""
    names = ["attractor_X", "attractor_V"]
    extra = [k for k in ds.data_vars if k.startswith("attractor_") and k not in names
             and ds[k].dims == ("attractor", "n")]
    out = []
    for k in range(ds.sizes.get("attractor", 0)):
        cols = [np.asarray(ds[nm].values[k], dtype=float) for nm in names + extra]
        pts = np.stack(cols, axis=1)
        out.append(pts[np.all(np.isfinite(pts), axis=1)])
    return out


def set_distance(a, b) -> float:
    """max(mean_a min_b |a - b|, mean_b min_a |a - b|) of two point sets (rows)."""
    if len(a) == 0 or len(b) == 0:
        return math.inf
    d = np.sqrt(((a[:, None, :] - b[None, :, :]) ** 2).sum(axis=2))
    return float(max(d.min(axis=1).mean(), d.min(axis=0).mean()))


def match(prev, new, tol) -> dict:
    """{index in new: index in prev}: greedy from the nearest pair, each at most once, only
    within ``tol``."""
    pairs = sorted((set_distance(a, b), i, j) for j, a in enumerate(prev)
                   for i, b in enumerate(new))
    out, used = {}, set()
    for d, i, j in pairs:
        if d <= tol and i not in out and j not in used:
            out[i] = j
            used.add(j)
    return out


def _value_chunk(spec, i, carry, workers=None, progress=None):
    """Chunk i of attractor_continuation: the basins at the i-th value (a Dataset, stored
    pickled with every bit)."""
    from ..chunks import solver_from_spec
    from .basins import basins
    m = solver_from_spec(spec["solver"]).model
    params = m.params(**spec["params"]).replace(**{spec["param"]: float(spec["values"][i])})
    return {"basins": basins(params, x=tuple(spec["x"]), v=tuple(spec["v"]), grid=spec["grid"],
                             method=spec["method"], lyapunov=False, workers=workers,
                             **spec["basins_kw"])}


def _check_values(param, values) -> np.ndarray:
    vals = np.asarray(values, dtype=np.float64)
    if vals.ndim != 1 or vals.size < 2:
        raise ParameterError(f"values: give at least two values of {param}, got {vals.size}")
    if not np.all(np.isfinite(vals)):
        raise ParameterError(f"values: the values of {param} must be finite")
    step = np.diff(vals)
    if not (np.all(step > 0) or np.all(step < 0)):
        raise ParameterError(f"values: the values of {param} must increase or decrease "
                             f"strictly (a path to follow)")
    return vals


def attractor_continuation(params, param: str, values, *, x=(-3.0, 3.0), v=(-3.0, 3.0),
                           grid=40, method: str = "smooth", match_tol: float | None = None,
                           progress=None, store=None, engine=None, workers: int | None = None,
                           **basins_kw) -> xr.Dataset:
    """The attractors at each of ``values`` of ``param`` (``basins`` on the window ``x`` x
    ``v`` with ``grid`` points per axis; further keywords such as ``transient``,
    ``max_periods``, ``rtol``, ``axes``, ``u0`` go to :func:`nonsmooth.basins`),
    matched from value to value (see the module documentation; ``match_tol``: the largest
    distance of two section sets taken as one attractor).

    Returns a Dataset over (``param``, ``attractor``): ``fraction`` (share of the grid that
    reaches it; 0 where it does not exist), ``exists``, ``period`` (0 chaotic, -1 absent),
    ``kind``, ``contact`` (-1 absent), ``max_X`` (NaN absent), the section points
    ``section_X``/``section_V`` (param, attractor, n); per value ``undecided_fraction`` and
    ``n_attractors``; per attractor ``born`` and ``died`` (the first value where it exists
    after not existing, and where it no longer exists after existing; NaN: from the first
    value on, or to the last).

    ``store`` / ``engine``: chunked, resumable runs (one chunk per value: its basins) and
    where they run (``nonsmooth.chunks``; on Dask the values run side by side); ``workers``:
    threads per value (None: all cores). The matching runs on the finished values."""
    from ..simulate import check_forced, check_params
    from ..sweep import progress_callback
    from .basins import basins
    params = check_params(params)
    check_forced(params, "attractor_continuation")
    p = params.model.param(param)
    vals = _check_values(p.name, values)
    for w in (vals[0], vals[-1]):
        params.replace(**{p.name: float(w)})  # a value out of the parameter's range: one line
    if match_tol is not None:
        from ..checks import check_positive
        match_tol = check_positive("match_tol", match_tol)  # (the CLI's check, its message)
    if "lyapunov" in basins_kw:
        raise ParameterError("lyapunov: not an option here (each value's basins run without "
                             "the evidence; run basins at a value for it)")
    progress = progress_callback(progress, "attractors")
    from ..chunks import Plan, check_engine, execute, plan_solver
    from ..kernels import Solver
    engine = check_engine(engine)
    spec = {"solver": plan_solver(Solver(method=method, model=params.model), engine),
            "params": params.as_dict(), "param": p.name, "values": vals,
            "x": [float(b) for b in x], "v": [float(b) for b in v], "grid": grid,
            "method": method, "basins_kw": basins_kw}
    plan = Plan("attractor_continuation", spec, len(vals), _value_chunk, spec)
    runs = [None] * len(vals)
    execute(plan, lambda i, res: runs.__setitem__(i, res["basins"]), store=store,
            engine=engine, workers=workers, progress=progress)
    b0 = runs[0]
    diag = math.hypot(float(b0.x0[-1] - b0.x0[0]), float(b0.v0[-1] - b0.v0[0]))
    tol = 0.1 * diag if match_tol is None else float(match_tol)

    ids_per_value, sets_prev, ids_prev, next_id = [], [], [], 0
    for ds in runs:
        sets = section_sets(ds)
        m = match(sets_prev, sets, tol)
        ids = []
        for k in range(len(sets)):
            if k in m:
                ids.append(ids_prev[m[k]])
            else:
                ids.append(next_id)
                next_id += 1
        ids_per_value.append(ids)
        sets_prev, ids_prev = sets, ids
    nv, na = len(vals), next_id
    npt = max([r.sizes.get("n", 0) for r in runs] + [1])
    frac = np.zeros((nv, na))
    exists = np.zeros((nv, na), np.int8)
    period = np.full((nv, na), -1, np.int32)
    kind = np.full((nv, na), -1, np.int8)
    contact = np.full((nv, na), -1, np.int8)
    max_x = np.full((nv, na), np.nan)
    SX = np.full((nv, na, npt), np.nan)
    SV = np.full((nv, na, npt), np.nan)
    undecided = np.zeros(nv)
    for i, (ds, ids) in enumerate(zip(runs, ids_per_value)):
        undecided[i] = float(ds.undecided_fraction)
        for k, a in enumerate(ids):
            frac[i, a] = float(ds.fraction[k])
            exists[i, a] = 1
            period[i, a] = int(ds.period[k])
            kind[i, a] = int(ds.kind[k])
            contact[i, a] = int(ds.contact[k])
            max_x[i, a] = float(ds.max_X[k])
            q = ds.sizes["n"]
            SX[i, a, :q] = ds.attractor_X.values[k]
            SV[i, a, :q] = ds.attractor_V.values[k]
    born = np.full(na, np.nan)
    died = np.full(na, np.nan)
    for a in range(na):
        alive = np.flatnonzero(exists[:, a])
        if alive[0] > 0:
            born[a] = vals[alive[0]]
        if alive[-1] < nv - 1:
            died[a] = vals[alive[-1] + 1]
    punits = p.units or "1"
    attrs = {k: val for k, val in b0.attrs.items()
             if k != f"param_{p.name}" and k not in (
                 "n_attractors", "total_periods", "mean_periods_used", "certification_periods",
                 "certified_cells", "lattice_cells", "forcing_period", "analysis")}
    attrs.update(analysis="attractor_continuation", continuation_parameter=p.name,
                 match_tol=tol, attractors_found=na)
    flags = lambda names, **kw: {"flag_values": np.arange(-1, len(names) - 1, dtype=np.int8),  # noqa: E731
                                 "flag_meanings": " ".join(names), **kw}
    ds = xr.Dataset(
        {
            "fraction": ((p.name, "attractor"), frac, {
                "long_name": "share of the grid's initial conditions that reach the attractor "
                             "(0: it does not exist)", "units": "1"}),
            "exists": ((p.name, "attractor"), exists, {
                "long_name": "the attractor exists at the value", "flag_values":
                np.array([0, 1], np.int8), "flag_meanings": "absent present"}),
            "period": ((p.name, "attractor"), period, {
                "long_name": "period in forcing periods (0 = chaotic, -1 = absent)",
                "units": "1"}),
            "kind": ((p.name, "attractor"), kind, flags(("absent", "periodic", "chaotic"),
                                                        long_name="kind of attractor")),
            "contact": ((p.name, "attractor"), contact, flags(
                ("absent", "no_contact", "contact"),
                long_name="the orbit reaches the contact (the model's contact test)")),
            "max_X": ((p.name, "attractor"), max_x, {"long_name": "largest X on the orbit"}),
            "section_X": ((p.name, "attractor", "n"), SX, {
                "long_name": "section points X (t = kT), NaN-padded"}),
            "section_V": ((p.name, "attractor", "n"), SV, {
                "long_name": "section points V (t = kT), NaN-padded"}),
            "undecided_fraction": ((p.name,), undecided, {
                "long_name": "share of the grid undecided or failed", "units": "1"}),
            "n_attractors": ((p.name,), exists.sum(axis=1).astype(np.int32), {
                "long_name": "attractors found at the value", "units": "1"}),
            "born": (("attractor",), born, {
                "long_name": f"first value of {p.name} where the attractor exists after not "
                             f"existing (NaN: from the first value)", "units": punits}),
            "died": (("attractor",), died, {
                "long_name": f"first value of {p.name} where the attractor no longer exists "
                             f"(NaN: to the last value)", "units": punits}),
        },
        coords={p.name: (p.name, vals, {"long_name": p.long_name or p.name, "units": punits}),
                "attractor": ("attractor", np.arange(na),
                              {"long_name": "attractor label along the path"})},
        attrs=clean_attrs(attrs),
    )
    return apply_state_units(ds, params.model)
