"""Benchmark: stable and unstable manifolds of a saddle (``ns.manifolds``), and the first
homoclinic tangency (``ns.homoclinic_tangency``).

Cases: Fig. 7's saddle (support model, omega = 1.10, exact and smooth; window [-3, 3]^2,
default spacing) and the forced double well x'' + 0.05 x' - x + x^3 = F cos t at F = 0.04
(smooth; a strongly expanding saddle, multiplier ~ 457). Each manifold computation reports its
time, the forcing periods it integrated (``periods_integrated``: the unstable branches'
iterates and every classification of the stable search) and their rate; scipy's ``solve_ivp``
(RK45, rtol 1e-10, atol 1e-12, the same vector field, no events) integrates the double well for
``--scipy-periods`` periods in the same run, and the ratio of the two rates is printed (for the
support model the exact kernel's events have no scipy counterpart here; see bench_models).

Run:  python benchmarks/bench_manifolds.py [--repeat 2] [--scipy-periods 20] [--tangency]
The last line is the total timed seconds of the manifold computations (for
``../shared/tools/side-by-side``).
"""

import argparse
import math
import time

import numpy as np
from scipy.integrate import solve_ivp

import nonsmooth as ns
from common import best_of


def double_well():
    return ns.model_from_equations(
        "double_well", states=("X", "V"), parameters={"delta": 0.05, "F0": 0.04, "omega": 1.0},
        modes={"free": ["V", "-delta*V + X - X**3 + F0*cos(omega*t)"]}, method="smooth")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--scipy-periods", type=int, default=20)
    ap.add_argument("--tangency", action="store_true", help="also time homoclinic_tangency")
    a = ap.parse_args()
    total = 0.0
    fig7 = ns.preset("fig7")
    for method in ("exact", "smooth"):
        orbit = ns.periodic_orbit(fig7, x0=-1.5, v0=0.25, method=method)
        ns.manifolds(fig7, orbit, x=(-3, 3), v=(-3, 3), length=1.0)  # compile / load
        dt, ds = best_of(a.repeat, lambda: ns.manifolds(fig7, orbit, x=(-3, 3), v=(-3, 3)))
        total += dt
        n = ds.attrs["periods_integrated"]
        print(f"fig7 saddle, {method}: {dt:.3f} s, {ds.sizes['point']} points, {n} periods, "
              f"{n / dt:,.0f} periods/s")
    dw = double_well()
    p = dw.params()
    orbit = ns.periodic_orbit(p, x0=-0.02, v0=0.0, method="smooth")
    kw = dict(x=(-2, 2), v=(-1.5, 1.5), length=5.0)
    ns.manifolds(p, orbit, **{**kw, "length": 0.5})
    dt, ds = best_of(a.repeat, lambda: ns.manifolds(p, orbit, **kw))
    total += dt
    n = ds.attrs["periods_integrated"]
    rate = n / dt
    T = 2 * math.pi

    def rhs(t, y):
        return [y[1], -0.05 * y[1] + y[0] - y[0] ** 3 + 0.04 * math.cos(t)]
    t0 = time.perf_counter()
    y = np.array([0.3, 0.1])
    for _ in range(a.scipy_periods):
        y = solve_ivp(rhs, (0, T), y, rtol=1e-10, atol=1e-12).y[:, -1]
    sp = a.scipy_periods / (time.perf_counter() - t0)
    print(f"double well F = 0.04, smooth: {dt:.3f} s, {ds.sizes['point']} points, "
          f"{ds.sizes['crossing']} homoclinic points, {n} periods, {rate:,.0f} periods/s; "
          f"scipy RK45 {sp:,.0f} periods/s: {rate / sp:,.0f}x")
    if a.tangency:
        t0 = time.perf_counter()
        t = ns.homoclinic_tangency(p.replace(F0=0.03), ns.periodic_orbit(
            p.replace(F0=0.03), x0=-0.015, v0=0.0, method="smooth"), "F0", (0.03, 0.045),
            tol=2e-4, spacing=0.05, max_search=60, **kw)
        print(f"homoclinic_tangency: F = {float(t.F0):.6f} in {time.perf_counter() - t0:.1f} s "
              f"({t.sizes['evaluation']} evaluations); Melnikov "
              f"{0.05 * 4 * math.cosh(math.pi / 2) / (3 * math.sqrt(2) * math.pi):.6f}")
    print(f"{total:.4f}")


if __name__ == "__main__":
    main()
