"""Attractors followed across a parameter (:func:`nonsmooth.attractor_continuation`): their
basin shares stacked over the parameter, and the largest X of each. Reads a Dataset; never
integrates."""

from __future__ import annotations

import numpy as np

from .basins import UNDECIDED_COLOR
from .common import new_figure, param_title

_COLORS = ("#4c72b0", "#dd8452", "#55a868", "#c44e52", "#8172b3", "#937860", "#da8bc3",
           "#8c8c8c", "#ccb974", "#64b5cd")


def plot_attractor_continuation(ds, axes=None):
    """Top: the share of the grid's initial conditions that reaches each attractor, stacked
    (grey: undecided); bottom: each attractor's largest X, with its births (triangles up) and
    deaths (down) marked."""
    if axes is None:
        fig, axes = new_figure(2, 1, figsize=(7.5, 6.5), sharex=True)
        fig.set_layout_engine("constrained")
    fig = axes[0].figure
    top, bot = axes
    name = ds.attrs.get("continuation_parameter", ds["fraction"].dims[0])
    w = ds[name].values
    na = ds.sizes["attractor"]
    colors = [_COLORS[a % len(_COLORS)] for a in range(na)]
    frac = np.asarray(ds["fraction"].values, dtype=float)
    top.stackplot(w, *frac.T, np.asarray(ds["undecided_fraction"].values, dtype=float),
                  colors=colors + [UNDECIDED_COLOR],
                  labels=[_label(ds, a) for a in range(na)] + ["undecided"])
    top.set_ylim(0, 1)
    top.set_ylabel("basin share")
    top.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    for a in range(na):
        mx = np.asarray(ds["max_X"].values[:, a], dtype=float)
        bot.plot(w, mx, "o-", ms=3, color=colors[a])
        for what, marker in (("born", "^"), ("died", "v")):
            val = float(ds[what].values[a])
            if np.isfinite(val):
                for ax in (top, bot):
                    ax.axvline(val, color=colors[a], ls=":", lw=1)
                bot.plot([val], [np.nanmax(mx)], marker, color=colors[a], ms=7)
    bot.set_xlabel(ds[name].attrs.get("long_name", name))
    bot.set_ylabel("largest X on the orbit")
    title = param_title(ds, exclude=(name,))
    if title:
        fig.suptitle(title, fontsize=10)
    return fig


def _label(ds, a) -> str:
    per = np.asarray(ds["period"].values[:, a])
    ex = per[per >= 0]
    kinds = sorted({("chaotic" if p == 0 else f"period {p}") for p in ex})
    con = np.asarray(ds["contact"].values[:, a])
    touch = " (contact)" if np.any(con == 1) else ""
    return f"A{a}: " + ", ".join(kinds) + touch
