"""The paper's switch model (eqs. 7, 11, 13, 14) written as equations, with memory slots.

The built-in ``support`` model's ``smooth`` method, written with ``ns.model_from_equations``
instead of hand-written numba functions: four regions (Gamma-, Sigma_alpha, Sigma_beta,
Gamma+), the support force of eq. 13 in the bands, and two memory slots:

* ``Va``, the velocity at which the orbit entered Sigma_alpha (eq. 13a's X_dot_a): a
  continuous memory slot (the field depends on it, so the tangent dynamics carry it and its
  Jacobian column is derived);
* ``side``, which of the two inequalities of the union region Gamma- holds (0: h_alpha <=
  -eta, 1: h_beta >= eta): a flag, which the surface of Gamma- uses.

``tests/test_equations_memory.py`` checks it against the built-in model on the generic kernel
(stroboscopic points, regions visited, Floquet multipliers). Use it as any user model::

    nonsmooth poincare --model examples/switch_model_equations.py:MODEL --preset table3 \\
        --method smooth

It is written for omega_s > 0 (h_beta divides by omega_s^2; the built-in model also takes
omega_s = xi_s = 0, a support that is not there).

``closed_form=False`` keeps every region on the RKF45, as the built-in model: Gamma-,
Sigma_beta and Gamma+ are linear and would otherwise be propagated in closed form (Sigma_alpha
uses the memory Va, so it has none), which solves the smoothed equations more exactly than
the paper's integrator, and faster.
"""

import nonsmooth as ns
from nonsmooth.models.support import PARAMETERS

R = "(xi_s/omega_s**2)"  # h_beta = -(X - 1) - R V (eq. 7)
HA, HB = "(X - 1)", f"(1 - X - {R}*V)"  # h_alpha, h_beta
F = "-omega0**2*X - xi*V + F0*cos(omega*t)"  # f_- (eq. 11a)
Q = "(X - 1 + eta)/(2*eta)"  # q of eq. 13a

MODEL = ns.model_from_equations(
    "switch_eq", states=("X", "V"), parameters={p.name: p for p in PARAMETERS},
    memory={"Va": "V", "side": f"Piecewise((0, {HA} <= -eta), (1, True))"},
    modes={"Gamma_minus": ["V", F],
           "Sigma_alpha": ["V", f"{F} - xi_s*V - omega_s**2*(X - 1 + eta)/2 "
                                f"+ xi_s*Va*(1 - {Q})"],  # eq. 13a
           "Sigma_beta": ["V", f"{F} - omega_s**2*(X - 1 + eta)/2 - xi_s*V/2"],  # eq. 13b
           "Gamma_plus": ["V", f"{F} - omega_s**2*(X - 1) - xi_s*V"]},  # eq. 11b
    guards={  # each surface >= 0 inside its region (eq. 14); the branches: the region across
        "Gamma_minus": [(f"(1 - side)*(-eta - {HA}) + side*({HB} - eta)",
                         [(f"side == 0 and {HB} >= eta", "Gamma_minus", {"side": "1"}),
                          (f"side == 1 and {HA} <= -eta", "Gamma_minus", {"side": "0"}),
                          ("side == 0 or V >= 0", "Sigma_alpha", {"Va": "V"}),
                          (True, "Sigma_beta")])],
        "Sigma_alpha": [(f"{HA} + eta", "Gamma_minus", {"side": "0"}),
                        (f"eta - {HA}", "Gamma_plus"),
                        (f"{R}*V", "Sigma_beta")],
        "Sigma_beta": [(f"-{R}*V", "Sigma_alpha", {"Va": "V"}),
                       (f"{HB} + eta", "Gamma_plus"),
                       (f"eta - {HB}", "Gamma_minus", {"side": "1"})],
        "Gamma_plus": [(f"{HA} - eta", [(f"{HB} >= eta", "Gamma_minus", {"side": "1"}),
                                        (True, "Sigma_beta")]),
                       (f"-eta - {HB}", [("V < 0", "Sigma_beta"),
                                         (f"{HA} <= -eta", "Gamma_minus", {"side": "0"}),
                                         (True, "Sigma_alpha", {"Va": "V"})])]},
    initial=[(f"{HA} <= -eta or {HB} >= eta", "Gamma_minus"),
             (f"{HA} >= eta and {HB} <= -eta", "Gamma_plus"),
             (f"{HA} < eta and {HB} <= -{HA}", "Sigma_alpha")],
    method="smooth", closed_form=False, forcing_amplitude="F0", contact_modes=("Gamma_plus",),
    description="the paper's switch model (eq. 13) written as equations",
    presets={name: (dict(values), text) for name, (values, text) in
             ns.model("support").presets.items()})
