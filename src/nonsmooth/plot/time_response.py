"""Time response and phase portrait coloured by region, like the paper's Fig. 3."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from .common import draw_band_edges, param_title, scatter_by_region


def plot_time_response(ds):
    """Figure with X(t) (left) and the phase portrait V(X) (right), coloured by region, with the
    band edges h_alpha = +-eta and h_beta = +-eta drawn and a zoom on the switching zone."""
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5), gridspec_kw={"width_ratios": [1.4, 1, 1]})
    t, X, V, R = ds.t.values, ds.X.values, ds.V.values, ds.region.values
    eta = float(ds.attrs["param_eta"])
    ws, xis = float(ds.attrs["param_omega_s"]), float(ds.attrs["param_xi_s"])
    ax = axes[0]
    ax.plot(t, X, color="0.8", lw=0.8, zorder=0)
    scatter_by_region(ax, t, X, R, s=4)
    ax.axhline(1.0, color="k", lw=0.6, ls="--")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("X = x/g")
    ax.set_title("time response")
    ax.legend(loc="upper right", markerscale=3, fontsize=8)
    for ax, zoom in ((axes[1], False), (axes[2], True)):
        ax.plot(X, V, color="0.8", lw=0.8, zorder=0)
        scatter_by_region(ax, X, V, R, s=4, legend=False)
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
