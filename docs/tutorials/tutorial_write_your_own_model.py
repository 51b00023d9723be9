"""
Write your own model
====================

This tutorial builds a non-smooth model step by step, runs every analysis on it, and then
explains the contract that every model implements (modes, guards, transitions, memory,
Jacobians), with the errors a malformed model gives.

The system: a harmonically forced oscillator that hits a **rigid stop** at X = 1 with
Newton's restitution law V+ = -r V- (an impact oscillator),

.. math::

    X'' + \\xi X' + \\omega_0^2 X = F_0 \\cos \\omega t \\quad (X < 1), \\qquad
    V \\to -r V \\ \\text{at} \\ X = 1 .
"""

# %%
# Step 1: the model as equations
# ------------------------------
# :func:`nonsmooth.model_from_equations` takes the states, the parameters (default, range,
# units), every mode's vector field and the switching surfaces with their transitions and
# resets. It derives the rest: the Jacobians (SymPy), the guards' affine rows, the closed form
# of linear modes, the transition and initial-mode functions, and compiles them with numba
# (cached on disk under a digest of the equations).
import numpy as np

import nonsmooth as ns

impact = ns.model_from_equations(
    "tutorial_impact",
    states=("X", "V"),
    parameters={
        "omega0": dict(default=1.0, low=0.0, low_open=True, long_name="natural frequency"),
        "xi": dict(default=0.05, low=0.0, long_name="damping"),
        "F0": 3.0,
        "omega": dict(default=1.5, low=0.0, low_open=True, units="rad/s"),
        "r": dict(default=0.8, low=0.0, high=1.0, long_name="restitution coefficient"),
    },
    # one mode: free flight; d(state)/dt as expressions of states, parameters and t
    modes={"free": ["V", "-omega0**2*X - xi*V + F0*cos(omega*t)"]},
    # a guard is a surface g >= 0 inside the mode; crossing it applies the reset
    guards={"free": [ns.Guard("1 - X", "free", reset={"V": "-r*V"})]},
    method="exact",
)
print(impact.name, impact.param_names, impact.mode_names, list(impact.methods))

# %%
# Step 2: parameters are validated
# --------------------------------
# ``params`` checks every value against its range and names the field in the error.
p = impact.params(r=0.7)
print(p)
try:
    impact.params(r=1.5)
except ns.ParameterError as err:
    print("refused:", err)

# %%
# Step 3: a time response
# -----------------------
# The free flight is linear with harmonic forcing: the exact method propagates it in closed
# form, and the impacts are located to round-off.
ds = ns.simulate(p, periods=4, transient=100, method="exact")
fig = ns.plot.plot_time_response(ds)

# %%
# Step 4: every analysis runs on it
# ---------------------------------
# The Poincaré section with its period and λ1, a periodic orbit with its Floquet multipliers
# (Newton shooting through the impacts: the saltation matrices), a bifurcation diagram, the
# basins of attraction, a Lyapunov spectrum and a continuation branch.
sec = ns.poincare(p, record=200, transient=300, method="exact")
print("period", int(sec.period), "motion", sec.motion.item(), "lambda1", float(sec.lambda1))

orb = ns.periodic_orbit(p, transient=100, method="exact")
print("orbit:", orb.attrs["verdict"], "|mu| =", orb.multiplier_abs.values.round(4))

bif = ns.bifurcation_diagram(p, "F0", np.linspace(1.0, 4.0, 80), transient=200, record=40,
                             method="exact")
fig = ns.plot.plot_bifurcation(bif)

# %%
bas = ns.basins(p, x=(-3, 1), v=(-4, 4), grid=60, method="exact")
print("attractors:", bas.sizes["attractor"], "fractions:", bas.fraction.values.round(3))
fig = ns.plot.plot_basins(bas)

# %%
lya = ns.lyapunov(p, periods=500, transient=100, method="exact")
print("Lyapunov spectrum:", lya.exponent.values.round(4), lya.attrs["verdict"])
br = ns.continuation(p, "F0", bounds=(1.0, 4.0), method="exact", max_points=60)
print("branch:", br.sizes["point"], "points; special points:", br.special_type.values)
fig = ns.plot.plot_continuation(br)

# %%
# Step 5: the contract behind the equations
# -----------------------------------------
# A model is plain data plus a few small compiled functions per method; ``model_from_equations``
# writes them for you, and you may write them by hand (numba ``cfunc``\ s, plain Python
# syntax). Per method, with ``mode`` the current mode, ``t`` the time within the forcing period,
# ``(c, s) = (cos ωt, sin ωt)``, ``u`` the state, ``p`` the packed parameters and ``mem`` the
# discrete memory:
#
# * ``field(mode, t, c, s, u, p, mem, du)``: the mode's vector field into ``du``;
# * ``jacobian(mode, t, c, s, u, p, mem, J)``: its Jacobian in the state (for Lyapunov
#   exponents, Floquet multipliers and continuation; checked against finite differences when
#   the model loads);
# * ``guards(mode, p, mem, G)``: the mode's switching surfaces as affine rows
#   ``a X + b V + ... + c_c cos ωt + c_s sin ωt + c >= 0`` inside the mode (curved surfaces
#   have a ``curved`` function with their gradient);
# * ``transition(mode, k, t, c, s, u, p, mem)``: the new mode when guard ``k`` is crossed; it
#   may reset the state (an impact) and write the memory;
# * ``initial(c, s, u, p, mem)``: the mode of a starting state;
# * optionally ``linear(mode, p, out)``: declares a mode linear with harmonic forcing, so that
#   it is propagated in closed form.
#
# **Memory** (``n_memory`` slots) carries discrete state that the vector field needs, e.g. the
# paper's entry velocity Ẋa of eq. 13a, or on which side of a gap a free flight is.
#
# The example shipped with the package, a Duffing oscillator hitting a one-sided
# spring-damper support, writes both methods by hand:
#
# .. literalinclude:: ../../examples/one_sided_duffing.py
#    :language: python
#    :lines: 60-160
#
# It loads like any user model, from a file and the name of its ``Model``:
from pathlib import Path

# the repository's examples/ folder (the gallery runs in its own folder, below it)
example = next(d / "examples" / "one_sided_duffing.py" for d in (Path.cwd(), *Path.cwd().parents)
               if (d / "examples" / "one_sided_duffing.py").is_file())
duffing = ns.model(f"{example}:MODEL")      # compiled and sample-checked here
q = duffing.params(k_s=50.0)
sec = ns.poincare(q, record=100, transient=200, method="exact")
print(duffing.name, "period", int(sec.period))
fig = ns.plot.plot_poincare(sec)

# %%
# Step 6: what a malformed model says
# -----------------------------------
# Every mistake is one line naming what is wrong, when the model is built or loaded, before
# anything computes with it.
bad_models = {
    "an unknown name": dict(modes={"free": ["V", "-omega0**2*X - zeta*V"]}),
    "a wrong number of equations": dict(modes={"free": ["V"]}),
    "a guard to an unknown mode": dict(
        modes={"free": ["V", "-omega0**2*X"]},
        guards={"free": [ns.Guard("1 - X", "stuck", reset={"V": "-r*V"})]}),
}
for what, kw in bad_models.items():
    kw.setdefault("guards", {})
    try:
        ns.model_from_equations("bad", states=("X", "V"),
                                parameters={"omega0": 1.0, "r": 0.8, "omega": 1.0},
                                method="exact", **kw)
    except ns.ParameterError as err:
        print(f"{what}: {err}")

# %%
# A model written by hand is checked the same way when it is first compiled: here the
# Jacobian of a hand-written impact oscillator has a wrong sign, and the sample check (the
# Jacobian against finite differences of the field, in every mode) names the entry.
from nonsmooth.models import Method, Model, Param, param_index

PARAMS = (Param("omega", 1.2, low=0.0, low_open=True), Param("F0", 0.5))
F = param_index(PARAMS)["F0"]


def field(mode, t, c, s, u, p, mem, du):
    du[0] = u[1]
    du[1] = -u[0] - 0.1 * u[1] + p[F] * c
    return 0


def jacobian(mode, t, c, s, u, p, mem, J):
    J[0, 0] = 0.0
    J[0, 1] = 1.0
    J[1, 0] = +1.0          # wrong: d(dV/dt)/dX = -1
    J[1, 1] = -0.1
    return 0


def guards(mode, p, mem, G):
    G[0, 0], G[0, 1], G[0, 2], G[0, 3], G[0, 4] = -1.0, 0.0, 1.0, 0.0, 0.0   # 1 - X >= 0
    return 1


def transition(mode, k, t, c, s, u, p, mem):
    u[1] = -0.8 * u[1]      # the impact: V -> -r V
    return 0


def initial(c, s, u, p, mem):
    return 0


bad = Model(name="bad_jacobian", description="an impact oscillator with a wrong Jacobian",
            parameters=PARAMS, state_names=("X", "V"), mode_names=("free",),
            methods={"exact": Method(field, jacobian, guards, transition, initial, modes=(0,))})
try:
    ns.simulate(bad.params(), periods=2, method="exact")
except ns.ParameterError as err:
    print("refused:", err)

# %%
# The same model from the command line: save the ``model_from_equations`` call in a file that
# assigns it to ``MODEL`` and run, for example,
# ``nonsmooth poincare --model impact_eq.py:MODEL --method exact --record 500 --plot p.png``.
