"""Benchmark: the full period-1 resonance curve of the Fig. 6a setting by continuation.

``continuation(preset("fig6a") at omega = 0.5, "omega", bounds=(0.5, 1.6))``, exact method:
every branch of period-1 orbits over omega in [0.5, 1.6] (the stable parts, and the unstable
part between the folds) with every special point located (grazing omega_a, folds omega_c and
omega_b, the grazing on the way back). Target (issue): <= 2 s on 2 cores once compiled.

Prints the located points, then, as the last line, the best of ``--rounds`` wall-clock seconds
(for ``../shared/tools/side-by-side``).

Usage::

    python benchmarks/bench_continuation.py [--rounds 3]
"""

import argparse
import time

import nonsmooth as ns
from nonsmooth.analysis.continuation import SPECIAL_NAMES, continuation


def run():
    return continuation(ns.preset("fig6a").replace(omega=0.5), "omega", bounds=(0.5, 1.6),
                        step=0.01, method="exact")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args(argv)
    run()  # compile / load the kernels
    best = float("inf")
    for _ in range(args.rounds):
        t0 = time.perf_counter()
        ds = run()
        best = min(best, time.perf_counter() - t0)
    print(f"# {ds.sizes['point']} points, status: {ds.attrs['status']}")
    for i in range(ds.sizes["special"]):
        mu = complex(float(ds.special_multiplier_real[i]), float(ds.special_multiplier_imag[i]))
        print(f"# {SPECIAL_NAMES[int(ds.special_type[i])]:>16s} omega = "
              f"{float(ds.special_omega[i]):.10f}  multiplier {mu:.9g}")
    print(f"# best of {args.rounds}: {best:.3f} s (target <= 2 s)")
    print(f"{best:.4f}")


if __name__ == "__main__":
    main()
