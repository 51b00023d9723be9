"""Phase portrait with its section points and the stroboscopic Poincaré map (Figs. 10, 12)."""

from __future__ import annotations

import numpy as np

from .common import (draw_model_lines, model_of, new_figure, param_title, scatter_by_region,
                     shown_components)


def motion_word(ds) -> str:
    """The verdict of ``ds.motion`` in words ("chaotic", "quasi-periodic", "not settled", as
    ``analysis.stability.VERDICTS``), from its CF flag meanings."""
    word = ds["motion"].attrs["flag_meanings"].split()[int(ds["motion"])]
    return word.replace("quasi_", "quasi-").replace("_", " ")


def _period_text(ds) -> str:
    p = int(ds["period"])
    if p == 0 and "motion" in ds and int(ds["motion"]) > 0:  # the lambda1 verdict
        kind = f"not periodic: {motion_word(ds)}"
    else:
        kind = (f"period-{p}" if p > 0 else "not periodic (chaotic or quasi-periodic)" if p == 0
                else "not settled (still converging)")
    contact = "contact" if int(ds["contact"]) else "no contact"
    return f"{kind}, {contact}"


def plot_poincare(ds, show=None):
    """Left: phase portrait V(X) over the orbit run (coloured by the model's modes) with the
    section points on it and the model's lines of X (support: X = 1); right: the Poincaré map
    (all section points, small dots). ``show`` = (a, b), two state component names (or
    "a,b"): both panels in the plane (a, b) instead."""
    fig, (ax0, ax1) = new_figure(1, 2, figsize=(11, 4.6))
    ia, ib, la, lb, oX, oV = shown_components(ds, show, "orbit_")
    X, V = shown_components(ds, show)[4:]
    oR = ds.orbit_region.values
    ax0.plot(oX, oV, color="0.55", lw=0.6, zorder=1)
    scatter_by_region(ax0, oX, oV, oR, s=1.5, model=model_of(ds), zorder=2)
    few = X.size <= 64 or int(ds["period"]) > 0
    ax0.scatter(X, V, s=16 if few else 1.0, color="k",
                marker="o", zorder=3, linewidths=0,
                label=r"section $t = kT$")
    if ia == 0:
        draw_model_lines(ax0, ds, "v", label=False, band_edges=False)
    ax0.set_xlabel(la)
    ax0.set_ylabel(lb)
    ax0.set_title(f"(a) phase portrait: {_period_text(ds)}", fontsize=10)
    ax0.legend(loc="lower left", fontsize=7, markerscale=2)
    n = X.size
    ax1.scatter(X, V, s=25.0 if few else (1.0 if n > 500 else 6.0), color="k", linewidths=0)
    names = str(ds.attrs.get("state_names", "X V")).split()
    ax1.set_xlabel(f"${names[ia]}(kT)$")  # (the model's own names: the ball's Z)
    ax1.set_ylabel(f"${names[ib]}(kT)$")
    title = f"(b) Poincaré map, {n} points after {ds.attrs.get('transient', '?')} periods"
    spread = _zoom_out(ax1, X, V, oX, oV)
    if spread is not None:
        title += f" (all within {spread:.1g})"
    ax1.set_title(title, fontsize=10)
    for ax in (ax0, ax1):
        ax.grid(True, lw=0.3, alpha=0.5)
    fig.suptitle(f"{ds.attrs.get('method', '')}: {param_title(ds)}", fontsize=9)
    fig.tight_layout()
    return fig


def _zoom_out(ax, X, V, oX, oV, rel=1e-6):
    """Where the section points coincide to ``rel`` of the orbit's extent (a periodic orbit:
    they differ by round-off), centre the map's axes on them with 5 % of the orbit's extent
    either side, instead of letting the axes zoom into the round-off; returns the points'
    largest spread then (else None)."""
    X, V = np.asarray(X, float), np.asarray(V, float)
    ok = np.isfinite(X) & np.isfinite(V)
    if not ok.any():
        return None
    X, V = X[ok], V[ok]
    spans = [float(np.ptp(a)) for a in (X, V)]
    extents = [float(np.nanmax(o) - np.nanmin(o)) if np.size(o) else 0.0 for o in (oX, oV)]
    if not all(e > 0.0 and sp <= rel * e for sp, e in zip(spans, extents)):
        return None
    ax.set_xlim(float(X.mean()) - 0.05 * extents[0], float(X.mean()) + 0.05 * extents[0])
    ax.set_ylim(float(V.mean()) - 0.05 * extents[1], float(V.mean()) + 0.05 * extents[1])
    return max(spans)
