"""Bifurcation diagram: section X versus the swept parameter (Figs. 9 and 11)."""

from __future__ import annotations

import numpy as np

from .common import new_figure, param_title

SWEEP_STYLE = {
    "up": dict(color="#1f77b4", marker=".", label="sweep up"),
    "down": dict(color="#d62728", marker="x", label="sweep down"),
    "fresh": dict(color="k", marker=".", label="fresh start each value"),
}

SYMBOLS = {"omega": r"$\omega$", "F0": r"$F_0$", "omega_s": r"$\omega_s$", "xi": r"$\xi$",
           "xi_s": r"$\xi_s$", "omega0": r"$\omega_0$", "eta": r"$\eta$"}


def sweep_names(ds) -> list[str]:
    """The direction names ("up", "down", "fresh") of the integer ``sweep`` coordinate of a
    bifurcation or resonance Dataset, from its CF flag_values / flag_meanings."""
    sw = ds["sweep"]
    meanings = dict(zip(np.asarray(sw.attrs["flag_values"]).tolist(),
                        sw.attrs["flag_meanings"].split()))
    return [meanings[int(c)] for c in np.atleast_1d(sw.values)]


def plot_bifurcation(ds, var: str = "X"):
    """Section ``var`` (X or V) of every recorded period versus the swept parameter; up and
    down sweeps in different colours and markers, small dots; failed points are left out."""
    param = ds.attrs["swept_param"]
    fig, ax = new_figure(figsize=(10, 5.5))
    vals = ds[param].values
    nsw = ds.sizes["sweep"]
    npts = vals.size * ds.sizes["n"]
    size = 0.6 if npts > 20000 else 2.0
    for j, name in enumerate(sweep_names(ds)):
        y = ds[var].values[j]  # (value, n)
        x = np.broadcast_to(vals[:, None], y.shape)
        ok = np.isfinite(y)
        style = dict(SWEEP_STYLE.get(str(name), dict(color="0.3", marker=".", label=str(name))))
        marker = style.pop("marker")
        ax.scatter(x[ok], y[ok], s=size * 1.6 if marker == "." else size, marker=marker,
                   linewidths=0.4 if marker == "x" else 0, alpha=0.7 if nsw > 1 else 1.0,
                   zorder=3 if str(name) == "up" else 2, rasterized=True, **style)
    if var == "X":
        ax.axhline(1.0, color="k", lw=0.6, ls="--", label=r"support $X = 1$")
    failed = int(np.count_nonzero(ds.status.values))
    unit = ds[param].attrs.get("units", "")
    ax.set_xlabel(f"{SYMBOLS.get(param, param)} [{unit}]" if unit else SYMBOLS.get(param, param))
    ax.set_ylabel(r"$X(kT)$" if var == "X" else r"$\dot X(kT)$")
    ax.set_xlim(vals[0], vals[-1])
    ttl = f"bifurcation diagram, {ds.sizes['n']} section points per value"
    if failed:
        ttl += f" ({failed} failed points omitted)"
    ax.set_title(ttl, fontsize=10)
    ax.legend(loc="best", fontsize=8, markerscale=4)
    ax.grid(True, lw=0.3, alpha=0.5)
    fig.suptitle(f"{ds.attrs.get('method', '')}: {param_title(ds, _others(param))}", fontsize=9)
    fig.tight_layout()
    return fig


def _others(param):
    return tuple(k for k in ("omega0", "omega_s", "xi", "xi_s", "F0", "omega", "eta") if k != param)
