"""Benchmark: a model written as equations (``ns.model_from_equations``) against the same model
written by hand, in the same run: forcing periods per second of one trajectory of
``--periods`` periods from X = 0.1, V = 0 on the generic kernel (``kernels.run``), CPU time,
best of ``--repeat`` after a warm-up. Target (issue 23): within 10 %.

Cases:

* the one-sided Duffing oscillator of ``examples/one_sided_duffing.py``, ``exact`` (RKF45 at
  rtol 1e-12 between located events; its memory slot is a third mode in the equations) and
  ``smooth`` (the regularised support force with ``logistic`` and ``softplus``, Jacobian
  derived);
* the impact oscillator, ``exact`` (closed form in free flight, derived from the equations),
  against the built-in ``impact`` model at an orbit with one impact per period.

Also prints the time to build each equations model again with a warm cache (its derivation read
back from the cache, without SymPy; the compiled functions load at their first use). Usage
(from the repository root)::

    python benchmarks/bench_equations.py [--periods 2000] [--repeat 3]

The last line is the total seconds of the timed equation-model runs (for
``../shared/tools/side-by-side``).
"""

from __future__ import annotations

import argparse
import time

import nonsmooth as ns
from bench_user_model import EXAMPLE, rate  # the same timing loop (this folder is on sys.path)

FREE = "-xi*V - X - beta*X**3 + F0*cos(omega*t)"
FORCE = "k_s*(X - gap) + c_s*V"
DUFFING_PARAMS = {"xi": 0.1, "beta": 0.5, "F0": 1.0, "omega": dict(default=1.2, low=0.0,
                                                                   low_open=True),
                  "gap": 1.0, "k_s": dict(default=20.0, low=0.0, low_open=True),
                  "c_s": dict(default=0.2, low=0.0), "eta": dict(default=1e-3, low=0.0,
                                                                 low_open=True)}


def duffing_exact():
    return ns.model_from_equations(
        "duffing_exact_eq", states=("X", "V"), parameters=DUFFING_PARAMS,
        modes={"free": ["V", FREE], "contact": ["V", f"{FREE} - ({FORCE})"],
               "above": ["V", FREE]},
        guards={"free": [("gap - X", [("V > 0", "contact"), (True, "above")])],
                "contact": [(FORCE, [("X > gap", "above"), (True, "free")])],
                "above": [(f"-({FORCE})", "contact"), ("X - gap", "free")]},
        initial=[(f"X > gap and {FORCE} > 0", "contact"), ("X > gap", "above")],
        method="exact", rtol=1e-12, atol=1e-14, contact_modes=("contact",))


def duffing_smooth():
    z = "(X - gap)/eta"
    y = f"({FORCE})/(k_s*eta)"
    force = f"logistic({z}) * k_s*eta*softplus({y})"
    return ns.model_from_equations(
        "duffing_smooth_eq", states=("X", "V"), parameters=DUFFING_PARAMS,
        modes={"free": ["V", f"{FREE} - {force}"], "contact": ["V", f"{FREE} - {force}"]},
        guards={"free": [("gap - X", "contact")], "contact": [("X - gap", "free")]},
        initial=[("X >= gap", "contact")], method="smooth", contact_modes=("contact",))


def impact_exact():
    return ns.model_from_equations(
        "impact_exact_eq", states=("X", "V"),
        parameters={"omega0": 1.0, "xi": 0.05, "F0": 3.0, "omega": 1.5,
                    "r": dict(default=0.8, low=0.0, high=1.0)},
        modes={"free": ["V", "-omega0**2*X - xi*V + F0*cos(omega*t)"]},
        guards={"free": [ns.Guard("1 - X", "free", reset={"V": "-r*V"})]}, method="exact")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--periods", type=int, default=2000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    hand_duffing = ns.model(EXAMPLE)
    impact = ns.model("impact")
    cases = []
    for label, build, method, hand in (
            ("one-sided Duffing", duffing_exact, "exact", hand_duffing.params()),
            ("one-sided Duffing", duffing_smooth, "smooth", hand_duffing.params()),
            ("impact (1 impact/period)", impact_exact, "exact",
             impact.params(omega0=1.0, xi=0.05, F0=3.0, omega=1.5, r=0.8))):
        build()  # first build: derive, generate, compile or load from the disk cache
        t0 = time.perf_counter()
        model = build()
        cases.append((label, method, model, hand, time.perf_counter() - t0))
    total = 0.0
    print(f"{'model':26s} {'method':7s} {'by hand':>10s} {'equations':>10s} {'ratio':>6s} "
          f"{'build':>7s}  (periods/s; build: seconds, warm cache)")
    for label, method, model, hand, build_s in cases:
        values = {k: v for k, v in hand.as_dict().items() if k in model.param_names}
        t_eq, code_eq = rate(model.params(**values), method, args.periods, args.repeat)
        t_hand, code_hand = rate(hand, method, args.periods, args.repeat)
        total += t_eq
        print(f"{label:26s} {method:7s} {args.periods / t_hand:10.4g} {args.periods / t_eq:10.4g}"
              f" {t_hand / t_eq:6.2f} {build_s:7.2f}  status {code_hand}/{code_eq}")
    print(f"{total:.4f}")


if __name__ == "__main__":
    main()
