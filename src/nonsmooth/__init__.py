"""nonsmooth: nonlinear dynamics of non-smooth mechanical systems.

Public API: :func:`models`, :func:`model` (a model's ``params(...)``), :func:`preset` (the
paper's parameter sets of the ``support`` model), :func:`simulate`, and the analyses.
``Params`` is a deprecated alias of ``model("support").params``.

Importing the package is cheap and has no side effects: the public names are loaded on first
use (PEP 562), so numba, xarray, scipy and matplotlib are imported, and the kernels compiled or
loaded from numba's cache, only when a computation or a figure needs them.
"""

from __future__ import annotations

import importlib
import sys
import types

from ._version import __version__
from .errors import IntegrationError, NonsmoothError, OutputError, ParameterError

#: Public name -> module (relative to this package) that defines it.
_LAZY = {
    "Params": ".models.support", "PARAM_NAMES": ".models.support",
    "preset": ".models.support", "PRESETS": ".models.support",
    "Solver": ".kernels",
    "model": ".models",
    "model_from_equations": ".models.equations",
    "Guard": ".models.equations",
    "simulate": ".simulate",
    "poincare": ".analysis.poincare",
    "bifurcation_diagram": ".analysis.bifurcation",
    "resonance_curve": ".analysis.resonance",
    "basins": ".analysis.basins",
    "basin_entropy": ".analysis.basin_entropy",
    "attractor_continuation": ".analysis.attractor_continuation",
    "eta_study": ".analysis.eta_study",
    "lyapunov": ".analysis.stability",
    "periodic_orbit": ".analysis.stability",
    "continuation": ".analysis.continuation",
    "two_parameter_curve": ".analysis.continuation",
    "fold_curve": ".analysis.fold_curve",
    "period_doubling_curve": ".analysis.fold_curve",
    "grazing_curve": ".analysis.fold_curve",
    "neimark_sacker_curve": ".analysis.fold_curve",
    "manifolds": ".analysis.manifolds",
    "homoclinic_tangency": ".analysis.manifolds",
    "parameter_map": ".analysis.parameter_map",
    "surface_section": ".analysis.autonomous",
    "surface_bifurcation_diagram": ".analysis.autonomous",
    "limit_cycle": ".analysis.autonomous",
    "equilibria": ".analysis.autonomous",
    "equilibrium_branch": ".analysis.autonomous",
    "limit_cycle_branch": ".analysis.autonomous",
    "surface_basins": ".analysis.autonomous",
    "reproduce": ".reproduction",
}

#: Subpackages and modules reachable as attributes (``ns.io``, ``ns.plot``, ...).
_SUBMODULES = ("analysis", "cli", "errors", "integrate", "io", "kernels", "models",
               "plot", "reproduction", "status", "sweep", "chunks")

__all__ = ["__version__", "Params", "PARAM_NAMES", "model", "models", "model_from_equations", "Guard", "preset", "PRESETS", "simulate", "reproduce", "Solver",
           "eta_study", "lyapunov", "periodic_orbit", "continuation", "two_parameter_curve", "fold_curve", "period_doubling_curve", "grazing_curve", "neimark_sacker_curve", "manifolds", "homoclinic_tangency", "parameter_map", "poincare", "bifurcation_diagram", "resonance_curve", "basins", "basin_entropy", "attractor_continuation",
           "surface_section", "surface_bifurcation_diagram", "limit_cycle", "equilibria", "equilibrium_branch",
           "limit_cycle_branch", "surface_basins",
           "NonsmoothError", "ParameterError", "OutputError", "IntegrationError"]


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name], __name__), name)
    elif name in _SUBMODULES:
        value = importlib.import_module("." + name, __name__)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__) | set(_SUBMODULES))


class _Package(types.ModuleType):
    def __setattr__(self, name, value):
        # importing the submodule nonsmooth.simulate must not hide the function simulate
        if isinstance(value, types.ModuleType) and _LAZY.get(name) == "." + name:
            value = getattr(value, name)
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package
