"""Basin entropy and the uncertainty exponent (:func:`nonsmooth.basin_entropy`): the entropy
of each box over the grid, and the boundary share f(eps) on log-log axes with its fit. Reads a
Dataset; never integrates."""

from __future__ import annotations

import math

import numpy as np

from .common import new_figure, param_title


def plot_basin_entropy(ds, axes=None):
    """Left: the Gibbs entropy of each box (white: a single attractor, dark: an even mix);
    right: ln f against ln(e - 1) for boxes of e x e cells, with the fitted slope alpha."""
    if axes is None:
        fig, axes = new_figure(1, 2, figsize=(11.0, 4.6))
        fig.set_layout_engine("constrained")
    fig = axes[0].figure
    ax, bx = axes
    S = np.asarray(ds["box_entropy"].values, dtype=float)
    cx, cy = (ds[c].values for c in ds["box_entropy"].dims)
    n_att = max(int(ds.attrs.get("n_attractors", 2)), 2)
    im = ax.pcolormesh(cx, cy, S.T, shading="nearest", cmap="Greys", vmin=0.0,
                       vmax=math.log(n_att))
    fig.colorbar(im, ax=ax, label=r"box entropy $S_i$")
    ax.set_xlabel(ds[ds["box_entropy"].dims[0]].attrs.get("long_name", "box"))
    ax.set_ylabel(ds[ds["box_entropy"].dims[1]].attrs.get("long_name", "box"))
    Sb, Sbb = float(ds["basin_entropy"]), float(ds["boundary_basin_entropy"])
    ax.set_title(rf"$S_b$ = {Sb:.3f}, $S_{{bb}}$ = {Sbb:.3f} "
                 + (r"> ln 2: fractal" if int(ds["fractal_boundary"]) else r"(<= ln 2)")
                 + f"\n{_box(ds)} x {_box(ds)} cells per box", fontsize=10)
    e = np.asarray(ds["epsilon"].values, dtype=float) - 1.0
    f = np.asarray(ds["boundary_share"].values, dtype=float)
    ok = (f > 0) & (e > 0)
    bx.loglog(e[ok], f[ok], "o", color="k", label=r"$f$ = boundary boxes / boxes")
    a, se = float(ds["uncertainty_exponent"]), float(ds["uncertainty_exponent_stderr"])
    fit = ok  # the reported fit: every size with f > 0 (f = 1 is the plateau alpha = 0)
    if math.isfinite(a) and np.count_nonzero(fit) >= 2:
        x = np.log(e[fit])
        c = float(np.mean(np.log(f[fit]) - a * x))
        xx = np.linspace(x.min(), x.max(), 20)
        bx.loglog(np.exp(xx), np.exp(c + a * xx), "-", color="tab:red",
                  label=rf"fit: $\alpha$ = {a:.3f} $\pm$ {se:.3f}")
    bx.set_xlabel(r"$\varepsilon$ (span of a box, cells)")
    bx.set_ylabel(r"$f(\varepsilon)$")
    bx.set_title("uncertainty exponent (1: smooth boundary)", fontsize=10)
    bx.legend(fontsize=9)
    title = param_title(ds)
    if title:
        fig.suptitle(title, fontsize=10)
    return fig


def _box(ds) -> int:
    """The box side of the entropies (also in a basins file that ``--entropy`` wrote)."""
    return int(ds["basin_entropy"].attrs.get("box_cells", ds.attrs.get("box", 0)))
