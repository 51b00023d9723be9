"""Checks of plain arguments (counts, numbers, parameters, forcing, a sweep's memory): one-line
ParameterErrors naming the field. A light module (no kernels imported), so that the CLI checks a
command's options before it imports the analyses, whose kernels compile on a fresh machine."""

from __future__ import annotations

import math

import numpy as np

from .errors import ParameterError
from .models.base import ParamsBase

#: the sweep directions of ``bifurcation_diagram``
SWEEPS = ("up", "down", "both", "fresh")
#: the starts of ``parameter_map``
STARTS = ("fresh", "continued")


def check_int(name: str, value, minimum: int) -> int:
    """``value`` as an int >= minimum, else a one-line ParameterError naming ``name``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        if isinstance(value, (float, np.floating)) and float(value).is_integer():
            value = int(value)
        else:
            raise ParameterError(f"{name}: expected a whole number, got {value!r}")
    if value < minimum:
        raise ParameterError(f"{name}: must be >= {minimum}, got {value}")
    return int(value)


def check_float(name: str, value) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: expected a number, got {value!r}") from None
    if not math.isfinite(v):
        raise ParameterError(f"{name}: must be finite, got {v}")
    return v


def check_positive(name: str, value) -> float:
    """``value`` as a finite float > 0, else a one-line ParameterError naming ``name``."""
    v = check_float(name, value)
    if not v > 0:
        raise ParameterError(f"{name}: must be > 0, got {v:g}")
    return v


def check_window(x, v):
    """A window ((x_lo, x_hi), (v_lo, v_hi)) of two state components, or None for neither;
    one-line ParameterErrors name ``x`` or ``v``."""
    if x is None and v is None:
        return None
    if x is None or v is None:
        raise ParameterError("x: give both x and v (the window), or neither")
    out = []
    for name, r in (("x", x), ("v", v)):
        try:
            lo, hi = (float(b) for b in r)
        except (TypeError, ValueError):
            raise ParameterError(f"{name}: expected (low, high), got {r!r}") from None
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise ParameterError(f"{name}: expected finite low < high, got ({lo:g}, {hi:g})")
        out.append((lo, hi))
    return tuple(out)


def check_solver_options(rtol=1e-8, atol=1e-10, section_phase=0.0) -> float:
    """The integration tolerances (0 < rtol, atol < 1) and the section's forcing phase
    (0 <= psi < 2 pi, radians) of a ``kernels.Solver``; returns the phase as a float."""
    for name, v in (("rtol", rtol), ("atol", atol)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and 0 < v < 1):
            raise ParameterError(f"{name}: must satisfy 0 < {name} < 1, got {v!r}")
    ph = section_phase
    if isinstance(ph, bool) or not isinstance(ph, (int, float, np.floating, np.integer)) \
            or not (math.isfinite(ph) and 0.0 <= ph < 2.0 * math.pi):
        raise ParameterError(f"section_phase: must satisfy 0 <= section_phase < 2 pi "
                             f"(radians), got {ph!r}")
    return float(ph)


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


def check_range(name: str, r) -> tuple[float, float]:
    """A (min, max) pair of finite numbers with min < max (a grid's window), else a one-line
    ParameterError naming ``name``."""
    try:
        lo, hi = r
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: expected a (min, max) pair, got {r!r}") from None
    lo = check_float(f"{name} min", lo)
    hi = check_float(f"{name} max", hi)
    if not hi > lo:
        raise ParameterError(f"{name}: empty or reversed range ({lo:g}, {hi:g}); need min < max")
    return lo, hi


def check_grid(grid) -> tuple[int, int]:
    """(nx, nv) of a grid of initial conditions given as an int or a pair, each >= 2."""
    if isinstance(grid, (tuple, list, np.ndarray)):
        if len(grid) != 2:
            raise ParameterError(f"grid: expected an int or an (nx, nv) pair, got {grid!r}")
        return check_int("grid nx", grid[0], 2), check_int("grid nv", grid[1], 2)
    g = check_int("grid", grid, 2)
    return g, g


def check_axes(model, axes) -> tuple[int, int]:
    """The indices of the two different state components ``axes`` names ("X,Y" or a pair;
    None: the first two) of ``model``; a one-line ParameterError naming ``axes`` otherwise."""
    names = model.state_names
    parts = component_pair(axes, names, "axes") or names[:2]
    ia, ib = (names.index(a) for a in parts)
    if ia == ib:
        raise ParameterError(f"axes: two different components are needed, got {axes!r}")
    return ia, ib


def check_axis(name: str, axis, params: ParamsBase):
    """(parameter, values) of an axis given as (name, lo, hi, n); one line naming ``name``
    for anything else (an unknown parameter, an empty or reversed range, n < 1)."""
    try:
        pname, lo, hi, n = axis
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: expected (parameter, min, max, n), got {axis!r}") from None
    if not isinstance(pname, str):
        raise ParameterError(f"{name}: expected a parameter name first, got {pname!r}")
    pname = params.model.param(pname).name
    lo = check_float(f"{name} min", lo)
    hi = check_float(f"{name} max", hi)
    n = check_int(f"{name} n", n, 1)
    if hi < lo or (hi == lo and n > 1):
        raise ParameterError(f"{name}: empty or reversed range {pname} = {lo:g} ... {hi:g}; "
                             f"need min < max (or n = 1 and min = max)")
    return pname, np.linspace(lo, hi, n)


def check_params(params) -> ParamsBase:
    """``params`` if it is a model's validated parameters (``model(...).params(...)``,
    ``preset(...)``), else a one-line ParameterError."""
    if not isinstance(params, ParamsBase):
        raise ParameterError(f"params: expected model(...).params(...) or preset(...), "
                             f"got {type(params).__name__}")
    return params


def check_forced(params, who: str) -> None:
    """A one-line ParameterError where ``who`` (a stroboscopic analysis) gets a model that
    declares no forcing: it has no period to sample."""
    if check_params(params).model.autonomous:
        raise ParameterError(f"{who}: model {params.model.name} declares no forcing "
                             f"(omega=None): a stroboscopic map has no period to sample; use "
                             f"its section surfaces (limit_cycle, limit_cycle_branch, "
                             f"surface_basins, equilibria) or simulate")


def check_sweep_memory(n_values: int, n_branches: int, record: int, field: str = "values") -> None:
    """Refuse, before computing (and before the values are built: the CLI calls it with the
    typed ``--steps``), a sweep whose section data would not fit in memory; the line names the
    larger of ``field`` (the number of values) and ``record``, and the largest that fits."""
    from .io import check_memory
    big = ("record", record) if record >= n_values else (field, n_values)  # the larger factor
    check_memory(34.0 * n_values * n_branches * record + 8.0 * n_values, big[0],
                 (f"{n_values:,} values x {n_branches} sweep(s) x {record:,} recorded periods; "
                  f"sweep fewer values or record fewer periods per value") if record else
                 f"{n_values:,} values; use fewer values",
                 size=(big[1], 1))


def component_pair(pair, names, field: str) -> tuple | None:
    """``pair`` (None, "X,Y" or a pair of component names) as a pair of names among ``names``
    (the model's ``state_names``); a one-line ParameterError naming ``field`` otherwise."""
    if pair is None:
        return None
    try:
        parts = [t.strip() for t in pair.split(",")] if isinstance(pair, str) else list(pair)
    except TypeError:
        parts = []
    if len(parts) != 2:
        raise ParameterError(f"{field}: expected two state components (e.g. "
                             f"{','.join(names[:2])}), got {pair!r}")
    for name in parts:
        if name not in names:
            raise ParameterError(f"{field}: unknown component {name!r} (the model has "
                                 f"{', '.join(names)})")
    return tuple(parts)


def check_workers(workers) -> None:
    """``workers`` (threads): None or 0 = all local cores, else a positive integer; one line
    otherwise (the CLI checks ``--workers`` with its other options, before the kernels load)."""
    if workers is not None and (not isinstance(workers, (int, np.integer)) or workers < 0):
        raise ParameterError(f"workers: must be a positive integer (0: all cores), got {workers!r}")
