"""Benchmark: the tangent part of the λ1 evidence of the exact table3 bifurcation diagram, alone.

``ns.bifurcation_diagram(ns.preset("table3"), "omega", np.linspace(0.8, 1.0, 200),
method="exact")`` gives its non-periodic points (117-118 on the reference machine, nearly
all chaotic) a Benettin estimate of λ1 (``analysis.stability.lambda1_points``: 50 periods of
alignment and 200 recorded, the generic tangent kernel on the support model). This script
captures that call's arguments from one diagram and times the call again on one thread: what
the evidence costs beyond the diagram itself (``bench_evidence.py`` times the whole analysis
with and without it).

Usage::

    python benchmarks/bench_evidence_tangent.py [--repeat 7]

The last line is the best CPU time in seconds (for ``../shared/tools/side-by-side``).
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

import nonsmooth as ns
from nonsmooth.analysis import stability


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()
    captured = {}
    original = stability.lambda1_points

    def capture(P, solver, states, periods, **kw):
        captured.update(P=np.array(P), solver=solver, states=np.array(states), periods=periods)
        return original(P, solver, states, periods, **kw)

    stability.lambda1_points = capture
    try:
        ns.bifurcation_diagram(ns.preset("table3"), "omega", np.linspace(0.8, 1.0, 200),
                               method="exact")
    finally:
        stability.lambda1_points = original
    P, solver, states = captured["P"], captured["solver"], captured["states"]
    best = float("inf")
    for _ in range(args.repeat):
        t0 = time.process_time()
        original(P, solver, states, captured["periods"], workers=1)
        best = min(best, time.process_time() - t0)
    print(f"Benettin of {P.shape[0]} points x {captured['periods']} periods (+ alignment), "
          f"one thread: {best:.4f} s CPU (best of {args.repeat})", file=sys.stderr)
    print(f"{best:.4f}")


if __name__ == "__main__":
    main()
