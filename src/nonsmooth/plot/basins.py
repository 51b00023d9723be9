"""Basins of attraction (like the paper's Fig. 7) and the coexisting orbits (like Fig. 8).

Both figures read a Dataset from :func:`nonsmooth.analysis.basins.basins`; they never integrate.
"""

from __future__ import annotations

import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from .common import (draw_model_lines, model_of, new_figure, param_symbol, param_title,
                     state_labels)

#: Basin colours: light for attractors without contact, dark for those with contact (as in the
#: paper's Fig. 7), cycling through hues when there are several of a kind.
_LIGHT = ("#f2c45a", "#9ecae1", "#a1d99b", "#fdae6b", "#dadaeb", "#fcbba1")
_DARK = ("#08306b", "#7f2704", "#00441b", "#3f007d", "#67000d", "#252525")
UNDECIDED_COLOR = "#9a9a9a"
_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")


def attractor_colors(ds) -> list[str]:
    """One colour per attractor of ``ds``: light hues without contact, dark hues with contact."""
    out, nl, nd = [], 0, 0
    for c in np.asarray(ds["contact"].values):
        if int(c):
            out.append(_DARK[nd % len(_DARK)])
            nd += 1
        else:
            out.append(_LIGHT[nl % len(_LIGHT)])
            nl += 1
    return out


def _chaotic(ds, k) -> bool:
    return "kind" in ds and int(ds["kind"].values[k]) == 1


def _describe(ds, k) -> str:
    what = "chaotic" if _chaotic(ds, k) else f"period {int(ds['period'].values[k])}"
    contact = "contact" if int(ds["contact"].values[k]) else "no contact"
    return f"A{k}: {what}, {contact}, {100 * float(ds['fraction'].values[k]):.1f}%"


def _section_points(ds, k):
    X = np.asarray(ds["attractor_X"].values[k], dtype=float)
    V = np.asarray(ds["attractor_V"].values[k], dtype=float)
    keep = np.isfinite(X) & np.isfinite(V)
    return X[keep], V[keep]


def _omega_text(ds) -> str:
    """``, <omega symbol> = value units`` of the model's forcing frequency, or ""."""
    m = model_of(ds)
    name = m.forcing_param if m is not None else "omega"
    omega = ds.attrs.get(f"param_{name}")
    if omega is None:
        return ""
    units = m.param(name).units if m is not None else "rad/s"
    return f", {param_symbol(m, name)} = {float(omega):.4g} {units}"


def plot_basins(ds, ax=None, points: bool = True):
    """Basin image over (x0, v0): one discrete colour per attractor, undecided points in grey,
    a legend with period, contact and basin fraction, the attractors' section points overlaid
    (a grid on other components than (X, V), attr ``axes``: the axes named, no overlay)."""
    axes = str(ds.attrs.get("axes", "X V")).split()
    planar = axes == ["X", "V"]
    points = points and planar
    if ax is None:
        fig, ax = new_figure(figsize=(6.4, 5.6))
    else:
        fig = ax.figure
    n_att = ds.sizes.get("attractor", 0)
    colors = attractor_colors(ds)
    cmap = ListedColormap([UNDECIDED_COLOR] + colors)
    norm = BoundaryNorm(np.arange(-1.5, n_att + 0.5), cmap.N)
    x0, v0 = ds["x0"].values, ds["v0"].values
    dx = (x0[-1] - x0[0]) / max(len(x0) - 1, 1)
    dv = (v0[-1] - v0[0]) / max(len(v0) - 1, 1)
    ax.imshow(np.asarray(ds["label"].values).T, origin="lower", cmap=cmap, norm=norm,
              extent=(x0[0] - dx / 2, x0[-1] + dx / 2, v0[0] - dv / 2, v0[-1] + dv / 2),
              aspect="auto", interpolation="nearest")
    handles = [Patch(facecolor=colors[k], edgecolor="k", lw=0.5, label=_describe(ds, k))
               for k in range(n_att)]
    und = float(np.mean(np.asarray(ds["label"].values) < 0))
    if und > 0 or n_att == 0:
        handles.append(Patch(facecolor=UNDECIDED_COLOR, edgecolor="k", lw=0.5,
                             label=f"undecided: {100 * und:.1f}%"))
    if points:
        for k in range(n_att):
            X, V = _section_points(ds, k)
            m = _MARKERS[k % len(_MARKERS)]
            size = 12 if _chaotic(ds, k) else 70
            ax.scatter(X, V, s=size, marker=m, facecolor=colors[k], edgecolor="k", lw=1.3, zorder=3)
            ax.scatter(X, V, s=size, marker=m, facecolor="none", edgecolor="w", lw=0.5, zorder=4)
        if n_att:
            handles.append(Line2D([], [], ls="none", marker="o", mfc="w", mec="k",
                                  label="section points (t = kT)"))
    ax.set_xlim(x0[0] - dx / 2, x0[-1] + dx / 2)
    ax.set_ylim(v0[0] - dv / 2, v0[-1] + dv / 2)
    if planar:
        ax.set_xlabel(r"initial $X_0$")
        ax.set_ylabel(r"initial $V_0 = \dot X_0$")
    else:
        ax.set_xlabel(f"initial ${axes[0]}$")
        ax.set_ylabel(f"initial ${axes[1]}$")
    ax.legend(handles=handles, loc="upper right", fontsize=8, framealpha=0.85)
    title = "basins of attraction" + _omega_text(ds)
    ax.set_title(f"{title}\n{ds.attrs.get('method', '')}: {param_title(ds)}", fontsize=9)
    return fig


def plot_attractors(ds, ax=None):
    """The coexisting attractors in the phase plane (like Fig. 8): each periodic attractor's
    orbit over its whole period (a chaotic one: over a few forcing periods, thinner), its
    section points, and the model's lines of X (support: its position X = 1)."""
    if ax is None:
        fig, ax = new_figure(figsize=(6.4, 5.2))
    else:
        fig = ax.figure
    n_att = ds.sizes.get("attractor", 0)
    colors = attractor_colors(ds)
    for k in range(n_att):
        X = np.asarray(ds["orbit_X"].values[k], dtype=float)
        V = np.asarray(ds["orbit_V"].values[k], dtype=float)
        keep = np.isfinite(X) & np.isfinite(V)
        ax.plot(X[keep], V[keep], color=colors[k], lw=0.6 if _chaotic(ds, k) else 2.0,
                label=_describe(ds, k), zorder=2)
        if not int(ds["contact"].values[k]):  # light colours need an outline on white
            ax.plot(X[keep], V[keep], color="0.35", lw=0.5, zorder=2)
        Xs, Vs = _section_points(ds, k)
        ax.scatter(Xs, Vs, s=12 if _chaotic(ds, k) else 55, marker=_MARKERS[k % len(_MARKERS)],
                   facecolor=colors[k],
                   edgecolor="k", lw=1.0, zorder=3)
    draw_model_lines(ax, ds, "v", band_edges=False, style=dict(lw=0.8))
    ax.set_xlabel(state_labels(ds)[0])
    ax.set_ylabel(state_labels(ds)[1])
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="best", fontsize=8)
    title = "coexisting attractors" + _omega_text(ds)
    ax.set_title(f"{title}\n{ds.attrs.get('method', '')}: {param_title(ds)}", fontsize=9)
    return fig
