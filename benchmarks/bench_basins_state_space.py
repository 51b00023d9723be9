"""Benchmark: basins of four-state models on a grid of two components, with the certificates of
the early stop as balls in the whole state space against ``early_stop=False`` (every point
runs until its section repeats), in the same run. Labels must agree.

* ``impact_2dof`` smooth, far from the stop (delta = 5, k_c = 100: linear), grid in (X, Y);
* ``jeffcott_rotor`` smooth, preset ``partial_rub`` (period one, rubbing at the bottom of each
  turn), grid in (X, Y).

Usage::

    python benchmarks/bench_basins_state_space.py [--grid 64] [--repeat 1]

Prints per case: seconds with certificates and without, their ratio, the trajectory-periods
of each (grid points' periods, and the certification's), the certified lattice cells; last,
the total seconds with certificates (for ``../shared/tools/side-by-side``).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import nonsmooth as ns

CASES = {
    "impact_2dof smooth linear": lambda: ns.model("impact_2dof").params(delta=5.0, k_c=100.0),
    "jeffcott_rotor smooth partial_rub": lambda: ns.model("jeffcott_rotor").preset("partial_rub"),
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grid", type=int, default=64)
    ap.add_argument("--repeat", type=int, default=1)
    args = ap.parse_args()
    total = 0.0
    print(f"{'case':36s} {'certified':>10s} {'off':>8s} {'ratio':>6s} {'periods on':>11s} "
          f"{'(cert.)':>8s} {'periods off':>12s} {'cells':>6s}")
    for name, params in CASES.items():
        p = params()

        def run(early):
            return ns.basins(p, x=(-1, 1), v=(-1, 1), grid=args.grid, method="smooth",
                             axes=("X", "Y"), early_stop=early, lyapunov=False)
        run(True)  # warm-up: compile / load
        t = {}
        ds = {}
        for early in (True, False):
            t[early] = np.inf
            for _ in range(args.repeat):
                t0 = time.perf_counter()
                ds[early] = run(early)
                t[early] = min(t[early], time.perf_counter() - t0)
        assert (ds[True].label.values == ds[False].label.values).all(), name
        on, off = ds[True], ds[False]
        total += t[True]
        print(f"{name:36s} {t[True]:9.2f}s {t[False]:7.2f}s {t[False] / t[True]:6.2f} "
              f"{int(on.periods_used.sum()):11d} {on.attrs['certification_periods']:8d} "
              f"{int(off.periods_used.sum()):12d} "
              f"{on.attrs['certified_cells']:>3d}/{on.attrs['lattice_cells']}")
    print(f"{total:.3f}")


if __name__ == "__main__":
    main()
