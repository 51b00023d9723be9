"""Forcing periods per second of one trajectory of the smoothed model (RKF45 kernel) against
scipy solve_ivp RK45 on the same smoothed right-hand side, in the same run.

    python benchmarks/bench_rkf45.py [--periods 20000] [--scipy-periods 40]

Case: preset table3 with omega = 0.92 (chaotic, contacts every few periods), rtol 1e-8,
atol 1e-10 for both, from rest. Rates are CPU time of this process (best of 3), so that
other load on the machine distorts the ratio less; both solvers are single-threaded. The last
line printed is the CPU seconds of ``ns.simulate`` over the same periods (the kernel through
the library's driver).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from common import cpu_timer, machine_line, scipy_rate  # noqa: E402

import nonsmooth as ns  # noqa: E402
from nonsmooth.kernels import Solver, advance, new_state, output_buffers  # noqa: E402


def kernel_rate(params, periods, method="smooth", repeats=3):
    solver = Solver(method=method)
    p, opts = params.pack(), solver.opts()
    buf = output_buffers(1)
    advance(solver.code, p, opts, new_state(0, 0), 1, 5, 1, *buf)  # compile / warm up
    best = np.inf
    for _ in range(repeats):
        state = new_state(0.0, 0.0)
        t0 = cpu_timer()
        code = advance(solver.code, p, opts, state, 1, periods - 1, 1, *buf)
        best = min(best, cpu_timer() - t0)
        assert code == 0, code
    return periods / best


def api_seconds(params, periods, repeats=3):
    """CPU seconds of ``ns.simulate`` over a transient of ``periods`` periods: the kernel
    through the library's driver (time slices, progress hooks), best of ``repeats``."""
    ns.simulate(params, periods=1, transient=5, samples_per_period=1)  # warm up
    best = np.inf
    for _ in range(repeats):
        t0 = cpu_timer()
        ns.simulate(params, periods=1, transient=periods, samples_per_period=1)
        best = min(best, cpu_timer() - t0)
    return best


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--periods", type=int, default=20000)
    ap.add_argument("--scipy-periods", type=int, default=100)
    a = ap.parse_args()
    params = ns.preset("table3").replace(omega=0.92)
    ours = kernel_rate(params, a.periods)
    theirs, _ = scipy_rate(params, a.scipy_periods)
    print(f"# {machine_line()}  case: table3, omega=0.92, rtol=1e-8, atol=1e-10")
    print(f"{'solver':40s} {'periods/s':>12s}")
    print(f"{'scipy solve_ivp RK45 (Python RHS)':40s} {theirs:12.1f}")
    print(f"{'nonsmooth RKF45 kernel (smooth)':40s} {ours:12.1f}")
    print(f"ratio smooth/scipy = {ours / theirs:.0f}x  (target >= 400x)")
    api = api_seconds(params, a.periods)
    print(f"{'ns.simulate (same kernel, library driver)':40s} {a.periods / api:12.1f}")
    print(f"{api:.4f}")  # last line: seconds of the library run (../shared/tools/side-by-side)


if __name__ == "__main__":
    main()
