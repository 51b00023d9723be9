"""Benchmark: bifurcation diagram, table3, omega in [0.8, 1.0], 1000 values x (500 transient +
200 recorded) periods, both sweeps (up and down in parallel), smoothed model.

Run: python benchmarks/bench_bifurcation.py [--values 1000] [--workers N] [--no-settle]
The last line printed is the wall time in seconds.
Throughput is reported in nominal trajectory-periods (values x sweeps x (transient + record))
per second and in periods actually integrated (the settled transient ends early).
"""

import argparse
import os
import time

import numpy as np

from nonsmooth import preset
from nonsmooth.analysis.bifurcation import bifurcation_diagram

def lyapunov_option(fn, wanted: bool) -> dict:
    """``lyapunov=wanted`` where ``fn`` has that option (older commits do not)."""
    import inspect
    return {"lyapunov": wanted} if "lyapunov" in inspect.signature(fn).parameters else {}



def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--values", type=int, default=1000)
    ap.add_argument("--transient", type=int, default=500)
    ap.add_argument("--record", type=int, default=200)
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--sweep", default="both")
    ap.add_argument("--method", default="smooth")
    ap.add_argument("--no-settle", action="store_true")
    ap.add_argument("--lyapunov", action="store_true",
                    help="also lambda1 per point (off: the sweep alone, comparable with "
                         "commits before lambda1 existed)")
    ap.add_argument("--no-extend", action="store_true",
                    help="no extension of still-converging sections (isolates the sweep itself)")
    a = ap.parse_args()
    if a.no_extend:
        import nonsmooth.analysis.bifurcation as bif
        bif.MAX_ROUNDS = 0  # absent before the extension existed: then a no-op
    params = preset("table3")
    values = np.linspace(0.8, 1.0, a.values)
    # warm-up (compilation / cache load)
    kw = lyapunov_option(bifurcation_diagram, a.lyapunov)
    bifurcation_diagram(params, "omega", values[:2], sweep=a.sweep, transient=2, record=2,
                        method=a.method, workers=a.workers, **kw)
    load0 = os.getloadavg()
    c0 = time.process_time()
    t0 = time.perf_counter()
    ds = bifurcation_diagram(params, "omega", values, sweep=a.sweep, transient=a.transient,
                             record=a.record, method=a.method, workers=a.workers,
                             settle=not a.no_settle, **kw)
    dt = time.perf_counter() - t0
    cpu = time.process_time() - c0
    load1 = os.getloadavg()
    nsw = ds.sizes["sweep"]
    nominal = a.values * nsw * (a.transient + a.record)
    actual = int(ds.transient_used.sum()) + a.values * nsw * a.record
    print(f"bifurcation table3 omega [0.8, 1.0], {a.values} values x ({a.transient} + {a.record}) "
          f"periods, sweep={a.sweep}, method={a.method}, settle={not a.no_settle}, "
          f"workers={a.workers or 'all'}, lambda1={bool(kw.get('lyapunov', False))}")
    print(f"time {dt:.2f} s; nominal {nominal / dt:,.0f} trajectory-periods/s; "
          f"integrated {actual:,} periods ({actual / nominal:.0%} of nominal), {actual / dt:,.0f} periods/s")
    print(f"CPU time {cpu:.2f} s (all threads): {actual / cpu:,.0f} periods per CPU-second; "
          f"on {os.cpu_count()} idle cores expect about {cpu / min(nsw, os.cpu_count()):.1f} s wall")
    print(f"failed points: {ds.attrs['n_failed']}; loadavg before {load0[0]:.2f}, after {load1[0]:.2f}")
    print(f"{dt:.4f}")  # last line: seconds (for ../shared/tools/side-by-side)


if __name__ == "__main__":
    main()
