"""Benchmark: the Lyapunov spectrum of every built-in model against its plain trajectory, in the
same run (issue 20, item 5: <= 2x exact, <= 3x smooth, on the same kernel).

For each model and method, from the model's case of ``bench_models.py`` (the same parameters):

* plain: ``ns.simulate(params, periods=transient + periods, samples_per_period=1)`` (one stored
  state per period, as a spectrum run keeps; ``support`` runs it on its specialised kernel,
  ``bench_lyapunov.py`` also times its generic one);
* spectrum: ``ns.lyapunov(params, periods=, transient=, method=)`` (every tangent vector of the
  state, re-orthonormalised every period);
* their ratio.

Times are wall seconds, best of ``--rounds`` after a warm-up call (compilation / cache load).
The last stdout line is one number, the total seconds of the spectra (for
``../shared/tools/side-by-side``).

Usage::

    python benchmarks/bench_lyapunov_models.py [--periods 2000] [--transient 100] [--rounds 3]
                                               [--models two_sided,impact_2dof]
"""

from __future__ import annotations

import argparse

import numpy as np

import nonsmooth as ns
from nonsmooth.models import BUILTIN

from bench_evidence import best
from bench_models import CASES


def warm_best(f, rounds):
    """Best of ``rounds`` timed calls after a warm-up call (compile / load)."""
    f()
    return best(f, rounds)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--periods", type=int, default=2000, help="spectrum periods")
    ap.add_argument("--transient", type=int, default=100, help="transient periods")
    ap.add_argument("--rounds", type=int, default=3, help="timed runs (best kept)")
    ap.add_argument("--models", default=",".join(BUILTIN), help="comma-separated model names")
    ap.add_argument("--methods", default="smooth,exact", help="comma-separated methods (e.g. "
                    "support's smooth_closed_form)")
    args = ap.parse_args(argv)
    names = args.models.split(",")
    total = 0.0
    seen = set()
    print(f"{'model':15s} {'method':18s} {'plain':>9s} {'spectrum':>9s} {'ratio':>6s}  exponents")
    for name, make, _note in CASES:
        if name not in names or name in seen:
            continue  # one case per model (the first)
        seen.add(name)
        model = ns.model(name)
        p = make(model)
        for method in args.methods.split(","):
            if method not in model.methods:
                continue
            plain = warm_best(lambda: ns.simulate(p, periods=args.transient + args.periods,
                                             samples_per_period=1, method=method), args.rounds)
            out = {}

            def spectrum():
                out["ds"] = ns.lyapunov(p, periods=args.periods, transient=args.transient,
                                        method=method)

            spec = warm_best(spectrum, args.rounds)
            total += spec
            ex = np.array2string(out["ds"]["exponent"].values, precision=4)
            print(f"{name:15s} {method:18s} {plain:8.4f}s {spec:8.4f}s {spec / plain:6.2f}  {ex}")
    print(f"{total:.4f}")


if __name__ == "__main__":
    main()
