"""Benchmark: issue 21's speed targets for the global-structure analyses, each on the paper's
model (exact method unless said), 2 cores.

* ``basin_entropy`` (S_b, S_bb and the uncertainty exponent) of a 1000 x 1000 basins Dataset
  (Fig. 7, omega = 1.10; the basins' own time is printed beside it): target <= 1 s;
* manifold branches of 10,000 points (Fig. 7's saddle, spacing 5e-4; the stable branches,
  grown by the search method, stop at 10,000 points; the unstable ones converge onto the
  attractors before): target <= 10 s a branch;
* ``attractor_continuation`` over 100 values of omega (1.0 ... 1.25) with 100 x 100 initial
  conditions each: target <= 60 s;
* a two-parameter fold curve of 200 points (Fig. 6a's fold in (omega, omega_s)): target <= 5 s.

Each is run once to compile / load, then timed (best of ``--repeat``).
Run:  python benchmarks/bench_global.py [--repeat 1] [--only entropy,manifold,attractors,fold]
The last line is the total timed seconds (for ``../shared/tools/side-by-side``).
"""

import argparse

import numpy as np

import nonsmooth as ns
from common import best_of


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--only", default="entropy,manifold,attractors,fold")
    a = ap.parse_args()
    only = set(a.only.split(","))
    total = 0.0
    fig7 = ns.preset("fig7")
    if "entropy" in only:
        ns.basin_entropy(ns.basins(fig7, grid=40, method="exact", lyapunov=False), 5)
        tb, bas = best_of(1, lambda: ns.basins(fig7, grid=1000, method="exact", lyapunov=False))
        dt, e = best_of(a.repeat, lambda: ns.basin_entropy(bas, 5))
        total += dt
        print(f"basin_entropy of a 1000 x 1000 basins Dataset: {dt:.3f} s (target <= 1 s); "
              f"S_b = {float(e.basin_entropy):.4f}, S_bb = {float(e.boundary_basin_entropy):.4f}, "
              f"alpha = {float(e.uncertainty_exponent):.3f} +- "
              f"{float(e.uncertainty_exponent_stderr):.3f} (the basins themselves: {tb:.1f} s)")
    if "manifold" in only:
        orbit = ns.periodic_orbit(fig7, x0=-1.5, v0=0.25)
        kw = dict(x=(-3, 3), v=(-3, 3), max_points=10000, spacing=5e-4)
        ns.manifolds(fig7, orbit, **{**kw, "max_points": 100})
        tu, mu = best_of(a.repeat, lambda: ns.manifolds(fig7, orbit, stable=False, **kw))
        dt, m = best_of(a.repeat, lambda: ns.manifolds(fig7, orbit, **kw))
        total += dt
        n = [int((m.branch.values == b).sum()) for b in range(4)]
        print(f"manifolds, Fig. 7's saddle, spacing 5e-4: unstable branches of {n[0]} and "
              f"{n[1]} points {tu:.2f} s together; stable branches of {n[2]} and {n[3]} points "
              f"{(dt - tu) / 2:.2f} s each (target <= 10 s a branch of 10,000 points); "
              f"all four {dt:.2f} s, {m.attrs['periods_integrated']} periods")
    if "attractors" in only:
        vals = np.linspace(1.0, 1.25, 100)
        ns.attractor_continuation(fig7, "omega", vals[:2], grid=10, method="exact")
        dt, att = best_of(a.repeat, lambda: ns.attractor_continuation(
            fig7, "omega", vals, grid=100, method="exact"))
        total += dt
        print(f"attractor_continuation, 100 values x 100^2 initial conditions: {dt:.1f} s "
              f"(target <= 60 s); {att.sizes['attractor']} attractors, at most "
              f"{int(att.n_attractors.max())} at once")
    if "fold" in only:
        p = ns.preset("fig6a").replace(omega=0.5)
        br = ns.continuation(p, "omega", bounds=(0.5, 1.6))
        kw = dict(start=br, bounds=(0.3, 2.0), bounds2=(0.5, 50.0), max_points=200,
                  step=0.005, max_step=0.005)
        ns.fold_curve(p, "omega", "omega_s", **{**kw, "max_points": 5})
        dt, fc = best_of(a.repeat, lambda: ns.fold_curve(p, "omega", "omega_s", **kw))
        total += dt
        print(f"fold_curve (omega, omega_s), {fc.sizes['point']} points: {dt:.2f} s (target "
              f"<= 5 s); status: {fc.attrs['status']}")
    print(f"{total:.4f}")


if __name__ == "__main__":
    main()
