"""Time response and phase portrait coloured by region, like the paper's Fig. 3."""

from __future__ import annotations

import numpy as np

from .common import (draw_model_lines, draw_phase_lines, has_support_bands, mode_colors,
                     mode_labels, model_lines, model_of, new_figure, param_title,
                     scatter_by_region, shown_components)


def _crossed_between_samples(ax, x, y, R, M, model):
    """Ring markers, in the mode's colour, on the samples after an interval that visited a
    mode seen at neither of its two ends (a band crossed between two samples)."""
    R = np.asarray(R, dtype=int)
    M = np.asarray(M, dtype=int)
    prev = np.concatenate([R[:1], R[:-1]])
    colors, labels = mode_colors(model), mode_labels(model)
    for code in range(len(colors)):
        sel = ((M >> code) & 1).astype(bool) & (R != code) & (prev != code)
        if np.any(sel):
            ax.scatter(np.asarray(x)[sel], np.asarray(y)[sel], s=30, facecolors="none",
                       edgecolors=colors[code], linewidths=1.0, zorder=3,
                       label=f"{labels[code]} crossed between samples")


def plot_time_response(ds, show=None):
    """Figure with X(t) (left) and the phase portrait V(X) (middle), coloured by the model's
    modes, with the model's lines of X drawn (support, smooth method: the band edges
    h_alpha = +-eta and h_beta = +-eta) and a zoom on the switching zone (right: around the
    model's first line, in the (X, V) plane, whatever ``show``: the lines are values of X).
    Modes visited only between two samples
    (``visited`` mask) are marked with rings, so the figure shows every mode the trajectory
    visited. ``show`` = (a, b), two state component names (or "a,b"): the left panel shows
    a(t) and the middle one b(a) instead (a model with more than two components)."""
    fig, axes = new_figure(1, 3, figsize=(15, 4.5), gridspec_kw={"width_ratios": [1.4, 1, 1]})
    t, X, V, R = ds.t.values, ds.X.values, ds.V.values, ds.region.values
    M = ds.visited.values
    model = model_of(ds)
    eta = float(ds.attrs.get("param_eta", 0.0)) if has_support_bands(ds) else 0.0
    lines = model_lines(ds, band_edges=False)
    ia, ib, la, lb, A, B = shown_components(ds, show)
    ax = axes[0]
    ax.plot(t, A, color="0.8", lw=0.8, zorder=0)
    scatter_by_region(ax, t, A, R, s=4, model=model)
    _crossed_between_samples(ax, t, A, R, M, model)
    if ia == 0:
        draw_model_lines(ax, ds, "h", label=False, band_edges=False)
    ax.set_xlabel("t [s]")
    ax.set_ylabel(la)
    ax.set_title("time response")
    ax.legend(loc="upper right", markerscale=3, fontsize=8)
    for ax, zoom in ((axes[1], False), (axes[2], True)):
        x, y = (X, V) if zoom else (A, B)
        ax.plot(x, y, color="0.8", lw=0.8, zorder=0)
        scatter_by_region(ax, x, y, R, s=4, legend=False, model=model)
        _crossed_between_samples(ax, x, y, R, M, model)
        if zoom:
            x1 = lines[0][0] if lines else None
            w = max(20 * eta, 0.02)
            near = np.abs(X - x1) < w if x1 is not None else np.zeros(X.shape, bool)
            if np.any(near):
                vmin, vmax = V[near].min(), V[near].max()
                pad = 0.1 * (vmax - vmin + 1e-9)
                ax.set_xlim(x1 - w, x1 + w)
                ax.set_ylim(vmin - pad, vmax + pad)
            ax.set_title("zoom on the switching bands" if eta > 0.0 else
                         f"zoom near the {lines[0][1]}, (X, V)" if lines else "(X, V)")
        else:
            ax.set_title("phase portrait")
        if zoom or ia == 0:
            draw_phase_lines(ax, ds, label=not zoom)
        ax.set_xlabel("X" if zoom else la)
        ax.set_ylabel("V = dX/dt" if zoom else lb)
    if axes[1].get_legend_handles_labels()[0]:
        axes[1].legend(loc="lower left", fontsize=8)
    fig.suptitle(f"{ds.attrs.get('method', '')}: {param_title(ds)}", fontsize=9)
    fig.tight_layout()
    return fig
