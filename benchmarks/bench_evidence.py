"""Benchmark: what the lambda1 evidence costs (issue 20, item 4): each analysis with its
defaults (lambda1 on) against the same analysis with ``lyapunov=False``, in the same run.

* ``bifurcation_diagram``, table 3, omega in [0.8, 1.0], 200 values, both sweeps, smooth and
  exact: periodic points get ln|mu_1| / (p T) from one tangent pass over their p periods,
  the others Benettin over ``record`` periods;
* ``poincare``, fig4 (chaotic), record 60,000, smooth and exact: Benettin over the record.

Usage::

    python benchmarks/bench_evidence.py [--repeat 2] [--cases poincare] [--methods smooth]

Prints a table (seconds with and without lambda1, their ratio) and, last, the total seconds
with lambda1 (for ``../shared/tools/side-by-side``). ``--cases`` keeps the cases whose name
contains one of the given words (comma-separated); ``--methods`` the support model's methods
measured (default ``smooth,exact``; ``smooth_closed_form`` is the switch model solved
exactly).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import nonsmooth as ns

CASES = {
    "bifurcation table3 x200": lambda method, lyap: ns.bifurcation_diagram(
        ns.preset("table3"), "omega", np.linspace(0.8, 1.0, 200), method=method,
        lyapunov=lyap),
    "poincare fig4 record 60000": lambda method, lyap: ns.poincare(
        ns.preset("fig4"), record=60000, transient=500, method=method, lyapunov=lyap),
}


def best(f, repeat):
    t = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        t = min(t, time.perf_counter() - t0)
    return t


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--cases", default="", help="comma-separated words: only the cases named so")
    ap.add_argument("--methods", default="smooth,exact", help="comma-separated methods")
    args = ap.parse_args()
    words = [w for w in args.cases.split(",") if w]
    total = 0.0
    print(f"{'analysis':28s} {'method':18s} {'lambda1 on':>11s} {'off':>8s} {'ratio':>6s}")
    for name, f in CASES.items():
        if words and not any(w in name for w in words):
            continue
        for method in args.methods.split(","):
            f(method, True)  # warm-up: compile / load
            on = best(lambda: f(method, True), args.repeat)
            off = best(lambda: f(method, False), args.repeat)
            total += on
            print(f"{name:28s} {method:18s} {on:10.2f}s {off:7.2f}s {on / off:6.2f}")
    print(f"{total:.3f}")


if __name__ == "__main__":
    main()
