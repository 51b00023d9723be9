"""Continuation: a branch of periodic orbits over the continued parameter, stable parts solid,
unstable parts dashed, with its special points (fold, period doubling, Neimark-Sacker,
grazing). Datasets of ``nonsmooth.continuation`` in, Figures out (nothing is integrated here)."""

from __future__ import annotations

import numpy as np

from .bifurcation import draw_lines_over
from .common import model_of, new_figure, param_symbol, param_title, params_of

#: Special-point type (CF flag value of ``special_type``) -> (short label, legend name, style).
SPECIAL_STYLES = {
    1: ("F", "fold", dict(marker="s", color="#d62728")),
    2: ("PD", "period doubling", dict(marker="D", color="#9467bd")),
    3: ("NS", "Neimark-Sacker", dict(marker="^", color="#2ca02c")),
    4: ("G", "grazing", dict(marker="o", color="#ff7f0e")),
}
BRANCH_COLOR = "#1f77b4"
#: y-axis labels of the usual variables (others: the variable's long_name and units).
VAR_LABELS = {"max_X": r"max $X$ over the orbit", "min_X": r"min $X$ over the orbit",
              "X_section": r"section $X(jT)$", "V_section": r"section $\dot X(jT)$",
              "contact_fraction": "contact fraction"}
_X_VARS = ("max_X", "min_X", "X_section")  # variables in units of X: the model's lines apply
GRAZING = 4


def _figure(ax, figsize):
    """(figure, axes, whether the figure is ours to lay out)."""
    if ax is None:
        return (*new_figure(figsize=figsize), True)
    return ax.figure, ax, False


def special_label(ds, i: int, digits: int = 5) -> str:
    """``F omega=1.19304`` for special point ``i`` of a continuation Dataset."""
    param = ds.attrs["param"]
    typ = int(ds["special_type"][i])
    short = SPECIAL_STYLES.get(typ, ("?", "?", {}))[0]
    return f"{short} {param}={float(ds[f'special_{param}'][i]):.{digits}g}"


def _columns(ds, var) -> np.ndarray:
    """``var`` as (point, column): one column per section point for X_section / V_section."""
    y = np.asarray(ds[var].values, dtype=float)
    return y.reshape(y.shape[0], -1)


def _special_y(lam, y, i, lam_s):
    """y at the special point with parameter ``lam_s`` between points i and i + 1: linear in
    the parameter where it lies between them, else (a fold, where the parameter turns) the
    vertex of the parabola lam(y) through three neighbouring points, kept between y_i and
    y_(i+1)."""
    n = lam.size
    j = min(i + 1, n - 1)
    lo, hi = sorted((lam[i], lam[j]))
    if lam[i] != lam[j] and lo <= lam_s <= hi:
        return y[i] + (lam_s - lam[i]) / (lam[j] - lam[i]) * (y[j] - y[i])
    ya, yb = sorted((y[i], y[j]))
    for idx in ((i - 1, i, j), (i, j, j + 1)):
        if idx[0] < 0 or idx[-1] >= n or len(set(idx)) < 3:
            continue
        yy, ll = y[list(idx)], lam[list(idx)]
        if not np.all(np.isfinite(yy)) or len(set(yy.tolist())) < 3:
            continue
        a, b, _ = np.polyfit(yy, ll, 2)
        if a != 0:
            return float(np.clip(-b / (2 * a), ya, yb))
    return 0.5 * (y[i] + y[j])


def _contact_level(ds, param, lam_s):
    """The model's contact level at ``param = lam_s`` (None where unknown)."""
    p = params_of(ds, **{param: lam_s})
    if p is None or not getattr(p.model, "contact_level", None):
        return None
    try:
        return float(p.model.contact_level(p))
    except Exception:  # noqa: BLE001 - a model's level must not break a figure
        return None


def _special_values(ds, var, lam, Y, sp_type, sp_lam, after) -> np.ndarray:
    """``var`` at each special point, (column, special): ``special_<var>`` where the Dataset
    has it; else max X = the contact level at a grazing point, and otherwise interpolated
    between the neighbouring points (:func:`_special_y`); special points at the same
    parameter value in the same interval (a fold at grazing) share the grazing value."""
    ncol, nsp = Y.shape[1], sp_lam.size
    if f"special_{var}" in ds.data_vars:
        return np.asarray(ds[f"special_{var}"].values, dtype=float).reshape(nsp, ncol).T
    out = np.array([[_special_y(lam, Y[:, c], int(a), s) for a, s in zip(after, sp_lam)]
                    for c in range(ncol)]).reshape(ncol, nsp)
    if var != "max_X":
        return out
    param = ds.attrs["param"]
    scale = max(1.0, float(np.nanmax(np.abs(lam)))) if lam.size else 1.0
    for i in np.flatnonzero(sp_type == GRAZING):
        level = _contact_level(ds, param, float(sp_lam[i]))
        if level is None:
            continue
        out[:, i] = level
        for j in range(nsp):
            if (j != i and after[j] == after[i]
                    and abs(sp_lam[j] - sp_lam[i]) <= 1e-5 * scale):
                out[:, j] = level
    return out


def _segments(lam, y, stable, after, xs, ys):
    """The branch as runs of constant stability ``[(stable, x, y), ...]``: the special points
    are vertices of the line (at its index ``after`` + 1/2), and the line switches between
    solid and dashed at the special point between two points of different stability (at the
    midpoint when none was located there)."""
    by_after = {}
    for a, x, yv in zip(after, xs, ys):
        if np.isfinite(yv):
            by_after.setdefault(int(a), []).append((x, yv))
    n = lam.size
    runs, cur, cx, cy = [], None, [], []

    def add(x, yv, s):
        nonlocal cur, cx, cy
        if cur is None:
            cur = s
        if s != cur:  # the vertex ends one run and starts the next
            runs.append((cur, cx + [x], cy + [yv]))
            cur, cx, cy = s, [], []
        cx.append(x)
        cy.append(yv)

    for i in range(n):
        add(lam[i], y[i], stable[i])
        if i + 1 >= n:
            break
        extra = by_after.get(i, [])
        if stable[i] != stable[i + 1]:
            if not extra:
                extra = [(0.5 * (lam[i] + lam[i + 1]), 0.5 * (y[i] + y[i + 1]))]
            # order the inserted vertices along the segment, switch at the one nearest to the
            # middle (the crossing that changed the stability is usually the only one)
            d = [abs(yv - y[i]) + abs(x - lam[i]) for x, yv in extra]
            extra = [e for _, e in sorted(zip(d, extra))]
            k = len(extra) // 2
            for m, (x, yv) in enumerate(extra):
                add(x, yv, stable[i] if m < k else stable[i + 1])
        else:
            d = [abs(yv - y[i]) + abs(x - lam[i]) for x, yv in extra]
            for _, (x, yv) in sorted(zip(d, extra)):
                add(x, yv, stable[i])
    if cx:
        runs.append((cur, cx, cy))
    return runs


def plot_continuation(ds, var: str = "max_X", ax=None):
    """The branch of a continuation Dataset: ``var`` (``max_X`` default, ``min_X``,
    ``X_section``, ``V_section``, ``contact_fraction``, ...) versus the continued parameter,
    stable parts solid, unstable parts dashed, the special points marked and labelled (F
    fold, PD period doubling, NS Neimark-Sacker, G grazing, with the parameter value), and,
    for variables of X, the model's contact level (support: X = 1)."""
    from ..errors import ParameterError

    if var not in ds.data_vars or "point" not in ds[var].dims:
        known = [v for v in ds.data_vars if ds[v].dims[:1] == ("point",) and v != ds.attrs["param"]]
        raise ParameterError(f"var: {var!r} is not a variable over the branch "
                             f"(known: {', '.join(known)})")
    fig, ax, own = _figure(ax, (8.5, 5.4))
    param = ds.attrs["param"]
    lam = np.asarray(ds[param].values, dtype=float)
    stable = np.asarray(ds["stable"].values).astype(bool)
    Y = _columns(ds, var)
    nsp = ds.sizes.get("special", 0)
    sp_type = np.asarray(ds["special_type"].values, dtype=int) if nsp else np.zeros(0, int)
    sp_lam = np.asarray(ds[f"special_{param}"].values, dtype=float) if nsp else np.zeros(0)
    after = np.asarray(ds["special_after_point"].values, dtype=int) if nsp else np.zeros(0, int)
    seen = set()
    sp_y = _special_values(ds, var, lam, Y, sp_type, sp_lam, after)
    for c in range(Y.shape[1]):
        for st, x, y in _segments(lam, Y[:, c], stable, after, sp_lam, sp_y[c]):
            label = ("stable" if st else "unstable") if st not in seen else None
            seen.add(st)
            ax.plot(x, y, color=BRANCH_COLOR, lw=1.6 if st else 1.2, ls="-" if st else "--",
                    label=label, zorder=2)
    shown = set()
    for c in range(Y.shape[1]):
        for i in range(nsp):
            short, name, style = SPECIAL_STYLES.get(int(sp_type[i]),
                                                    ("?", "special", dict(marker="x", color="k")))
            if not np.isfinite(sp_y[c, i]):
                continue
            ax.plot(sp_lam[i], sp_y[c, i], ls="none", ms=7, mec="k", mew=0.7, zorder=4,
                    label=f"{name} ({short})" if name not in shown else None, **style)
            shown.add(name)
            if c == 0:
                ax.annotate(f"{short} {sp_lam[i]:.5g}", (sp_lam[i], sp_y[c, i]),
                            xytext=(6, 6 if i % 2 == 0 else -12), textcoords="offset points",
                            fontsize=8, color=style.get("color", "k"), zorder=5,
                            bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none",
                                      alpha=0.75))
    if var in _X_VARS and lam.size:
        finite = lam[np.isfinite(lam)]
        if finite.size:
            draw_lines_over(ax, ds, param, np.linspace(finite.min(), finite.max(), 41))
    unit = ds[param].attrs.get("units", "")
    sym = param_symbol(model_of(ds), param)
    ax.set_xlabel(f"{sym} [{unit}]" if unit else sym)
    va = ds[var].attrs
    ylab = VAR_LABELS.get(var, va.get("long_name", var))
    if var not in VAR_LABELS and va.get("units", "1") not in ("", "1"):
        ylab += f" [{va['units']}]"
    ax.set_ylabel(ylab)
    ax.grid(True, lw=0.3, alpha=0.5)
    ax.legend(loc="best", fontsize=8)
    a = ds.attrs
    k = int(a.get("k", 1))
    what = f"limit cycles on {a['section']}" if "section" in a else f"period-{k} orbits"
    rest = param_title(ds, exclude=(param,))  # (empty: the continued parameter is the only one)
    ax.set_title(f"continuation of the {what} in {param}: {lam.size} points, "
                 f"{nsp} special, {a.get('status', '?')}\n{a.get('method', '')}"
                 + (f": {rest}" if rest else ""), fontsize=9)
    if own:
        fig.tight_layout()
    return fig


def _parameter_plane(ds, ax):
    """(fig, ax, model, param, param2) of a figure in the plane of a result's two parameters
    (attrs ``param``, ``param2``)."""
    if ax is None:
        fig, ax = new_figure(figsize=(7, 5))
    else:
        fig = ax.figure
    return fig, ax, model_of(ds), ds.attrs["param"], ds.attrs["param2"]


def _finish_plane(fig, ax, ds, m, param, param2, title):
    ax.set_xlabel(f"{param_symbol(m, param)} [{ds[param].attrs.get('units', '')}]")
    ax.set_ylabel(f"{param_symbol(m, param2)} [{ds[param2].attrs.get('units', '')}]")
    ax.set_title(title, fontsize=10)
    ax.grid(True, lw=0.3, alpha=0.5)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def plot_two_parameter(ds, ax=None):
    """A two-parameter curve (``analysis.continuation.two_parameter_curve``): the special
    points' first parameter versus the second, one line per point of the branch."""
    fig, ax, m, param, param2 = _parameter_plane(ds, ax)
    y = ds[param2].values
    for j in range(ds.sizes["n"]):
        ax.plot(ds[param].values[:, j], y, marker=".", lw=1.2, label=f"{ds.attrs['special']} #{j}")
    return _finish_plane(fig, ax, ds, m, param, param2,
                         f"{ds.attrs['special']} points in ({param}, {param2})")


def plot_special_curve(ds, ax=None):
    """A fold, period-doubling, grazing or Neimark-Sacker curve continued as an extended
    system (``fold_curve``, ``period_doubling_curve``, ``grazing_curve``,
    ``neimark_sacker_curve``): the first parameter versus the second, its start (o), its cusps
    (x) and its other codimension-two points (diamonds)."""
    fig, ax, m, param, param2 = _parameter_plane(ds, ax)
    what = {"fold_curve": "fold", "period_doubling_curve": "period doubling",
            "grazing_curve": "grazing", "neimark_sacker_curve": "Neimark-Sacker"}.get(
                ds.attrs.get("analysis"), "special point")
    ax.plot(ds[param].values, ds[param2].values, "-", color="k", lw=1.3, label=f"{what} curve")
    ax.plot(ds[param].values[0], ds[param2].values[0], "o", mfc="none", mec="k",
            label="start (on the branch)")
    if ds.sizes.get("cusp", 0):
        ax.plot(ds["cusp_" + param].values, ds["cusp_" + param2].values, "x", color="tab:red",
                ms=10, mew=2, label="cusp")
    if ds.sizes.get("codim2", 0):
        names = ds["codim2_type"].attrs["flag_meanings"].split()
        for i in range(ds.sizes["codim2"]):
            ax.plot(float(ds["codim2_" + param][i]), float(ds["codim2_" + param2][i]), "D",
                    mfc="none", ms=8, label=names[int(ds["codim2_type"][i])].replace("_", " "))
    return _finish_plane(fig, ax, ds, m, param, param2,
                         f"{what} continued in ({param}, {param2}): {ds.attrs.get('status', '')}")
