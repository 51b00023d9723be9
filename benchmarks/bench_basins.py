"""Benchmark: basins of attraction, fig7 setting (omega 1.10 by default), grid on [-3, 3]^2.

Targets (issue 4, 2-core machine): 1000 x 1000 in <= 20 s with method="exact", <= 120 s with
the smoothed model. Other jobs may load the CPU, so a 200 x 200 grid is timed too and the time
extrapolated linearly in the number of points (the work per point does not depend on the grid
spacing); the load average is printed before and after each run.

Run:  python benchmarks/bench_basins.py [--method smooth|exact|both] [--omega 1.10]
                                        [--grids 200 1000] [--workers N]
Throughput: trajectory-periods per second = (sum of periods_used + certification periods) / time.
The last line is the total timed seconds (for ``../shared/tools/side-by-side``), e.g.
``../shared/tools/side-by-side 8d0d1d5 benchmarks/bench_basins.py --method exact --grids 200``.
"""

import argparse
import os
import time

import numba

from nonsmooth import preset
from nonsmooth.analysis.basins import basins

def lyapunov_option(fn, wanted: bool) -> dict:
    """``lyapunov=wanted`` where ``fn`` has that option (older commits do not)."""
    import inspect
    return {"lyapunov": wanted} if "lyapunov" in inspect.signature(fn).parameters else {}



def load():
    a, b, _ = os.getloadavg()
    return f"load(1m,5m)={a:.2f},{b:.2f}"


def run(params, method, grid, workers, kw):
    l0 = load()
    t0 = time.perf_counter()
    ds = basins(params, grid=grid, method=method, workers=workers, **kw)
    dt = time.perf_counter() - t0
    work = ds.attrs["total_periods"] + ds.attrs["certification_periods"]
    fr = ", ".join(f"A{k}(p{int(ds.period[k])},c{int(ds.contact[k])})={float(ds.fraction[k]):.4f}"
                   for k in range(ds.sizes["attractor"]))
    print(f"{method:6s} {grid:5d}^2: {dt:8.2f} s  {work / dt:10.0f} trajectory-periods/s  "
          f"mean {ds.attrs['mean_periods_used']:.2f} periods/point  {l0} -> {load()}  "
          f"undecided {float((ds.label.values < 0).mean()):.4f}  {fr}", flush=True)
    return dt


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--method", default="both", choices=("smooth", "exact", "both"))
    ap.add_argument("--omega", type=float, default=1.10)
    ap.add_argument("--grids", type=int, nargs="+", default=[200, 1000])
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--lyapunov", action="store_true",
                    help="also lambda1 per attractor (off: comparable with commits before it)")
    a = ap.parse_args()
    kw = lyapunov_option(basins, a.lyapunov)
    params = preset("fig7").replace(omega=a.omega)
    methods = ("exact", "smooth") if a.method == "both" else (a.method,)
    targets = {"exact": 20.0, "smooth": 120.0}
    print(f"fig7, omega={a.omega}, [-3, 3]^2, cpus={os.cpu_count()}, "
          f"threads={a.workers or numba.config.NUMBA_NUM_THREADS}, {load()}")
    total = 0.0
    for m in methods:
        basins(params, grid=4, method=m, workers=a.workers, **kw)  # compilation / cache load
        times = {}
        for g in a.grids:
            times[g] = run(params, m, g, a.workers, kw)
            total += times[g]
        g0 = min(times)
        est = times[g0] * (1000 / g0) ** 2
        line = f"{m}: 1000^2 extrapolated from {g0}^2: {est:.1f} s"
        if 1000 in times:
            line += f"; measured {times[1000]:.1f} s"
        print(f"{line} (target {targets[m]:.0f} s)")
    print(f"timed total (s): {total:.3f}")


if __name__ == "__main__":
    main()
