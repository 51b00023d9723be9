"""nonsmooth: nonlinear dynamics of non-smooth mechanical systems.

Public API: :class:`Params`, :func:`preset`, :func:`simulate`, and the analyses.
"""

from ._version import __version__
from .errors import IntegrationError, NonsmoothError, OutputError, ParameterError
from .kernels import Solver
from .params import PARAM_NAMES, Params
from .presets import PRESETS, preset
from .simulate import simulate
from .analysis.poincare import poincare
from .analysis.bifurcation import bifurcation_diagram
from .analysis.resonance import resonance_curve
from .analysis.basins import basins
from .analysis.eta_study import eta_study
from .reproduction import reproduce

__all__ = ["__version__", "Params", "PARAM_NAMES", "preset", "PRESETS", "simulate", "reproduce", "Solver",
           "eta_study", "poincare", "bifurcation_diagram", "resonance_curve", "basins",
           "NonsmoothError", "ParameterError", "OutputError", "IntegrationError"]
