"""Figure of :func:`nonsmooth.manifolds`: the saddle's stable and unstable manifolds in the
section plane, over the basins when they are given."""

from __future__ import annotations

import numpy as np
from matplotlib.lines import Line2D

from .common import new_figure, param_title

#: branch flag -> (colour, label)
_STYLE = {0: ("tab:red", r"$W^u_+$"), 1: ("tab:orange", r"$W^u_-$"),
          2: ("tab:blue", r"$W^s_+$"), 3: ("tab:cyan", r"$W^s_-$")}


def plot_manifolds(ds, ax=None, basins=None):
    """The branches of ``ds`` (a manifolds Dataset) as lines in the plane of its ``axes``
    (default (X, V)), the saddle (+), the
    unstable branches' end points (o: where they converged onto an attractor) and the
    homoclinic crossings (black dots); over the basin image of ``basins`` (a basins Dataset
    of the same window) if given. The axes keep the basins' window, else the manifolds'
    extent."""
    if ax is None:
        fig, ax = new_figure(figsize=(6.6, 6.0))
    fig = ax.figure
    if basins is not None:
        from .basins import plot_basins
        plot_basins(basins, ax=ax, points=False)
    flag = np.asarray(ds["branch"].values)
    ca, cb = str(ds.attrs.get("axes", "X V")).split()
    X, V = np.asarray(ds[ca].values), np.asarray(ds[cb].values)
    handles = []
    for b in np.unique(flag):
        c, lab = _STYLE.get(int(b), ("k", str(b)))
        sel = flag == b
        ax.plot(X[sel], V[sel], "-", color=c, lw=1.1)
        handles.append(Line2D([], [], color=c, lw=1.5, label=lab))
    ax.plot(float(ds[f"saddle_{ca}"]), float(ds[f"saddle_{cb}"]), "k+", ms=12, mew=2)
    handles.append(Line2D([], [], ls="none", marker="+", color="k", mew=2, label="saddle"))
    ends = np.isfinite(ds[f"end_{ca}"].values)
    if ends.any():
        ax.plot(ds[f"end_{ca}"].values[ends], ds[f"end_{cb}"].values[ends], "o", mfc="none", mec="k",
                ms=8)
        handles.append(Line2D([], [], ls="none", marker="o", mfc="none", mec="k",
                              label=r"end of $W^u$ (attractor)"))
    if ds.sizes.get("crossing", 0):
        ax.plot(ds[f"crossing_{ca}"].values, ds[f"crossing_{cb}"].values, "k.", ms=6)
        handles.append(Line2D([], [], ls="none", marker=".", color="k",
                              label=f"homoclinic points ({ds.sizes['crossing']})"))
    if basins is not None:
        ax.set_xlim(*(float(x) for x in (basins["x0"].values[[0, -1]])))
        ax.set_ylim(*(float(x) for x in (basins["v0"].values[[0, -1]])))
    ax.set_xlabel(rf"${ca}$ at $t = kT$")
    ax.set_ylabel(rf"${cb}$ at $t = kT$")
    ax.legend(handles=handles, fontsize=8, loc="best")
    title = param_title(ds)
    ax.set_title((title + "\n" if title else "") + "stable and unstable manifolds of the "
                 "saddle", fontsize=9)
    return fig
