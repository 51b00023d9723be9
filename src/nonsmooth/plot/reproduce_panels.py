"""Composite figures of the paper reproduction (Figs. 5, 8, 10, 12). Datasets in, Figures out."""

from __future__ import annotations

import numpy as np

from ..reproduction.access import value, x_extrema
from .common import (draw_model_lines, draw_phase_lines, mode_colors, model_of, new_figure,
                     param_title, scatter_by_region)


def plot_support_stiffness(ds):
    """Fig. 5: for every support stiffness (dimension ``omega_s``) the time response X(t) (top)
    and the phase portrait (bottom), coloured by region, the model's lines of X (the support
    position X = 1) drawn."""
    ws = ds["omega_s"].values
    n = ws.size
    fig, axes = new_figure(2, n, figsize=(3.2 * n, 6.2), squeeze=False)
    model = model_of(ds)
    for j, w in enumerate(ws):
        d = ds.isel(omega_s=j)
        t, X, V, R = d.t.values, d.X.values, d.V.values, d.region.values
        ax = axes[0, j]
        ax.plot(t - t[0], X, color="0.75", lw=0.7, zorder=0)
        scatter_by_region(ax, t - t[0], X, R, s=2, legend=(j == 0), model=model)
        draw_model_lines(ax, ds, "h", label=False, band_edges=False, omega_s=w)
        ax.set_title(rf"$\omega_s$ = {w:g}, max X = {x_extrema(d)[0]:.4f}", fontsize=9)
        ax.set_xlabel("t - t0 [s]")
        if j == 0:
            ax.set_ylabel("X")
            ax.legend(fontsize=7, markerscale=3, loc="lower left")
        ax = axes[1, j]
        ax.plot(X, V, color="0.75", lw=0.7, zorder=0)
        scatter_by_region(ax, X, V, R, s=2, legend=False, model=model)
        draw_model_lines(ax, ds, "v", label=False, band_edges=False, omega_s=w)
        ax.set_xlabel("X")
        if j == 0:
            ax.set_ylabel("V = dX/dt")
    fig.suptitle("Fig. 5: response for different support stiffness (settled, "
                 f"{param_title(ds, exclude=('omega_s',))})", fontsize=10)
    fig.tight_layout()
    return fig


def plot_coexisting(ds):
    """Fig. 8: the coexisting periodic orbits (dimension ``attractor``) in the phase plane, each
    with its section points; the model's lines of X (the support position X = 1) drawn."""
    fig, ax = new_figure(figsize=(6.5, 5))
    colors = ("0.15", "#e08214", "#2166ac", "#1b7837")
    for k, a in enumerate(ds["attractor"].values):
        d = ds.sel(attractor=a)
        ox, ov = d.orbit_X.values, d.orbit_V.values
        ok = np.isfinite(ox)
        c = colors[k % len(colors)]
        lab = (f"{'contact' if int(d.contact) else 'no contact'}, period {int(d.period)}, "
               f"basin {100 * float(d.basin_fraction):.0f}%, IC ({float(d.x0):.2f}, {float(d.v0):.2f})")
        ax.plot(ox[ok], ov[ok], color=c, lw=1.2, label=lab)
        ax.plot(d.X.values, d.V.values, "o", ms=5, mfc="w", mec=c, mew=1.5)
    draw_model_lines(ax, ds, "v", band_edges=False, style=dict(lw=0.7))
    ax.set_xlabel("X")
    ax.set_ylabel("V = dX/dt")
    ax.legend(fontsize=8, loc="lower left")
    ax.set_title("Fig. 8: coexisting periodic attractors (circles: section t = kT)\n"
                 + param_title(ds), fontsize=9)
    fig.tight_layout()
    return fig


def _per(p) -> str:
    p = int(p)
    return f"period {p}" if p > 0 else ("not settled" if p < 0 else "not periodic")


def plot_section_panel(ds, title: str = "", exact=None):
    """Figs. 10/12: phase portrait coloured by region with the Poincaré section points (left)
    and the Poincaré map alone (right). ``ds`` is a ``poincare`` Dataset; ``exact`` an optional
    one of the exact model at the same parameters, drawn in grey for comparison."""
    fig, axes = new_figure(1, 2, figsize=(12, 4.8))
    per = int(value(ds, "period", 0))
    ax = axes[0]
    ox, ov, orr = ds.orbit_X.values, ds.orbit_V.values, ds.orbit_region.values
    ax.plot(ox, ov, color="0.7", lw=0.6, zorder=0)
    scatter_by_region(ax, ox, ov, orr, s=1.5, model=ds)
    npts = min(ds.sizes["n"], 2000)
    ax.plot(ds.X.values[-npts:], ds.V.values[-npts:], "k.", ms=4 if per > 0 else 1,
            label="section t = kT", zorder=3)
    draw_phase_lines(ax, ds, label=False)
    draw_model_lines(ax, ds, "v", label=False, band_edges=False, style=dict(ls="-"))
    ax.set_xlabel("X")
    ax.set_ylabel("V = dX/dt")
    ax.set_title("phase portrait", fontsize=9)
    ax.legend(fontsize=7, markerscale=3, loc="lower left")
    ax = axes[1]
    if exact is not None:
        ax.plot(exact.X.values, exact.V.values, ".", color="0.6", ms=2,
                label=f"exact model ({_per(value(exact, 'period', 0))})")
    ax.plot(ds.X.values, ds.V.values, ".", color=mode_colors(model_of(ds))[-1], ms=6 if per > 0 else 2,
            label=f"smoothed switch model ({_per(per)})")
    ax.set_xlabel("X")
    ax.set_ylabel("V = dX/dt")
    ax.set_title(f"Poincaré section ({ds.sizes['n']} points)", fontsize=9)
    ax.legend(fontsize=7, markerscale=3)
    fig.suptitle(f"{title} -- {_per(per)}, max X = {float(value(ds, 'max_X')):.4f}\n"
                 f"{param_title(ds)}", fontsize=9)
    fig.tight_layout()
    return fig
