"""``bouncing_ball``: a ball bouncing on a table that vibrates harmonically, y = A sin(omega t)
(Holmes 1982; Luck & Mehta 1993), written as equations (:mod:`.equations`).

State: the ball's height above the table Z = x - y and its rate V = Z'. In flight
Z'' = -g + A omega^2 sin(omega t). Parameters: gravity g, amplitude A, frequency omega,
restitution r; the dimensionless acceleration is Gamma = A omega^2 / g.

``method="exact"``: Newton's impact law at Z = 0, V -> -r V (modes ``flight`` and ``stuck``).
An impact slower than V_STICK (g / omega) while the table presses the ball (its acceleration
above -g) ends a chattering sequence: the ball rides on the table (mode ``stuck``, Z = V = 0)
until the table's downward acceleration exceeds g, when it takes off again, so complete
chattering ends in finite time, never Zeno. Free flight (no stiffness) and riding on the
table are linear modes propagated in closed form: free flight by the oscillator's formulas
with k = c = 0 (a parabola plus the table's harmonic, ``integrate.pwlinear``), riding as a
drift at rate 0 (Z' = V = 0: the same formulas without force).

``method="smooth"``: the table is a stiff linear spring-damper, mode ``contact`` while Z < 0,
force -k_c Z - c V with c = 2 zeta sqrt(k_c) and zeta = -ln r / sqrt(pi^2 + ln^2 r), so that
one isolated contact restitutes r (as the ``impact`` model's smooth method).

Closed forms (g = 1, T = 2 pi / omega = 1; tests/test_models_bouncing_ball.py checks them): the
period-one orbit (one impact per period, the ball leaving with absolute velocity g T / 2) exists
for Gamma >= pi (1 - r)/(1 + r), born in a fold, with Gamma cos(phi) = pi (1 - r)/(1 + r) at the
impact phase phi; its Floquet multipliers have product r^2 and sum 1 + r^2 - (1 + r)^2 Gamma
sin(phi), so it doubles its period at Gamma^2 = (pi (1-r)/(1+r))^2 + (2 (1+r^2)/(1+r)^2)^2.
"""

from __future__ import annotations

import math

from .base import Param, _PARAM_NAMES
from .equations import Guard, model_from_equations

#: impacts slower than V_STICK g / omega while the table presses end in sticking (exact method)
V_STICK = 1e-7

FLIGHT = "-g + A*omega**2*sin(omega*t)"
PRESSING = "-g + A*omega**2*sin(omega*t) <= 0"
ZETA = "(-log(Max(r, 1e-300))/sqrt(pi**2 + log(Max(r, 1e-300))**2))"

PARAMETERS = (
    Param("g", 1.0, low=0.0, low_open=True, units="m/s^2", long_name="gravity", symbol="$g$"),
    Param("A", 1.3 / (4 * math.pi**2), low=0.0, units="m", long_name="table amplitude",
          symbol="$A$"),
    Param("omega", 2 * math.pi, low=0.0, low_open=True, units="rad/s",
          long_name="table frequency", symbol=r"$\omega$"),
    Param("r", 0.5, low=0.0, high=1.0, units="1", long_name="coefficient of restitution",
          symbol="$r$"),
    Param("k_c", 1e5, low=0.0, low_open=True, units="1/s^2",
          long_name="contact stiffness of the smooth method (per unit mass)", symbol="$k_c$"),
)

MODEL = model_from_equations(
    "bouncing_ball", states=("Z", "V"), parameters={p.name: p for p in PARAMETERS},
    compile_now=False,  # (compiled at its first use: importing the model compiles nothing)
    methods={
        "exact": dict(
            modes={"flight": ["V", FLIGHT], "stuck": ["0", "0"]},
            guards={"flight": [Guard("Z", [(f"-V < {V_STICK}*g/omega and {PRESSING}", "stuck",
                                            {"Z": "0", "V": "0"}),
                                           (True, "flight", {"Z": "0", "V": "-r*V"})])],
                    "stuck": [Guard("g - A*omega**2*sin(omega*t)", "flight")]},
            # (a faster start into the table is an impact: flight, whose guard applies it)
            initial=[(f"Z <= 0 and V <= 0 and -V < {V_STICK}*g/omega and {PRESSING}",
                      "stuck")],
            admissible="Z >= 0",
            description="Newton's impact law, chatter ending in sticking; flight in closed "
                        "form"),
        "smooth": dict(
            modes={"flight": ["V", FLIGHT],
                   "contact": ["V", f"{FLIGHT} - k_c*Z - 2*{ZETA}*sqrt(k_c)*V"]},
            guards={"flight": [("Z", "contact")], "contact": [("-Z", "flight")]},
            initial=[("Z < 0", "contact")],
            description="compliant table (spring-damper restituting r); flight and contact in "
                        "closed form"),
    },
    description="a ball bouncing on a harmonically vibrating table (relative height Z)",
    forcing_amplitude="A",
    state_units=("m", "m/s"),
    state_long_names=("height above the table Z = x - y", "relative velocity dZ/dt"),
    contact_modes=("stuck", "contact"),
    axis_labels=(r"$Z = x - y$", r"$V = \dot Z$"),
    contact_name="resting on (exact) or pressed into (smooth) the table",
    lines=lambda params, method: [(0.0, "table (Z = 0)")],
    references=("P. J. Holmes, J. Sound Vib. 84 (1982) 173-189",
                "J. M. Luck and A. Mehta, Phys. Rev. E 48 (1993) 3988-3997"),
    presets={
        "period_one": ({"A": 1.3 / (4 * math.pi**2)},
                       "Gamma = 1.3: the stable period-one orbit, one impact per period (from "
                       "x0 = 0.07, v0 = -0.6; from rest the ball chatters and rides on the table "
                       "once per period)"),
        "doubled": ({"A": 1.6 / (4 * math.pi**2)},
                    "Gamma = 1.6: the period-two orbit past the period doubling at Gamma = 1.527 "
                    "(from x0 = 0.07, v0 = -0.6)"),
        "chaotic": ({"A": 3.0 / (4 * math.pi**2), "r": 0.85},
                    "Gamma = 3.0, r = 0.85: chaotic bouncing, lambda1 about 0.5 per period (at "
                    "r = 0.5 the ball ends up chattering and riding on the table)"),
    },
)
_PARAM_NAMES["bouncing_ball"] = MODEL.param_names
