"""Bifurcation diagram: section X versus the swept parameter (Figs. 9 and 11)."""

from __future__ import annotations

import numpy as np

from .common import model_lines, model_of, new_figure, param_symbol, param_title

SWEEP_STYLE = {
    "up": dict(color="#1f77b4", marker=".", label="sweep up"),
    "down": dict(color="#d62728", marker="x", label="sweep down"),
    "fresh": dict(color="k", marker=".", label="fresh start each value"),
}



def sweep_names(ds) -> list[str]:
    """The direction names ("up", "down", "fresh") of the integer ``sweep`` coordinate of a
    bifurcation or resonance Dataset, from its CF flag_values / flag_meanings."""
    sw = ds["sweep"]
    meanings = dict(zip(np.asarray(sw.attrs["flag_values"]).tolist(),
                        sw.attrs["flag_meanings"].split()))
    return [meanings[int(c)] for c in np.atleast_1d(sw.values)]


def plot_bifurcation(ds, var: str = "X"):
    """Section ``var`` (X or V) of every recorded period versus the swept parameter; up and
    down sweeps in different colours and markers, small dots; failed points are left out."""
    param = ds.attrs["swept_param"]
    fig, ax = new_figure(figsize=(10, 5.5))
    vals = ds[param].values
    nsw = ds.sizes["sweep"]
    npts = vals.size * ds.sizes["n"]
    size = 0.6 if npts > 20000 else 2.0
    for j, name in enumerate(sweep_names(ds)):
        y = ds[var].values[j]  # (value, n)
        x = np.broadcast_to(vals[:, None], y.shape)
        ok = np.isfinite(y)
        style = dict(SWEEP_STYLE.get(str(name), dict(color="0.3", marker=".", label=str(name))))
        marker = style.pop("marker")
        ax.scatter(x[ok], y[ok], s=size * 1.6 if marker == "." else size, marker=marker,
                   linewidths=0.4 if marker == "x" else 0, alpha=0.7 if nsw > 1 else 1.0,
                   zorder=3 if str(name) == "up" else 2, rasterized=True, **style)
    if var == "X":
        draw_lines_over(ax, ds, param, vals)
    failed = int(np.count_nonzero(ds.status.values))
    unit = ds[param].attrs.get("units", "")
    sym = param_symbol(model_of(ds), param)
    ax.set_xlabel(f"{sym} [{unit}]" if unit else sym)
    ax.set_ylabel(r"$X(kT)$" if var == "X" else r"$\dot X(kT)$")
    ax.set_xlim(vals[0], vals[-1])
    ttl = f"bifurcation diagram, {ds.sizes['n']} section points per value"
    if failed:
        ttl += f" ({failed} failed points omitted)"
    ax.set_title(ttl, fontsize=10)
    ax.legend(loc="best", fontsize=8, markerscale=4)
    ax.grid(True, lw=0.3, alpha=0.5)
    fig.suptitle(f"{ds.attrs.get('method', '')}: {param_title(ds, exclude=(param,))}",
                 fontsize=9)
    fig.tight_layout()
    return fig


def draw_lines_over(ax, ds, param, vals, style=None):
    """The model's main lines of X (``Model.plot_lines`` without band edges) over the swept
    parameter: horizontal where they do not depend on it, else a curve through the values."""
    style = {**dict(color="k", lw=0.6, ls="--"), **(style or {})}
    per_value = [model_lines(ds, band_edges=False, **{param: float(v)}) for v in vals]
    n = min((len(li) for li in per_value), default=0)
    for k in range(n):
        ys = np.array([li[k][0] for li in per_value])
        lab = per_value[0][k][1]
        if np.all(ys == ys[0]):
            ax.axhline(ys[0], label=lab, **style)
        else:
            ax.plot(vals, ys, label=lab, **style)

