"""Stability and chaos: the running Lyapunov spectrum, and a periodic orbit with its section
points and Floquet multipliers. Datasets of ``nonsmooth.lyapunov`` / ``nonsmooth.periodic_orbit``
in, Figures out (nothing is integrated here)."""

from __future__ import annotations

import numpy as np

from .common import (MODE_COLORS, draw_model_lines, model_of, new_figure, param_title, state_labels,
                     scatter_by_region, shown_components)


def _figure(ax, figsize):
    """(figure, axes, whether the figure is ours to lay out)."""
    if ax is None:
        return (*new_figure(figsize=figsize), True)
    return ax.figure, ax, False


def multiplier_value(ds, i: int, digits: int = 4) -> str:
    """Multiplier ``i`` (0-based) of a periodic_orbit Dataset as ``a`` or ``a+bj``."""
    re, im = float(ds["multiplier_real"][i]), float(ds["multiplier_imag"][i])
    return f"{re:.{digits}g}" if im == 0 else f"{re:.{digits}g}{im:+.{digits}g}j"


def multiplier_text(ds, i: int) -> str:
    """``mu_i = a+bj, |mu_i| = r`` of multiplier ``i`` (0-based) of a periodic_orbit Dataset."""
    return (f"mu{i + 1} = {multiplier_value(ds, i)}, "
            f"|mu{i + 1}| = {float(ds['multiplier_abs'][i]):.4g}")


def plot_lyapunov(ds, ax=None):
    """The running estimate of each Lyapunov exponent (per unit time) over the recorded
    forcing periods (log axis), with its final value +- one standard error as a band; the
    verdict in the title."""
    fig, ax, own = _figure(ax, (7.5, 4.8))
    periods = ds["period"].values
    running = np.asarray(ds["running"].values, dtype=float)
    for j, i in enumerate(ds["i"].values):
        c = MODE_COLORS[j % len(MODE_COLORS)]
        y = running[:, j]
        ok = np.isfinite(y)
        lam, err = float(ds["exponent"][j]), float(ds["stderr"][j])
        label = (rf"$\lambda_{{{i}}}$ = {lam:.4g}" + (f" ± {err:.2g}" if np.isfinite(err) else "")
                 + " 1/s")
        ax.plot(periods[ok], y[ok], color=c, lw=1.2, label=label)
        if np.isfinite(lam):
            ax.axhline(lam, color=c, lw=0.7, ls="--")
            if np.isfinite(err) and err > 0:
                ax.axhspan(lam - err, lam + err, color=c, alpha=0.2, lw=0)
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xscale("log")
    if periods.size:
        ax.set_xlim(periods[0], max(periods[-1], periods[0] + 1))
    ax.set_xlabel("forcing periods recorded")
    ax.set_ylabel(r"running estimate of $\lambda_i$ [1/s]")
    ax.grid(True, which="both", lw=0.3, alpha=0.5)
    ax.legend(loc="best", fontsize=8, title="final value ± 1 s.e. (band)", title_fontsize=8)
    a = ds.attrs
    ax.set_title(f"Lyapunov spectrum: {a.get('verdict', '?')}, {a.get('periods', '?')} periods "
                 f"after {a.get('transient', '?')}\n{a.get('method', '')}: {param_title(ds)}",
                 fontsize=9)
    if own:
        fig.tight_layout()
    return fig


def plot_orbit(ds, ax=None, show=None):
    """The periodic orbit's phase portrait V(X) coloured by the model's modes, its section
    points (t = jT) marked, the model's lines of X (support: X = 1), and the Floquet
    multipliers with the verdict in a text box. ``show`` = (a, b) (or "a,b"): the plane of
    two other state components instead."""
    fig, ax, own = _figure(ax, (6.8, 5.2))
    ia, ib, la, lb, X, V = shown_components(ds, show)
    Xs, Vs = shown_components(ds, show, suffix="_section")[4:]
    R = ds["mode"].values
    a = ds.attrs
    k = int(a.get("k", ds.sizes.get("point", 1)))
    ok = np.isfinite(X) & np.isfinite(V)
    ax.plot(X[ok], V[ok], color="0.55", lw=0.8, zorder=1)
    scatter_by_region(ax, X[ok], V[ok], R[ok], s=4, model=model_of(ds), zorder=2)
    ax.scatter(Xs, Vs, s=60, facecolor="w", edgecolor="k", lw=1.5, zorder=3,
               label=r"section $t = jT$")
    if ia == 0:
        draw_model_lines(ax, ds, "v", band_edges=False)
    ax.set_xlabel(la)
    ax.set_ylabel(lb)
    ax.grid(True, lw=0.3, alpha=0.5)
    ax.legend(loc="lower left", fontsize=7, markerscale=1.5)
    found = a.get("status", "") == "converged"
    lines = [multiplier_text(ds, i) for i in range(ds.sizes.get("multiplier", 0))]
    lines.append(f"{a.get('verdict', '?')}" + ("" if found else f" ({a.get('status', '?')})"))
    lo, hi = ax.get_ylim()  # room above the orbit for the text box
    ax.set_ylim(lo, hi + (0.06 + 0.05 * len(lines)) * (hi - lo))
    ax.text(0.98, 0.98, "\n".join(lines), transform=ax.transAxes, ha="right", va="top",
            fontsize=8, family="monospace",
            bbox=dict(boxstyle="round,pad=0.3", fc="white", ec="0.6", alpha=0.9))
    what = f"period-{k} orbit" + ("" if found else " (not found: last Newton iterate)")
    ax.set_title(f"{what}: {a.get('verdict', '?')}, contact fraction "
                 f"{float(ds['contact_fraction']):.3g}\n{a.get('method', '')}: {param_title(ds)}",
                 fontsize=9)
    if own:
        fig.tight_layout()
    return fig
