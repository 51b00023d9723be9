"""Resonance curve with both sweep branches and omega_a, omega_b, omega_c marked (Fig. 6)."""

from __future__ import annotations

import math

import numpy as np

from .bifurcation import SWEEP_STYLE, draw_lines_over, sweep_names
from .common import model_of, new_figure, param_symbol, param_title


def plot_resonance(ds, show_min: bool = True):
    """max X (and min X) of the settled response versus omega for the up and the down sweep,
    with vertical lines at omega_a (contact starts), omega_b and omega_c (jumps) and the
    model's lines of X (support: X = 1)."""
    fig, ax = new_figure(figsize=(8, 5))
    m = model_of(ds)
    wname = (m.forcing_param if m is not None and m.forcing_param in ds else
             str(ds.attrs.get("swept_param", "omega")))
    w = ds[wname].values
    for j, name in enumerate(sweep_names(ds)):
        style = dict(SWEEP_STYLE.get(str(name), dict(color="0.3", marker=".", label=str(name))))
        ls = "-" if str(name) == "up" else "--"
        ax.plot(w, ds.max_X.values[j], ls=ls, lw=1.0, markersize=3, **style)
        if show_min:
            style.pop("label")
            ax.plot(w, ds.min_X.values[j], ls=ls, lw=0.8, markersize=2, alpha=0.6, **style)
    if f"branch_{wname}" in ds:  # every period-1 branch (continuation): unstable dashed
        bw, bm, stb = (ds[f"branch_{wname}"].values, ds.branch_max_X.values,
                       ds.branch_stable.values)
        for flag, ls, lab in ((1, "-", "period-1 branch, stable"),
                              (0, "--", "period-1 branch, unstable")):
            y = bm.astype(float).copy()
            y[stb != flag] = math.nan
            if flag == 0:  # join the dashed part to its stable neighbours
                edge = (stb == 0) | np.r_[stb[1:] == 0, False] | np.r_[False, stb[:-1] == 0]
                y = np.where(edge, bm, math.nan)
            ax.plot(bw, y, ls=ls, color="k", lw=1.3, label=lab, zorder=3)
    draw_lines_over(ax, ds, wname, w, style=dict(ls=":"))
    from ..analysis.resonance import jump_names
    for key, col in zip(jump_names(ds), ("#2ca02c", "#9467bd", "#8c564b")):
        v = float(ds.attrs.get(key, math.nan))
        base, _, k = key.rpartition("_")
        sym = (r"\omega" if base == "omega" else base if base.isalnum() else
               r"\mathrm{" + base.replace("_", r"\_") + "}") + f"_{k}"
        if math.isfinite(v):
            ax.axvline(v, color=col, lw=0.9, ls="-.")
            ax.annotate(f"${sym} = {v:.4f}$", xy=(v, 0.03), xycoords=("data", "axes fraction"),
                        xytext=(3, 0), textcoords="offset points", rotation=90, va="bottom",
                        fontsize=8, color=col,
                        bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.85))
    unit = ds[wname].attrs.get("units", "rad/s")
    ax.set_xlabel(f"{param_symbol(m, wname)} [{unit}]")
    ax.set_ylabel(r"$\max X$, $\min X$" if show_min else r"$\max X$")
    ax.set_xlim(w[0], w[-1])
    ax.set_title("resonance curve (continuation up and down)", fontsize=10)
    ax.legend(loc="upper left", fontsize=8)
    ax.grid(True, lw=0.3, alpha=0.5)
    fig.suptitle(f"{ds.attrs.get('method', '')}: {param_title(ds, exclude=(wname,))}", fontsize=9)
    fig.tight_layout()
    return fig
