"""nonsmooth: nonlinear dynamics of non-smooth mechanical systems.

Public API: :class:`Params`, :func:`preset`, :func:`simulate`, and the analyses.
"""

from ._version import __version__
from .errors import IntegrationError, NonsmoothError, OutputError, ParameterError
from .kernels import Solver
from .params import PARAM_NAMES, Params
from .presets import PRESETS, preset
from .simulate import simulate

__all__ = ["__version__", "Params", "PARAM_NAMES", "preset", "PRESETS", "simulate", "Solver",
           "NonsmoothError", "ParameterError", "OutputError", "IntegrationError"]
