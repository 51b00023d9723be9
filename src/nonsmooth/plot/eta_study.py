"""Figure of the eta audit in the style of the paper's Fig. 4: one phase portrait per eta."""

from __future__ import annotations

import math

import numpy as np

from .common import (draw_phase_lines, mode_labels, model_lines, model_of, new_figure, param_title,
                     scatter_by_region)


def _full_contact(ds) -> str:
    """How the verdict names the model's full-contact modes (support: Gamma+)."""
    m = model_of(ds)
    labels = mode_labels(m)
    names = [labels[k] for k in range(len(labels)) if m is not None and (m.contact_modes >> k) & 1]
    return " / ".join(names) or "contact"


def _verdict(ds, i) -> str:
    if int(ds["status"].values[i]) != 0:
        return "failed"
    reach = int(ds["reaches_gamma_plus"].values[i])
    per = int(ds["period"].values[i])
    e_reach = int(ds["exact_reaches_gamma_plus"])
    e_per = int(ds["exact_period"])
    if int(ds["agrees"].values[i]):
        return "agrees with exact"
    if reach != e_reach:
        full = _full_contact(ds)
        return f"never reaches {full}" if not reach else f"enters {full}, exact does not"
    if per != e_per:
        return f"period {per or 'none'} (exact {e_per or 'none'})"
    return f"distance {float(ds['distance_to_exact'].values[i]):.2g} too large"


def plot_eta_study(ds):
    """Phase portraits (X, V) per eta, points coloured by the model's modes, the model's lines
    at each eta (support: band edges X = 1 +- eta and h_beta = +-eta), the exact (eta = 0)
    orbit overlaid, and an enlargement of the band around the model's first line (support:
    X = 1). Title: eta and the verdict of the audit. Dataset in, Figure out."""
    model = model_of(ds)
    etas = np.asarray(ds["eta"].values, dtype=float)
    n = len(etas)
    ncol = min(n, 2) if n <= 4 else 3
    nrow = int(math.ceil(n / ncol))
    fig, axes = new_figure(nrow, ncol, figsize=(5.2 * ncol, 4.2 * nrow), squeeze=False)
    eX = np.asarray(ds["exact_orbit_X"].values)
    eV = np.asarray(ds["exact_orbit_V"].values)
    for i, eta in enumerate(etas):
        ax = axes[i // ncol][i % ncol]
        X = np.asarray(ds["orbit_X"].values[i])
        V = np.asarray(ds["orbit_V"].values[i])
        R = np.asarray(ds["orbit_region"].values[i])
        ok = np.isfinite(X) & np.isfinite(V)
        scatter_by_region(ax, X[ok], V[ok], R[ok], s=2.0, legend=(i == 0), model=model)
        ax.plot(eX, eV, color="k", lw=0.5, alpha=0.7, label="exact ($\\eta = 0$)" if i == 0 else None)
        vals = np.concatenate([V[ok], eV[np.isfinite(eV)]])
        if vals.size:
            pad = 0.05 * (vals.max() - vals.min() + 1e-12)
            ax.set_ylim(vals.min() - pad, vals.max() + pad)
        draw_phase_lines(ax, ds, label=(i == 0), eta=eta)
        ax.set_xlabel("X")
        ax.set_ylabel("V")
        ax.set_title(f"$\\eta$ = {eta:.3g}: {_verdict(ds, i)}", fontsize=10)
        # enlargement of the switching band around the model's first line (support: X = 1)
        lines = model_lines(ds, "smooth", band_edges=False, eta=eta)
        x1 = lines[0][0] if lines else np.nan
        w = 6.0 * eta
        near = ok & (np.abs(X - x1) < w)
        enear = np.isfinite(eX) & (np.abs(eX - x1) < w)
        if lines and (np.any(near) or np.any(enear)):
            vs = np.concatenate([V[near], eV[enear]])
            ins = ax.inset_axes([0.04, 0.58, 0.36, 0.38])
            scatter_by_region(ins, X[near], V[near], R[near], s=3.0, legend=False, model=model)
            ins.plot(eX, eV, color="k", lw=0.5, alpha=0.7)
            ins.set_xlim(x1 - w, x1 + w)
            vpad = 0.1 * (vs.max() - vs.min() + 1e-9)
            ins.set_ylim(vs.min() - vpad, vs.max() + vpad)
            draw_phase_lines(ins, ds, label=False, eta=eta)
            ins.tick_params(labelsize=6)
    for j in range(n, nrow * ncol):
        axes[j // ncol][j % ncol].axis("off")
    handles, labels = axes[0][0].get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 6), fontsize=8,
                   markerscale=4, frameon=False)
    rec = float(ds["recommended_eta"])
    rec_s = f"{rec:.3g}" if math.isfinite(rec) else "none"
    fig.suptitle(f"Band half-width audit ({param_title(ds, exclude=('eta',))});"
                 f" recommended $\\eta$ = {rec_s}", fontsize=10)
    fig.tight_layout(rect=(0, 0.05, 1, 0.96))
    return fig
