"""``support``: the paper's model, a harmonically forced oscillator hitting a spring-damper
support across a gap (eqs. 4-14).

Free flight  X'' + xi X' + omega0^2 X = F0 cos(omega t); in contact the support adds
omega_s^2 (X - 1) + xi_s X'. Methods:

* ``smooth``: the paper's switch model with bands of half-width eta (regions Gamma-,
  Sigma_alpha, Sigma_beta, Gamma+ of eq. 14; transition fields eq. 13);
* ``smooth_eq12``: the same regions with the convex transition fields of eq. 12;
* ``smooth_closed_form``: the switch model of ``smooth`` solved exactly, on the generic
  kernel: Gamma-, Sigma_beta and Gamma+ are linear oscillators, propagated in closed form,
  and Sigma_alpha (whose field uses the memory Va) by RKF45 at rtol 1e-12, so the solution is
  that of the equations to about 1e-12, where ``smooth`` carries the RKF45's error at the
  paper's tolerances (1e-8);
* ``exact``: the non-smooth system (eta = 0), event-driven in closed form.

``smooth``, ``smooth_eq12`` and ``exact`` run on specialised kernels with these functions
inlined (``smooth_kernel``, ``exact_kernel``); the generic descriptions in :mod:`.generic`
describe the same model through the interface of :mod:`nonsmooth.models.base` (used by the
generic kernel for tangent dynamics and for ``smooth_closed_form``, and tested against the
specialised kernels). Its parameters and the paper's sets are in :mod:`.parameters`.
"""

from __future__ import annotations

import warnings

from ..base import (KERNEL_SUPPORT_EXACT, KERNEL_SUPPORT_SMOOTH, Method, Model, ModelParams,
                    _PARAM_NAMES)
from . import generic as g
from .parameters import PARAM_NAMES, PARAMETERS, PRESETS, check, dimensionless
from .switch import REGION_NAMES, TRANSITION_EQ12


def _contact(params, mask, max_X, min_X):
    # left Gamma- (a band or contact visited) and the mass reached the support
    return bool(mask & 0b1110) and max_X >= 1.0


def _lines(params, method):
    lines = [(1.0, "support (X = 1)")]
    if method != "exact" and params is not None:
        lines += [(1.0 - params.eta, "band edge"), (1.0 + params.eta, "band edge")]
    return lines


MODEL = Model(
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
                         continuous_memory=(0,), evidence="smooth_closed_form",
                         description="switch model, eqs. 10-14 (RKF45, located switches)"),
        "smooth_eq12": Method(g.smooth_eq12_field, g.smooth_eq12_jacobian, g.smooth_guards,
                              g.smooth_transition, g.smooth_initial, modes=(0, 1, 2, 3),
                              flow_is_homeomorphism=True, kernel=KERNEL_SUPPORT_SMOOTH,
                              variant=TRANSITION_EQ12,
                              description="switch model with the convex transition fields of "
                                          "eq. 12 instead of eq. 13 (RKF45, located switches)"),
        "smooth_closed_form": Method(
            g.smooth_field, g.smooth_jacobian, g.smooth_guards, g.smooth_transition,
            g.smooth_initial, g.smooth_linear, closed_form=True, modes=(0, 1, 2, 3),
            flow_is_homeomorphism=True, continuous_memory=(0,), rtol=1e-12, atol=1e-14,
            dop853=False,  # Sigma_alpha, a thin band, is crossed in a few short steps
            description="switch model, eqs. 10-14, solved exactly: closed form in Gamma-, "
                        "Sigma_beta and Gamma+, RKF45 at rtol 1e-12 in Sigma_alpha (whose "
                        "field uses the entry velocity Va)"),
        "exact": Method(g.exact_field, g.exact_jacobian, g.exact_guards, g.exact_transition,
                        g.exact_initial, g.exact_linear, closed_form=True, modes=(0, 3),
                        flow_is_homeomorphism=True, kernel=KERNEL_SUPPORT_EXACT,
                        description="closed form between located switching events",
                        unused=("eta",)),
    },
    n_memory=g.N_MEMORY,
    references=("the founding paper (switch model of a support across a gap), eqs. 4-14",),
    contact=_contact,
    contact_modes=0b1000,  # Gamma+: full support force (eta_study)
    contact_name="contact with the support (max X >= 1 and a band or Gamma+ visited)",
    mode_long_name="region of eq. 14",
    lines=_lines,
    contact_level=lambda params: 1.0,
    mode_labels=(r"$\Gamma_-$", r"$\Sigma_\alpha$", r"$\Sigma_\beta$", r"$\Gamma_+$"),
    line_labels={"support (X = 1)": r"support $X = 1$"},
    axis_labels=(r"$X = x/g$", r"$V = \dot X$"),
    mode_word="regions",
    contact_label="Gamma+",
    presets=PRESETS,
    check=check,
)
_PARAM_NAMES["support"] = MODEL.param_names


def preset(name: str) -> ModelParams:
    """The paper's parameter set ``name`` (see :data:`PRESETS` or ``nonsmooth presets``)."""
    return MODEL.preset(name)


def from_dimensional(**quantities) -> ModelParams:
    """The support model's parameters from dimensional quantities (eq. 3): ``m, k, c, k_s,
    c_s, f0, g, omega`` and ``eta_hat`` (see :func:`.parameters.dimensionless`)."""
    return MODEL.params(**dimensionless(**quantities))


def _deprecated(old: str, new: str) -> None:
    warnings.warn(f"nonsmooth.{old} is deprecated: use {new}", DeprecationWarning, stacklevel=3)


class _ParamsAlias(type):
    def __call__(cls, *args, **values):
        _deprecated("Params(...)", "nonsmooth.model('support').params(...)")
        if len(args) > len(PARAM_NAMES):
            raise TypeError(f"Params takes at most {len(PARAM_NAMES)} values, got {len(args)}")
        return MODEL.params(**dict(zip(PARAM_NAMES, args)), **values)

    def __instancecheck__(cls, obj):
        return isinstance(obj, ModelParams) and obj.model is MODEL


class Params(metaclass=_ParamsAlias):
    """Deprecated alias (one release) of ``nonsmooth.model("support").params``: the support
    model's values are ordinary :class:`~nonsmooth.models.base.ModelParams`."""

    @staticmethod
    def from_dimensional(**quantities) -> ModelParams:
        _deprecated("Params.from_dimensional", "nonsmooth.models.support.from_dimensional")
        return from_dimensional(**quantities)

    @staticmethod
    def from_attrs(source, **point) -> ModelParams:
        _deprecated("Params.from_attrs", "nonsmooth.model('support').params_from_attrs")
        return MODEL.params_from_attrs(source, _call="Params.from_attrs", **point)
