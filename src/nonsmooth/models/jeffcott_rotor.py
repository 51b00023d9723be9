"""``jeffcott_rotor``: a Jeffcott rotor with unbalance rubbing on a circular stator, written as
equations (:mod:`.equations`) with a **curved** switching surface, the circle
X^2 + Y^2 = delta^2 (Karpenko, Wiercigroch & Cartmell 2002; Chu & Zhang 1998 study this
class).

State (per unit rotor mass, the rotor spinning at omega): the horizontal displacement X and
velocity V (u[0], u[1]), the vertical displacement Y and velocity W. Out of contact

    X'' = e omega^2 cos(omega t) - omega_n^2 X - xi V
    Y'' = e omega^2 sin(omega t) - omega_n^2 Y - xi W - g

(unbalance e, natural frequency omega_n, damping xi = c/m, gravity g pulling the whirl's
centre down by g / omega_n^2). In contact, r = sqrt(X^2 + Y^2)
> delta, the stator pushes back with the normal force k_s (r - delta) and Coulomb friction
mu times it, opposite to the rotor's surface velocity (the rotor spins forward, faster than
it whirls):

    X'' += -k_s (1 - delta/r) (X - mu Y),    Y'' += -k_s (1 - delta/r) (mu X + Y).

``method="exact"``: two modes, ``free`` (g = delta^2 - X^2 - Y^2 >= 0) and ``rub``
(g = X^2 + Y^2 - delta^2 >= 0), switched at the located crossing of the circle; the contact
force is continuous there, its Jacobian is not (the saltation matrix is the identity, the
tangent dynamics change field). The free whirl is linear: in closed form (the series of
``integrate.linmodes``); the rub by DOP853 at rtol 1e-12 (``integrate.rk8``).

``method="smooth"``: one vector field, the contact force regularised over a band eta:
k_s (r - delta)_+ is replaced by k_s eta softplus((r - delta) / eta), which tends to the exact
force as eta -> 0 (the modes ``free`` and ``rub`` then only label the side of the circle).

Full annular rub (the rotor rolls round the stator in steady synchronous whirl) has the closed
form X + iY = A e^{i omega t}, |A| = R > delta, with
A (omega_n^2 - omega^2 + kappa + i (xi omega + kappa mu)) = e omega^2, kappa = k_s (1 - delta/R);
tests/test_model_jeffcott.py checks the model against it and against scipy with events.
"""

from __future__ import annotations

from .base import Param, _PARAM_NAMES
from .equations import model_from_equations

FREE_X = "e*omega**2*cos(omega*t) - omega_n**2*X - xi*V"
FREE_Y = "e*omega**2*sin(omega*t) - omega_n**2*Y - xi*W - g"
R = "sqrt(X**2 + Y**2)"
#: the normal force per unit displacement, k_s (1 - delta / r), exact and regularised
PRESS = f"k_s*(1 - delta/{R})"
#: (r^2 + 1e-100 under the root of the regularised law keeps it finite at the centre, where
#: the force itself is zero to far below round-off)
R_SAFE = "sqrt(X**2 + Y**2 + 1e-100)"
SMOOTH_PRESS = f"k_s*eta*softplus(({R_SAFE} - delta)/eta)/{R_SAFE}"

PARAMETERS = (
    Param("omega_n", 1.0, low=0.0, low_open=True, units="rad/s",
          long_name="natural frequency of the rotor sqrt(k/m)", symbol=r"$\omega_n$"),
    Param("xi", 0.1, low=0.0, units="1/s", long_name="damping c/m", symbol=r"$\xi$"),
    Param("e", 0.3, low=0.0, units="m", long_name="unbalance eccentricity", symbol="$e$"),
    Param("omega", 1.0, low=0.0, low_open=True, units="rad/s",
          long_name="spin speed (forcing frequency)", symbol=r"$\omega$"),
    Param("delta", 1.0, low=0.0, low_open=True, units="m", long_name="radial clearance",
          symbol=r"$\delta$"),
    Param("k_s", 10.0, low=0.0, units="1/s^2", long_name="stator stiffness k_s/m",
          symbol="$k_s$"),
    Param("mu", 0.1, low=0.0, units="1", long_name="friction coefficient of the rub",
          symbol=r"$\mu$"),
    Param("g", 0.0, units="m/s^2", long_name="gravity (a constant downward force per unit mass)",
          symbol="$g$"),
    Param("eta", 1e-3, low=0.0, low_open=True, units="m",
          long_name="band of the regularised contact force (smooth method)",
          symbol=r"$\eta$"),
)

MODEL = model_from_equations(
    "jeffcott_rotor", states=("X", "V", "Y", "W"), parameters={p.name: p for p in PARAMETERS},
    compile_now=False,  # (compiled at its first use: importing the model compiles nothing)
    methods={
        "exact": dict(
            modes={"free": ["V", FREE_X, "W", FREE_Y],
                   "rub": ["V", f"{FREE_X} - {PRESS}*(X - mu*Y)",
                           "W", f"{FREE_Y} - {PRESS}*(mu*X + Y)"]},
            guards={"free": [("delta**2 - X**2 - Y**2", "rub")],
                    "rub": [("X**2 + Y**2 - delta**2", "free")]},
            initial=[("X**2 + Y**2 > delta**2", "rub")],
            flow_is_homeomorphism=True,
            description="rub on the stator switched at the located crossing of the circle "
                        "r = delta (a curved guard); free whirl in closed form, rub DOP853 at "
                        "rtol 1e-12"),
        "smooth": dict(
            modes={m: ["V", f"{FREE_X} - {SMOOTH_PRESS}*(X - mu*Y)",
                       "W", f"{FREE_Y} - {SMOOTH_PRESS}*(mu*X + Y)"] for m in ("free", "rub")},
            guards={"free": [("delta**2 - X**2 - Y**2", "rub")],
                    "rub": [("X**2 + Y**2 - delta**2", "free")]},
            initial=[("X**2 + Y**2 > delta**2", "rub")],
            flow_is_homeomorphism=True,
            description="contact force regularised over the band eta (softplus), RKF45; the "
                        "modes only label the side of the circle (one field)"),
    },
    description="Jeffcott rotor with unbalance rubbing on a circular stator (curved guard)",
    forcing_amplitude="e",
    state_units=("m", "m/s", "m", "m/s"),
    state_long_names=("horizontal displacement X", "horizontal velocity dX/dt",
                      "vertical displacement Y", "vertical velocity dY/dt"),
    contact_modes=("rub",),
    axis_labels=("$X$", r"$\dot X$", "$Y$", r"$\dot Y$"),
    contact_name="the orbit reaches the stator (rub visited)",
    contact=lambda params, mask, max_X, min_X: bool(mask & 0b10),
    contact_level=lambda params: params.delta,
    lines=lambda params, method: [(params.delta, r"stator ($X = \delta$)"),
                                  (-params.delta, "")],
    references=("A. Karpenko, M. Wiercigroch and M. P. Cartmell, Chaos Solitons Fractals 13 "
                "(2002) 1231-1242",
                "F. Chu and Z. Zhang, J. Sound Vib. 210 (1998) 1-18"),
    presets={
        "intermittent": ({}, "at resonance: the whirl crosses the clearance circle, rubbing "
                             "part of each turn"),
        "annular_rub": ({"omega": 0.8, "e": 1.0, "mu": 0.05},
                        "full annular rub: stable synchronous whirl in permanent contact"),
        "dry_whip": ({"omega": 0.8, "e": 1.0, "mu": 0.2},
                     "friction drives backward whirl: the annular rub orbit is unstable and the "
                     "whirl grows without bound (the model has no rigid stator)"),
        "partial_rub": ({"e": 0.1, "g": 0.5},
                        "gravity pulls the whirl down: period one, rubbing at the bottom of "
                        "each turn"),
        "chaotic_rub": ({"e": 0.2, "g": 0.5, "omega": 1.2},
                        "transient chaos: chaotic rubbing (lambda1 about +0.05 per unit "
                        "time while it lasts) for hundreds to thousands of periods, then a "
                        "stable period-two rub orbit (|multipliers| 0.905, 0.388)"),
        "no_rub": ({"e": 0.05}, "small unbalance: whirl inside the clearance"),
    },
)
_PARAM_NAMES["jeffcott_rotor"] = MODEL.param_names
