"""Self-excited systems: the bifurcation diagram on a section surface."""

from __future__ import annotations

import numpy as np

from .common import model_of, new_figure, param_symbol, param_title, shown_components


def plot_surface_bifurcation(ds, show: str | None = None):
    """The crossings of the section surface (one state component, ``show``: a name, default
    X; or ``"phase"``, a forced system's forcing phase at the crossings) against the swept
    parameter (``surface_bifurcation_diagram``); values where the orbit comes to rest on an
    equilibrium or stops crossing are marked on the axis."""
    fig, ax = new_figure(figsize=(7.5, 4.6))
    param = ds.attrs["param"]
    names = str(ds.attrs.get("state_names", "X V")).split()
    if show == "phase" and "phase" in ds:
        label, U = r"forcing phase $\omega t$ mod $2\pi$", ds.phase.values
    else:
        pair = (show or names[0], names[1] if (show or names[0]) != names[1] else names[0])
        _, _, label, _, U, _ = shown_components(ds, pair)
    lam = ds[param].values
    x = np.repeat(lam[:, None], U.shape[1], axis=1).ravel()
    if show == "phase" and "phase" in ds:  # every crossing visible: a branch's max would
        ax.scatter(x, U.ravel(), s=2, color="k", lw=0)  # hide a doubling's other branch
    else:
        ax.plot(x, U.ravel(), ",", color="k", alpha=0.7)
        ax.scatter(lam, np.nanmax(U, axis=1), s=2, color="k")  # visible also for few crossings
    rest = ds.at_equilibrium.values.astype(bool) | (ds.status.values != 0)
    if rest.any():
        lo = np.nanmin(U) if np.isfinite(U).any() else 0.0
        ax.plot(lam[rest], np.full(rest.sum(), lo), "|", color="tab:red", ms=8,
                label="at rest / no crossing")
        ax.legend(loc="best", fontsize=8)
    ax.set_xlabel(param_symbol(model_of(ds), param))
    ax.set_ylabel(f"{label} at the crossings")
    ax.set_title(f"crossings of {ds.attrs.get('section', '?')} after "
                 f"{ds.attrs.get('transient', '?')} transient crossings\n{ds.attrs.get('method', '')}: "
                 f"{param_title(ds, exclude=(param,))}", fontsize=9)
    ax.grid(True, lw=0.3, alpha=0.5)
    fig.tight_layout()
    return fig
