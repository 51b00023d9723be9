"""Figures: Dataset in, matplotlib Figure out. Plots never integrate.

Figures are made with the pyplot-free ``matplotlib.figure.Figure`` API
(:func:`nonsmooth.plot.common.new_figure`): importing or using this package never selects a
backend nor touches pyplot's state, so it is safe in notebooks and GUI programs. The plot
functions are loaded on first use (``nonsmooth.plot.plot_poincare``, ...).
"""

from __future__ import annotations

import importlib

#: Mode colours, one per mode code (up to models.base.MAX_MODES = 8); the first four are the
#: region colours of the support model (codes of models.support.switch).
MODE_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
               "#17becf")
REGION_COLORS = MODE_COLORS[:4]
#: Legend labels of the paper's regions (mathtext): the support model's ``mode_labels``; every
#: model's own labels are ``Model.mode_labels`` (default ``mode_names``) and
#: ``Model.line_labels``.
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
    "plot_basin_entropy": ".basin_entropy",
    "plot_attractor_continuation": ".attractor_continuation",
    "plot_manifolds": ".manifolds",
    "plot_support_stiffness": ".reproduce_panels",
    "plot_coexisting": ".reproduce_panels",
    "plot_section_panel": ".reproduce_panels",
    "plot_lyapunov": ".stability",
    "plot_orbit": ".stability",
    "plot_continuation": ".continuation",
    "plot_two_parameter": ".continuation",
    "plot_special_curve": ".continuation",
    "plot_parameter_map": ".parameter_map",
    "plot_lambda1_map": ".parameter_map",
}

__all__ = ["MODE_COLORS", "REGION_COLORS", "REGION_LABELS",
           *_PLOTS]


def __getattr__(name: str):
    if name not in _PLOTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_PLOTS[name], __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
