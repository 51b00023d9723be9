"""``impact_2dof``: a two-degree-of-freedom impact oscillator, written as equations
(:mod:`.equations`). A primary mass m1 on a spring-damper to the ground, driven by
F0 cos(omega t), carries a secondary mass m2 on a second spring-damper; the primary mass hits a
rigid stop at X = delta (Aidanpaa & Gupta 1993; Luo 2004 study this class).

State (per unit primary mass): the primary displacement X and velocity V (u[0], u[1]), the
secondary displacement Y and velocity W. Between impacts

    X'' = F0 cos(omega t) - omega1^2 X - xi1 V - mu (omega2^2 (X - Y) + xi2 (V - W))
    Y'' = -omega2^2 (Y - X) - xi2 (W - V)

with mu = m2/m1, omega1^2 = k1/m1, xi1 = c1/m1, omega2^2 = k2/m2, xi2 = c2/m2.

``method="exact"``: Newton's impact law at X = delta, V -> -r V (Y and W do not jump). An
impact slower than V_STICK while the forces press the mass onto the stop ends a chattering
sequence: the mass rests on the stop (mode ``stuck``: X = delta, V = 0, the secondary mass
still moving) until the force on it pulls it away. Both modes are linear with four states:
propagated in closed form (the series of the augmented matrix exponential,
``integrate.linmodes``).

``method="smooth"``: the stop is a stiff spring-damper, mode ``contact`` while X > delta,
force -k_c (X - delta) - c V with c = 2 zeta sqrt(k_c), zeta = -ln r / sqrt(pi^2 + ln^2 r), so
that one isolated contact restitutes about r (as the ``impact`` model's smooth method).

Checked against scipy ``solve_ivp`` with events (tests/test_model_impact_2dof.py).
"""

from __future__ import annotations

from .base import Param, _PARAM_NAMES
from .equations import Guard, model_from_equations

#: impacts slower than this while the stop is pressed end in sticking (exact method)
V_STICK = 1e-9

SPRING = "mu*(omega2**2*(X - Y) + xi2*(V - W))"
PRIMARY = f"F0*cos(omega*t) - omega1**2*X - xi1*V - {SPRING}"
SECONDARY = "-omega2**2*(Y - X) - xi2*(W - V)"
#: the primary mass's acceleration at rest on the stop (X = delta, V = 0): > 0 presses it on
PRESS = "F0*cos(omega*t) - omega1**2*delta - mu*(omega2**2*(delta - Y) - xi2*W)"
ZETA = "(-log(Max(r, 1e-300))/sqrt(pi**2 + log(Max(r, 1e-300))**2))"

PARAMETERS = (
    Param("omega1", 1.0, low=0.0, low_open=True, units="rad/s",
          long_name="natural frequency of the primary mass sqrt(k1/m1)", symbol=r"$\omega_1$"),
    Param("xi1", 0.05, low=0.0, units="1/s", long_name="damping of the primary mass c1/m1",
          symbol=r"$\xi_1$"),
    Param("mu", 0.5, low=0.0, units="1", long_name="mass ratio m2/m1", symbol=r"$\mu$"),
    Param("omega2", 1.5, low=0.0, low_open=True, units="rad/s",
          long_name="natural frequency of the secondary mass sqrt(k2/m2)",
          symbol=r"$\omega_2$"),
    Param("xi2", 0.05, low=0.0, units="1/s", long_name="damping of the coupling c2/m2",
          symbol=r"$\xi_2$"),
    Param("F0", 1.0, units="m/s^2", long_name="forcing amplitude per unit primary mass",
          symbol="$F_0$"),
    Param("omega", 1.0, low=0.0, low_open=True, units="rad/s", long_name="forcing frequency",
          symbol=r"$\omega$"),
    Param("delta", 0.5, units="m", long_name="position of the stop", symbol=r"$\delta$"),
    Param("r", 0.8, low=0.0, high=1.0, units="1", long_name="coefficient of restitution",
          symbol="$r$"),
    Param("k_c", 1e4, low=0.0, low_open=True, units="1/s^2",
          long_name="contact stiffness of the smooth method (per unit primary mass)",
          symbol="$k_c$"),
)

MODEL = model_from_equations(
    "impact_2dof", states=("X", "V", "Y", "W"), parameters={p.name: p for p in PARAMETERS},
    compile_now=False,  # (compiled at its first use: importing the model compiles nothing)
    methods={
        "exact": dict(
            modes={"free": ["V", PRIMARY, "W", SECONDARY],
                   "stuck": ["0", "0", "W", SECONDARY]},
            guards={"free": [Guard("delta - X", [(f"V < {V_STICK} and {PRESS} >= 0", "stuck",
                                                  {"X": "delta", "V": "0"}),
                                                 (True, "free", {"V": "-r*V"})])],
                    "stuck": [Guard(PRESS, "free")]},
            initial=[(f"X >= delta and V >= 0 and {PRESS} >= 0", "stuck")],
            admissible="X <= delta",
            description="Newton's impact law at the stop, chatter ending in sticking; closed "
                        "form between impacts"),
        "smooth": dict(
            modes={"free": ["V", PRIMARY, "W", SECONDARY],
                   "contact": ["V", f"{PRIMARY} - k_c*(X - delta) - 2*{ZETA}*sqrt(k_c)*V",
                               "W", SECONDARY]},
            guards={"free": [("delta - X", "contact")], "contact": [("X - delta", "free")]},
            initial=[("X > delta", "contact")],
            flow_is_homeomorphism=True,
            description="compliant stop (spring-damper restituting about r); both modes in "
                        "closed form"),
    },
    description="two masses in series, the primary one hitting a rigid stop",
    forcing_amplitude="F0",
    state_units=("m", "m/s", "m", "m/s"),
    state_long_names=("primary displacement X", "primary velocity dX/dt",
                      "secondary displacement Y", "secondary velocity dY/dt"),
    contact_modes=("stuck", "contact"),
    axis_labels=("$X$", r"$\dot X$", "$Y$", r"$\dot Y$"),
    contact_name="the orbit reaches the stop (max X >= delta - 1e-9)",
    contact=lambda params, mask, max_X, min_X: bool(mask & 0b110)
    or max_X >= params.delta - 1e-9,
    contact_level=lambda params: params.delta,
    lines=lambda params, method: [(params.delta, r"stop ($X = \delta$)")],
    references=("J.-O. Aidanpaa and R. B. Gupta, J. Sound Vib. 165 (1993) 305-327",
                "G. W. Luo, Phys. Lett. A 323 (2004) 210-217"),
    presets={
        "period_one": ({}, "one impact per forcing period"),
    },
)
_PARAM_NAMES["impact_2dof"] = MODEL.param_names
