"""Benchmark: a two-parameter map, table3, omega in [0.8, 1.0] x F0 in [0.15, 0.45], 400 x 400
points, transient 500 and record 100 periods, exact method, lambda1 at every point; on the
embedded engine (numba threads on all cores) and on a Dask LocalCluster of 2 and of 1 worker
processes (one thread each): the Dask/embedded ratio, the strong-scaling efficiency from 1 to 2
workers, the speed-up over scipy solve_ivp (extrapolated from a short run), the peak memory,
and a projection for a 2000 x 2000 map on 10 such machines.

Run: python benchmarks/bench_map.py [--n 400] [--engines embedded,local:2,local:1]
     python benchmarks/bench_map.py --memory 4000   (peak RSS of a 4000 x 4000 map with a
                                                     short transient: memory does not grow
                                                     with the periods integrated)
The last line printed is the embedded wall time in seconds.
"""

import argparse
import os
import resource
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))

from nonsmooth import preset  # noqa: E402
from nonsmooth.analysis.parameter_map import parameter_map  # noqa: E402


def peak_rss_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def run(engine, a, params):
    t0 = time.perf_counter()
    ds = parameter_map(params, x=("omega", 0.8, 1.0, a.n), y=("F0", 0.15, 0.45, a.n),
                       transient=a.transient, record=a.record, method=a.method,
                       engine=None if engine == "embedded" else engine,
                       lyapunov=not a.no_lyapunov)
    return time.perf_counter() - t0, ds


def memory(a):
    """One N x N map (transient a.transient, record a.record) in this process; prints the
    peak RSS and the size of the output arrays."""
    params = preset("table3")
    base = peak_rss_mib()
    t0 = time.perf_counter()
    ds = parameter_map(params, x=("omega", 0.8, 1.0, a.memory), y=("F0", 0.15, 0.45, a.memory),
                       transient=a.transient, record=a.record, method=a.method,
                       lyapunov=False)
    dt = time.perf_counter() - t0
    out_mib = sum(v.nbytes for v in ds.data_vars.values()) / 2**20
    print(f"memory: {a.memory} x {a.memory} map ({a.memory**2:,} points), transient "
          f"{a.transient}, record {a.record}, no lambda1: {dt:.1f} s; output arrays "
          f"{out_mib:.0f} MiB; peak RSS {peak_rss_mib():.0f} MiB (before the map {base:.0f} MiB)")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=400)
    ap.add_argument("--transient", type=int, default=500)
    ap.add_argument("--record", type=int, default=100)
    ap.add_argument("--method", default="exact")
    ap.add_argument("--engines", default="embedded,local:2,local:1")
    ap.add_argument("--no-lyapunov", action="store_true")
    ap.add_argument("--memory", type=int, default=0,
                    help="only the peak-memory run of an N x N map (short transient)")
    a = ap.parse_args()
    if a.memory:
        memory(a)
        return
    params = preset("table3")
    parameter_map(params, x=("omega", 0.8, 1.0, 2), y=("F0", 0.15, 0.45, 2), transient=2,
                  record=2, method=a.method)  # warm-up: compilation / cache load
    times, results = {}, {}
    for engine in a.engines.split(","):
        times[engine], results[engine] = run(engine, a, params)
        print(f"{engine}: {times[engine]:.2f} s", flush=True)
    emb = results.get("embedded")
    n_pts = a.n * a.n
    nominal = n_pts * (a.transient + a.record)
    print(f"map table3 omega [0.8, 1.0] x F0 [0.15, 0.45], {a.n} x {a.n} points x "
          f"({a.transient} + {a.record}) periods, method={a.method}, "
          f"lambda1={not a.no_lyapunov}, cpus={os.cpu_count()}")
    if emb is not None:
        used = int(emb.transient_used.sum()) + n_pts * a.record
        print(f"embedded: {times['embedded']:.2f} s, {nominal / times['embedded']:,.0f} nominal "
              f"trajectory-periods/s ({used / nominal:.0%} integrated: settled transients end "
              f"early), peak RSS of this process {peak_rss_mib():.0f} MiB")
        for engine, ds in results.items():
            if engine != "embedded":
                same = all(np.array_equal(ds[v].values, emb[v].values, equal_nan=True)
                           for v in emb.data_vars)
                print(f"{engine}: {times[engine]:.2f} s = {times[engine] / times['embedded']:.3f}"
                      f" x embedded; bit-identical to embedded: {same}")
    if "local:1" in times and "local:2" in times:
        eff = times["local:1"] / (2 * times["local:2"])
        print(f"strong scaling 1 -> 2 Dask workers: speed-up {times['local:1'] / times['local:2']:.2f},"
              f" efficiency {eff:.0%}")
        per_machine = times["local:2"]
        print(f"projection: 2000 x 2000 = 25 x this map; on 10 machines like this one "
              f"(2 workers each) about {25 * per_machine / 10:.0f} s at this efficiency")
    from common import scipy_rate
    rate, _ = scipy_rate(params.replace(omega=0.9, F0=0.3), 20, repeats=2)
    scipy_s = nominal / rate
    if "embedded" in times:
        print(f"scipy solve_ivp (RK45 on the smoothed model, one point after another, "
              f"extrapolated from 20 periods): {scipy_s:,.0f} s = "
              f"{scipy_s / times['embedded']:,.0f} x the embedded map")
        print(f"{times['embedded']:.4f}")


if __name__ == "__main__":
    main()
