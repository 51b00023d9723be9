"""``support``: the paper's model, a harmonically forced oscillator hitting a spring-damper
support across a gap (eqs. 4-14).

Free flight  X'' + xi X' + omega0^2 X = F0 cos(omega t); in contact the support adds
omega_s^2 (X - 1) + xi_s X'. ``method="smooth"`` is the paper's switch model with bands of
half-width eta (regions Gamma-, Sigma_alpha, Sigma_beta, Gamma+ of eq. 14; transition fields
eq. 13, or eq. 12 with ``transition="eq12"``); ``method="exact"`` is the non-smooth system
(eta = 0), event-driven in closed form. Both run on specialised kernels with these functions
inlined (``smooth_kernel``, ``exact_kernel``); the generic descriptions in :mod:`.generic`
describe the same model through the interface of :mod:`nonsmooth.models.base` (used by the
generic kernel, and tested against the specialised kernels).
"""

from __future__ import annotations

from ...errors import ParameterError
from ...presets import PRESETS
from ..base import KERNEL_SUPPORT_EXACT, KERNEL_SUPPORT_SMOOTH, Method, Model, Param, _PARAM_NAMES
from . import generic as g
from .switch import REGION_NAMES

PARAMETERS = (
    Param("omega0", 1.0, low=0.0, low_open=True, units="rad/s",
          long_name="natural frequency sqrt(k/m)", symbol=r"$\omega_0$"),
    Param("omega_s", 17.32, low=0.0, units="rad/s",
          long_name="support frequency sqrt(k_s/m)", symbol=r"$\omega_s$"),
    Param("xi", 0.05, low=0.0, units="1/s",
          long_name="damping c/m (multiplies X' directly)", symbol=r"$\xi$"),
    Param("xi_s", 0.6, low=0.0, units="1/s", long_name="support damping c_s/m",
          symbol=r"$\xi_s$"),
    Param("F0", 0.3125, units="1/s^2", long_name="forcing amplitude f0/(m g)", symbol=r"$F_0$"),
    Param("omega", 0.91, low=0.0, low_open=True, units="rad/s", long_name="forcing frequency",
          symbol=r"$\omega$"),
    Param("eta", 1e-5, low=0.0, high=0.5, low_open=True, high_open=True, units="1",
          long_name="half-width of the switching bands (eta_hat / g)", symbol=r"$\eta$"),
)


def _contact(params, mask, max_X, min_X):
    # left Gamma- (a band or contact visited) and the mass reached the support
    return bool(mask & 0b1110) and max_X >= 1.0


def _lines(params, method):
    lines = [(1.0, "support (X = 1)")]
    if method == "smooth":
        lines += [(1.0 - params.eta, "band edge"), (1.0 + params.eta, "band edge")]
    return lines


class _SupportModel(Model):
    """The support model: its parameters are the package's :class:`~nonsmooth.Params` (the
    same names, ranges and one-line messages as before the model interface)."""

    def params(self, **values):
        from ...params import Params
        for k in values:
            if k not in self.param_names:
                raise ParameterError(self.unknown_message(k))
        return Params(**{p.name: values.get(p.name, p.default) for p in self.parameters})


MODEL = _SupportModel(
    name="support",
    description="forced oscillator hitting a spring-damper support across a gap (the paper's "
                "switch model, eqs. 4-14)",
    parameters=PARAMETERS,
    state_names=("X", "V"),
    state_units=("1", "1/s"),
    state_long_names=("displacement X = x/g", "velocity dX/dt"),
    mode_names=REGION_NAMES,
    methods={
        "smooth": Method(g.smooth_field, g.smooth_jacobian, g.smooth_guards,
                         g.smooth_transition, g.smooth_initial, modes=(0, 1, 2, 3),
                         flow_is_homeomorphism=True, kernel=KERNEL_SUPPORT_SMOOTH,
                         continuous_memory=(0,),
                         description="switch model, eqs. 10-14 (RKF45, located switches)"),
        "exact": Method(g.exact_field, g.exact_jacobian, g.exact_guards, g.exact_transition,
                        g.exact_initial, g.exact_linear, closed_form=True, modes=(0, 3),
                        flow_is_homeomorphism=True, kernel=KERNEL_SUPPORT_EXACT,
                        description="closed form between located switching events"),
    },
    n_memory=g.N_MEMORY,
    references=("the founding paper (switch model of a support across a gap), eqs. 4-14",),
    contact=_contact,
    contact_modes=0b1000,  # Gamma+: full support force (eta_study)
    contact_name="contact with the support (max X >= 1 and a band or Gamma+ visited)",
    lines=_lines,
    contact_level=lambda params: 1.0,
    presets=PRESETS,
)
_PARAM_NAMES["support"] = MODEL.param_names
