"""Figures: Dataset in, matplotlib Figure out. Plots never integrate.

Figures are made with the pyplot-free ``matplotlib.figure.Figure`` API
(:func:`nonsmooth.plot.common.new_figure`): importing or using this package never selects a
backend nor touches pyplot's state, so it is safe in notebooks and GUI programs. The plot
functions are loaded on first use (``nonsmooth.plot.plot_poincare``, ...).
"""

from __future__ import annotations

import importlib

#: Region colours used by every figure (codes of the support model, models.support.switch).
REGION_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728")
REGION_LABELS = (r"$\Gamma_-$", r"$\Sigma_\alpha$", r"$\Sigma_\beta$", r"$\Gamma_+$")

#: Plot function -> module of this package that defines it.
_PLOTS = {
    "plot_time_response": ".time_response",
    "plot_poincare": ".poincare",
    "plot_bifurcation": ".bifurcation",
    "plot_resonance": ".resonance",
    "plot_eta_study": ".eta_study",
    "plot_basins": ".basins",
    "plot_attractors": ".basins",
    "plot_support_stiffness": ".reproduce_panels",
    "plot_coexisting": ".reproduce_panels",
    "plot_section_panel": ".reproduce_panels",
}

__all__ = ["REGION_COLORS", "REGION_LABELS", *_PLOTS]


def __getattr__(name: str):
    if name not in _PLOTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_PLOTS[name], __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
