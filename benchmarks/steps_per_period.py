"""Where a model's time per period goes: its rate (periods/s), its steps per forcing period and
the cost of one step, on the generic kernel, one trajectory from rest, for the cases of
``bench_models.py`` (a second case of a model is named ``name#2``).

Steps per period: the smallest ``max_steps`` (``Solver.opts()[OPT_MAX_STEPS]``, the steps a
call allows per period on average) with which 400 periods finish, found by bisection; it counts
every step the kernel takes, rejected and event steps included. ``--rtol`` replaces the
method's tolerance (e.g. to see what the exact method's rtol 1e-12 costs a nonlinear mode).

Usage::

    python benchmarks/steps_per_period.py [--models jeffcott_rotor,impact_2dof]
                                          [--methods exact,smooth] [--rtol 1e-12,1e-10]
"""

from __future__ import annotations

import argparse
import time

from bench_models import CASES

from nonsmooth import kernels
from nonsmooth.integrate.contract import OPT_ATOL, OPT_MAX_STEPS, OPT_RTOL
from nonsmooth.models import model

#: ``bench_models``' models on the generic kernel (``support`` runs its own kernels)
GENERIC = tuple(dict.fromkeys(name for name, _make, _note in CASES if name != "support"))


def measure(name: str, make, method: str, rtol: float | None) -> tuple[float, int]:
    m = model(name)
    solver = kernels.Solver(model=m, method=method)
    p = make(m).pack()
    opts = solver.opts()
    if rtol is not None:
        opts[OPT_RTOL], opts[OPT_ATOL] = rtol, rtol * 1e-2

    def go(periods, max_steps=None):
        o = opts.copy()
        if max_steps:
            o[OPT_MAX_STEPS] = max_steps
        st = kernels.new_state(0.0, 0.0)
        t = time.process_time()
        status = kernels.run(solver.code, solver.fns, p, o, st, 1, 0, periods,
                             *kernels.output_buffers(periods))
        return periods / (time.process_time() - t), status
    go(5)
    rate = max(go(4000)[0] for _ in range(3))
    lo, hi = 1, 4000
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if go(400, mid)[1] == 0:
            hi = mid
        else:
            lo = mid
    return rate, hi


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--models", default=",".join(GENERIC))
    ap.add_argument("--methods", default="exact,smooth")
    ap.add_argument("--rtol", default="", help="comma-separated tolerances (default: the method's)")
    a = ap.parse_args(argv)
    rtols = [float(r) for r in a.rtol.split(",") if r] or [None]
    print(f"{'model':15s} {'method':6s} {'rtol':>7s} {'periods/s':>10s} {'steps/period':>12s} "
          f"{'us/step':>8s}")
    seen: dict = {}
    for name, make, _note in CASES:
        if name not in a.models.split(","):
            continue
        seen[name] = seen.get(name, 0) + 1  # a model's second case of bench_models: name#2
        label = name if seen[name] == 1 else f"{name}#{seen[name]}"
        for method in a.methods.split(","):
            for rtol in rtols:
                rate, steps = measure(name, make, method, rtol)
                print(f"{label:15s} {method:6s} {rtol or 'method':>7} {rate:10.4g} {steps:12d} "
                      f"{1e6 / rate / steps:8.3f}", flush=True)


if __name__ == "__main__":
    main()
