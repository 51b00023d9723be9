"""Benchmark: forcing periods per second of the generic kernel on the built-in ``stick_slip``
(preset ``stribeck``: Stribeck friction, exact at rtol 1e-12) and on the user model of
``examples/one_sided_duffing.py``, exact and smooth: one trajectory of ``--periods`` periods
from X = 0.1, V = 0 through ``kernels.run``, CPU time, best of ``--repeat`` after a warm-up.

Usage (from the repository root)::

    python benchmarks/bench_user_model.py [--periods 2000] [--repeat 3]

The last line is the total seconds of the timed runs (for ``../shared/tools/side-by-side``).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import nonsmooth as ns
from nonsmooth import kernels
from nonsmooth.models.base import KERNEL_GENERIC

#: the README's example, found from this file (the benchmark runs from any folder)
EXAMPLE = f"{Path(__file__).resolve().parents[1] / 'examples' / 'one_sided_duffing.py'}:MODEL"
CASES = (("stick_slip", "stribeck"), (EXAMPLE, None))


def rate(params, method, periods, repeat):
    """(best CPU seconds of ``periods`` periods from X = 0.1, V = 0 on the generic kernel,
    status) for ``params`` and ``method``, after a warm-up call."""
    solver = kernels.Solver(model=params.model, method=method)
    p, opts, fns = params.pack(), solver.opts(), solver.fns

    def once(n):
        state = kernels.new_state(0.1, 0.0)
        t0 = time.process_time()
        code = kernels.run(KERNEL_GENERIC, fns, p, opts, state, 1, 0, n,
                           *kernels.output_buffers(n))
        return time.process_time() - t0, code

    once(2)  # load / compile
    best, code = min(once(periods) for _ in range(repeat))
    return best, code


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--periods", type=int, default=2000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    total = 0.0
    print(f"{'model':40s} {'method':7s} {'periods/s':>10s}  status")
    for spec, preset in CASES:
        m = ns.model(spec)
        for method in ("exact", "smooth"):
            params = m.preset(preset) if preset else m.params()
            t, code = rate(params, method, args.periods, args.repeat)
            total += t
            print(f"{m.name:40s} {method:7s} {args.periods / t:10.4g}  {code}")
    print(f"{total:.4f}")


if __name__ == "__main__":
    main()
