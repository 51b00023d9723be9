"""Time response and phase portrait coloured by region, like the paper's Fig. 3."""

from __future__ import annotations

import numpy as np

from . import REGION_COLORS, REGION_LABELS
from .common import draw_band_edges, new_figure, param_title, scatter_by_region


def _crossed_between_samples(ax, x, y, R, M):
    """Ring markers, in the region's colour, on the samples after an interval that visited a
    region seen at neither of its two ends (a band crossed between two samples)."""
    R = np.asarray(R, dtype=int)
    M = np.asarray(M, dtype=int)
    prev = np.concatenate([R[:1], R[:-1]])
    for code in range(len(REGION_COLORS)):
        sel = ((M >> code) & 1).astype(bool) & (R != code) & (prev != code)
        if np.any(sel):
            ax.scatter(np.asarray(x)[sel], np.asarray(y)[sel], s=30, facecolors="none",
                       edgecolors=REGION_COLORS[code], linewidths=1.0, zorder=3,
                       label=f"{REGION_LABELS[code]} crossed between samples")


def plot_time_response(ds):
    """Figure with X(t) (left) and the phase portrait V(X) (right), coloured by region, with the
    band edges h_alpha = +-eta and h_beta = +-eta drawn and a zoom on the switching zone.
    Regions visited only between two samples (``visited`` mask) are marked with rings, so the
    figure shows every region the trajectory visited."""
    fig, axes = new_figure(1, 3, figsize=(15, 4.5), gridspec_kw={"width_ratios": [1.4, 1, 1]})
    t, X, V, R = ds.t.values, ds.X.values, ds.V.values, ds.region.values
    M = ds.visited.values
    eta = float(ds.attrs["param_eta"])
    ws, xis = float(ds.attrs["param_omega_s"]), float(ds.attrs["param_xi_s"])
    ax = axes[0]
    ax.plot(t, X, color="0.8", lw=0.8, zorder=0)
    scatter_by_region(ax, t, X, R, s=4)
    _crossed_between_samples(ax, t, X, R, M)
    ax.axhline(1.0, color="k", lw=0.6, ls="--")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("X = x/g")
    ax.set_title("time response")
    ax.legend(loc="upper right", markerscale=3, fontsize=8)
    for ax, zoom in ((axes[1], False), (axes[2], True)):
        ax.plot(X, V, color="0.8", lw=0.8, zorder=0)
        scatter_by_region(ax, X, V, R, s=4, legend=False)
        _crossed_between_samples(ax, X, V, R, M)
        if zoom:
            near = np.abs(X - 1) < max(20 * eta, 0.02)
            if np.any(near):
                vmin, vmax = V[near].min(), V[near].max()
                pad = 0.1 * (vmax - vmin + 1e-9)
                ax.set_xlim(1 - max(20 * eta, 0.02), 1 + max(20 * eta, 0.02))
                ax.set_ylim(vmin - pad, vmax + pad)
            ax.set_title("zoom on the switching bands")
        else:
            ax.set_title("phase portrait")
        draw_band_edges(ax, eta, ws, xis, label=not zoom)
        ax.set_xlabel("X")
        ax.set_ylabel("V = dX/dt")
    axes[1].legend(loc="lower left", fontsize=8)
    fig.suptitle(f"{ds.attrs.get('method', '')}: {param_title(ds)}", fontsize=9)
    fig.tight_layout()
    return fig
