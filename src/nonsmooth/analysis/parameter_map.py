"""Two-parameter maps: what the settled motion is at every point of a grid of two parameters
(the period, chaos, the largest exponent, the amplitude and whether the support is reached).

``parameter_map(params, x=("omega", 0.8, 1.0, 400), y=("F0", 0.15, 0.45, 400))`` runs, at each
grid point, ``transient`` forcing periods (ended early once the section has provably settled)
and records ``record`` section points, classified as in the bifurcation diagrams
(:func:`.bifurcation.summarize`: sections still converging are integrated further; period
-1 = not settled), with lambda1 over ``record`` further periods of the attractor and the
verdict ``motion`` (:func:`.stability.classify_points`).

Starting states (``start``): ``"fresh"``: every point from (x0, v0) (all points independent);
``"continued"``: along each row of the grid (fixed y) the state is carried from one x value to
the next in increasing x, as the up sweeps of the bifurcation diagrams do (the first x value of
a row starts from (x0, v0)), so a row follows a branch through its coexistence region.

The grid is computed in chunks (``nonsmooth.chunks``): blocks of points (fresh) or of whole
rows (continued), whose layout depends only on the grid; each chunk's result is reduced to the
per-point variables at once, so memory holds the output arrays and a few chunks.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from ..checks import STARTS, check_axis  # noqa: F401 (re-exported)
from ..errors import ParameterError
from ..kernels import Solver
from ..models.base import ParamsBase

#: Points per chunk of a fresh map: at least MAP_CHUNK, and at most MAX_CHUNKS chunks.
MAP_CHUNK = 1024
MAX_CHUNKS = 4000
#: Rows per chunk of a continued map: at least ROW_CHUNK and about MAP_CHUNK * 4 points.
ROW_CHUNK = 8
#: Output variables per point: name -> dtype.
OUTPUTS = {"period": np.int32, "max_X": np.float64, "min_X": np.float64, "contact": np.int8,
           "status": np.int64, "transient_used": np.int32}
LYAPUNOV_OUTPUTS = {"lambda1": np.float64, "lambda1_stderr": np.float64, "motion": np.int8}
#: Bytes per grid point of the output arrays (memory check).
_BYTES_PER_POINT = 64


def _layout(ny: int, nx: int, start: str, chunk: int | None = None):
    """Chunk bounds over points (fresh, row-major) or rows (continued); ``chunk`` points or
    rows per chunk (default: from the grid alone)."""
    from ..chunks import chunk_bounds
    if start == "fresh":
        n = nx * ny
        return chunk_bounds(n, chunk or max(MAP_CHUNK, math.ceil(n / MAX_CHUNKS)))
    return chunk_bounds(ny, chunk or max(ROW_CHUNK, math.ceil(4 * MAP_CHUNK / nx)))


def _map_chunk(spec, i, carry, workers=None, progress=None):
    """Chunk ``i`` of :func:`parameter_map` (a ``chunks.Plan`` task): the per-point
    variables of its points (fresh: a block of points; continued: a block of rows)."""
    from ..chunks import solver_from_spec
    from ..kernels import new_state
    from .bifurcation import sweep_block
    solver = solver_from_spec(spec["solver"])
    a, b = spec["bounds"][i]
    xs, ys, base = spec["xs"], spec["ys"], spec["base"]
    nx = xs.size
    if spec["start"] == "fresh":
        k = np.arange(a, b)
        P = np.tile(base, (b - a, 1))
        P[:, spec["ix"]] = xs[k % nx]
        P[:, spec["iy"]] = ys[k // nx]
        P = P[:, None, :]
    else:
        P = np.tile(base, (b - a, nx, 1))
        P[:, :, spec["ix"]] = xs[None, :]
        P[:, :, spec["iy"]] = ys[a:b, None]
    init = new_state(spec["x0"], spec["v0"], tuple(spec.get("u0_extra", ())))
    states = np.tile(init, (P.shape[0], 1))
    out = sweep_block(np.ascontiguousarray(P), solver, states, init, spec["transient"],
                      spec["settle_tol"], spec["record"], spec["lyapunov"], floquet=True,
                      workers=workers, progress=progress)
    out["transient_used"] = out.pop("used")
    names = list(OUTPUTS) + (list(LYAPUNOV_OUTPUTS) if spec["lyapunov"] else [])
    return {k: out[k].astype(OUTPUTS.get(k) or LYAPUNOV_OUTPUTS[k]).reshape(-1)
            for k in names}


def parameter_map(params: ParamsBase, x=None, y=("F0", 0.15, 0.45, 100), *,
                  transient: int = 500, record: int = 100, method: str = "smooth",
                  start: str = "fresh", x0: float = 0.0, v0: float = 0.0, rtol: float = 1e-8,
                  atol: float = 1e-10, settle: bool = True,
                  max_steps: int = 200_000, lyapunov: bool | None = None,
                  workers: int | None = None, progress=None, store=None,
                  engine=None, chunk: int | None = None,
                  section_phase: float = 0.0, u0=None) -> xr.Dataset:
    """Map of the settled motion over a grid of two parameters (see the module docstring).
    Points start from (x0, v0), or from ``u0`` (every component, see ``simulate``).

    ``x``, ``y``: (parameter, min, max, n) of the two axes (any parameters of the model, n >= 1
    values from min to max); ``x`` defaults to the forcing frequency from 0.8 to 1.0 (a
    model with a forcing period: that period from 2 pi / 1.0 to 2 pi / 0.8), 100 values. ``start``: "fresh" or "continued" (along x). ``lyapunov`` (None:
    where tangent dynamics exist): also ``lambda1``, ``lambda1_stderr`` and ``motion``.
    ``store``: a directory where finished chunks are written; the same call with the same
    store resumes (``nonsmooth.chunks``). ``engine``: None (all local cores), "local[:N]", a
    Dask scheduler address or a ``dask.distributed.Client``; the numbers do not depend on it,
    nor on ``workers``. ``chunk``: points (fresh) or rows (continued) per chunk, the unit of
    resumption and of Dask tasks (default: from the grid size alone; part of the identity of
    a stored run).

    Returns a Dataset over (y parameter, x parameter) with ``period`` (0 = not periodic, -1 =
    not settled), ``max_X``, ``min_X``, ``contact``, ``status`` (0 = ok; failed points have
    NaN data and period 0), ``transient_used`` and, with lambda1, ``lambda1``,
    ``lambda1_stderr``, ``motion`` (periodic / quasi-periodic / chaotic / not settled).
    ``progress`` (None or False: silent; True: a progress bar with a time estimate on a terminal,
    plain lines elsewhere; or a callable ``progress(done, total)``): reports the work done.
    """
    from ..simulate import check_forced
    check_forced(params, "parameter_map")
    from ..sweep import progress_callback
    progress = progress_callback(progress, "map")
    from ..chunks import Plan, check_engine, execute, plan_solver
    from ..io import check_memory
    from ..simulate import check_admissible, check_int, check_params, initial_u, start_attrs
    from .poincare import settle_tolerance
    from .stability import wants_lyapunov
    params = check_params(params)
    if x is None:
        x = (params.model.forcing_param, *params.model.forcing_range(0.8, 1.0), 100)
    xname, xs = check_axis("x", x, params)
    yname, ys = check_axis("y", y, params)
    if xname == yname:
        raise ParameterError(f"y: the two axes need different parameters, both are {xname!r}")
    if start not in STARTS:
        raise ParameterError(f"start: expected one of {', '.join(STARTS)}, got {start!r}")
    transient = check_int("transient", transient, 0)
    record = check_int("record", record, 1)
    u = initial_u(params.model, x0, v0, u0)
    x0, v0 = float(u[0]), float(u[1])
    engine = check_engine(engine)
    for xv in (xs[0], xs[-1]):  # every constraint is an interval per parameter: the corners
        for yv in (ys[0], ys[-1]):
            params.replace(**{xname: float(xv), yname: float(yv)})
    ny, nx = ys.size, xs.size
    check_memory(_BYTES_PER_POINT * nx * ny, "x n",
                 f"a {ny} x {nx} map holds {nx * ny} points; use fewer points per axis",
                 size=(nx, 1))
    solver = Solver(model=params.model, method=method, rtol=rtol, atol=atol,
                    max_steps=max_steps, section_phase=section_phase)
    check_admissible(solver, params, u)
    lyap = wants_lyapunov(lyapunov, solver)
    if chunk is not None:
        chunk = check_int("chunk", chunk, 1)
    bounds = _layout(ny, nx, start, chunk)
    in_chunk = (bounds[0][1] - bounds[0][0]) * (1 if start == "fresh" else nx)
    check_memory(34.0 * in_chunk * record * 2, "record",
                 f"a chunk of {in_chunk} points keeps {record:,} section points each; record "
                 f"fewer periods (or use a smaller --chunk)", size=(record, 1))
    index = params.model.index
    spec = {"solver": plan_solver(solver, engine), "xs": xs, "ys": ys, "base": params.pack(),
            "ix": index[xname], "iy": index[yname], "start": start, "x0": x0, "v0": v0,
            **({"u0_extra": [float(e) for e in u[2:]]} if len(u) > 2 else {}),
            "transient": transient, "record": record,
            "settle_tol": settle_tolerance(solver, settle), "lyapunov": lyap,
            "bounds": bounds}
    per_unit = (transient + record) * (1 if start == "fresh" else nx)
    plan = Plan("parameter_map", {k: v for k, v in spec.items()
                                  if k not in ("bounds", "base", "ix", "iy")} | {
        "params": dict(zip(params.model.param_names, spec["base"])), "x": xname, "y": yname,
        "settle": bool(settle), "chunk": bounds[0][1] - bounds[0][0]},
        len(bounds), _map_chunk, spec, weights=[(b - a) * per_unit for a, b in bounds])
    names = {**OUTPUTS, **(LYAPUNOV_OUTPUTS if lyap else {})}
    out = {k: np.empty(nx * ny, dt) for k, dt in names.items()}
    scale = 1 if start == "fresh" else nx

    def collect(i, res):
        a, b = bounds[i]
        for k in names:
            out[k][a * scale:b * scale] = res[k]
    execute(plan, collect, store=store, engine=engine, workers=workers, progress=progress)
    return _dataset(params, solver, xname, xs, yname, ys,
                    {k: v.reshape(ny, nx) for k, v in out.items()},
                    dict(analysis="parameter_map", start=start, transient=transient,
                         record=record, **start_attrs(u), settle=settle, x_param=xname,
                         y_param=yname))


def _dataset(params, solver, xname, xs, yname, ys, out, attrs) -> xr.Dataset:
    from ..io import flag_attrs, provenance_attrs, status_flags
    from .poincare import MAX_PERIOD, PERIOD_LONG_NAME
    from .stability import lyapunov_attrs
    dims = (yname, xname)
    lyap = {k: (dims, out[k], a) for k, a in lyapunov_attrs(attrs["record"], solver).items()
            if k in out}
    if "lambda1" in lyap:
        lyap["lambda1"][2]["periods"] = attrs["record"]

    def coord(name, values):
        spec = params.model.param(name)
        return (name, values, {"long_name": spec.long_name, "units": spec.units})
    ds = xr.Dataset(
        {
            "period": (dims, out["period"], {"long_name": PERIOD_LONG_NAME, "units": "1"}),
            "max_X": (dims, out["max_X"], {"long_name": "largest X over the recorded periods",
                                          "units": "1"}),
            "min_X": (dims, out["min_X"], {"long_name": "smallest X over the recorded periods",
                                          "units": "1"}),
            "contact": (dims, out["contact"], flag_attrs(
                ("no_contact", "contact"), dtype=np.int8,
                long_name=f"{params.model.contact_name} during the recorded periods")),
            "status": (dims, out["status"], status_flags(long_name="kernel status")),
            "transient_used": (dims, out["transient_used"], {
                "long_name": "forcing periods integrated before the recorded window",
                "units": "1"}),
            **lyap,
        },
        coords={xname: coord(xname, xs), yname: coord(yname, ys)},
        attrs=provenance_attrs(params, solver, swept=(xname, yname), max_period=MAX_PERIOD,
                               n_failed=int(np.count_nonzero(out["status"])), **attrs),
    )
    from ..io import apply_state_units
    return apply_state_units(ds, params.model)


def regimes(ds, max_shown: int = 8):
    """Categories of a map for a legend: (codes (y, x), names) where code k < max_shown is
    "period k+1", then "period > max_shown", "quasi-periodic", "chaotic",
    "non-periodic" (no lambda1 to decide), "not settled", "failed"."""
    period = ds.period.values
    motion = ds.motion.values if "motion" in ds else None
    names = [f"period {k}" for k in range(1, max_shown + 1)] + [
        f"period > {max_shown}", "quasi-periodic", "chaotic", "non-periodic", "not settled",
        "failed"]
    code = np.full(period.shape, names.index("non-periodic"), np.int16)
    code[(period >= 1) & (period <= max_shown)] = period[(period >= 1) & (period <= max_shown)] - 1
    code[period > max_shown] = names.index(f"period > {max_shown}")
    code[period < 0] = names.index("not settled")
    if motion is not None:
        from .stability import CHAOTIC, NOT_SETTLED, QUASI_PERIODIC
        np_ = period == 0
        code[np_ & (motion == QUASI_PERIODIC)] = names.index("quasi-periodic")
        code[np_ & (motion == CHAOTIC)] = names.index("chaotic")
        code[np_ & (motion == NOT_SETTLED)] = names.index("not settled")
    code[ds.status.values != 0] = names.index("failed")
    return code, names
