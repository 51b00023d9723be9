"""Pieces shared by several figures."""

from __future__ import annotations

import numpy as np

from . import REGION_COLORS, REGION_LABELS


def new_figure(nrows: int = 1, ncols: int = 1, *, figsize=None, **subplots_kw):
    """``(fig, axes)`` like ``plt.subplots`` but without pyplot: a ``matplotlib.figure.Figure``
    that no backend or pyplot state knows about (saved by ``nonsmooth.io.save_figure``, shown
    in a notebook by displaying ``fig``). ``subplots_kw`` go to ``Figure.subplots``."""
    from matplotlib.figure import Figure
    fig = Figure(figsize=figsize)
    return fig, fig.subplots(nrows, ncols, **subplots_kw)


def scatter_by_region(ax, x, y, region, s=2.0, legend=True, **kw):
    """Scatter (x, y) coloured by region code; only the regions present get a legend entry."""
    region = np.asarray(region)
    for code in range(4):
        sel = region == code
        if np.any(sel):
            ax.scatter(np.asarray(x)[sel], np.asarray(y)[sel], s=s, color=REGION_COLORS[code],
                       label=REGION_LABELS[code] if legend else None, linewidths=0, **kw)


def draw_band_edges(ax, eta, omega_s, xi_s, vlim=None, label=True):
    """Draw h_alpha = +-eta (X = 1 +- eta) and h_beta = +-eta (eq. 7) in the phase plane."""
    kw = dict(color="0.3", lw=0.6, ls="--")
    ax.axvline(1 - eta, **kw, label=r"band edges ($h=\pm\eta$)" if label else None)
    ax.axvline(1 + eta, **kw)
    if omega_s > 0 and xi_s > 0:
        r = xi_s / omega_s**2
        lo, hi = vlim if vlim is not None else ax.get_ylim()
        v = np.linspace(lo, hi, 2)
        for sgn in (-1, 1):
            ax.plot(1 - r * v - sgn * eta, v, color="0.5", lw=0.6, ls=":")
        ax.set_ylim(lo, hi)


def param_title(ds, keys=("omega0", "omega_s", "xi", "xi_s", "F0", "omega", "eta")) -> str:
    parts = []
    for k in keys:
        a = f"param_{k}"
        if a in ds.attrs:
            parts.append(f"{k}={ds.attrs[a]:.4g}")
    return ", ".join(parts)
