"""Benchmark: forcing periods per second of the exact event-driven solver.

Compares, in the same run and on the same trajectory settings (preset ``table3`` with
omega = 0.92, the chaotic grazing case of Fig. 10b, from X = V = 0):

* the exact solver (``Solver(method="exact")``, closed form between located events);
* the compiled RKF45 kernel of the smoothed switch model (``method="smooth"``, rtol 1e-8,
  atol 1e-10);
* scipy ``solve_ivp(method="RK45", rtol=1e-8, atol=1e-10)`` on the smoothed model's right-hand
  side written in plain Python (eqs. 10-14, eq. 13a with the entry velocity Va kept in a
  closure), the baseline of the issue (target: exact >= 3000x this).

Usage::

    python benchmarks/bench_exact.py [--periods 20000] [--smooth-periods 2000]
                                     [--scipy-periods 30] [--repeat 3]

Rates are the best of ``--repeat`` runs (after a compilation / warm-up run), since other
processes on a shared machine only ever slow a run down.
"""

from __future__ import annotations

import argparse
import math
import time

from scipy.integrate import solve_ivp

from nonsmooth import Solver, preset
from nonsmooth.kernels import advance, new_state, output_buffers


def smoothed_rhs(p):
    """Plain-Python right-hand side of eqs. 10-14 (transition eq. 13) with the Va memory.

    Mirrors ``nonsmooth.models.switch.region`` / ``accel``: the region is classified at every
    call, and entering Sigma_alpha from another region stores the entry velocity Va.
    """
    w02 = p.omega0 ** 2
    ws2 = p.omega_s ** 2
    xi, xis, F0, om, eta = p.xi, p.xi_s, p.F0, p.omega, p.eta
    r = xis / ws2 if p.omega_s > 0 else 0.0
    mem = {"Va": 0.0, "last": -1}

    def rhs(t, u):
        X, V = u
        ha = X - 1.0
        hb = -ha - r * V
        if ha <= -eta or hb >= eta:
            reg = 0
        elif ha >= eta and hb <= -eta:
            reg = 3
        elif ha < eta and hb <= -ha:
            reg = 1
        else:
            reg = 2
        if reg == 1 and mem["last"] != 1:
            mem["Va"] = V
        mem["last"] = reg
        base = -w02 * X - xi * V + F0 * math.cos(om * t)
        if reg == 0:
            a = base
        elif reg == 3:
            a = base - ws2 * ha - xis * V
        elif reg == 1:
            q = (ha + eta) / (2.0 * eta)
            a = base - xis * V - 0.5 * ws2 * (ha + eta) + xis * mem["Va"] * (1.0 - q)
        else:
            a = base - 0.5 * ws2 * (ha + eta) - 0.5 * xis * V
        return [V, a]

    return rhs


def rate_kernel(params, solver, periods, repeat):
    p = params.pack()
    opts = solver.opts()
    st = new_state(0.0, 0.0)
    advance(solver.code, p, opts, st, 1, 0, 5, *output_buffers(5))  # compile / load the cache
    best = 0.0
    code = 0
    for _ in range(repeat):
        st = new_state(0.0, 0.0)
        buf = output_buffers(periods)
        t0 = time.perf_counter()
        code = advance(solver.code, p, opts, st, 1, 0, periods, *buf)
        dt = time.perf_counter() - t0
        best = max(best, periods / dt)
    return best, code


def rate_scipy(params, periods, repeat):
    T = params.period
    best = 0.0
    nfev = 0
    for _ in range(repeat):
        rhs = smoothed_rhs(params)
        t0 = time.perf_counter()
        sol = solve_ivp(rhs, (0.0, periods * T), [0.0, 0.0], method="RK45", rtol=1e-8, atol=1e-10)
        dt = time.perf_counter() - t0
        nfev = sol.nfev
        best = max(best, periods / dt)
    return best, nfev


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--periods", type=int, default=20000, help="forcing periods, exact solver")
    ap.add_argument("--smooth-periods", type=int, default=2000, help="periods, RKF45 kernel")
    ap.add_argument("--scipy-periods", type=int, default=30, help="periods, scipy RK45")
    ap.add_argument("--repeat", type=int, default=3, help="runs per method (best is kept)")
    ap.add_argument("--omega", type=float, default=0.92, help="forcing frequency (table3)")
    args = ap.parse_args(argv)

    params = preset("table3").replace(omega=args.omega)
    ex, code_ex = rate_kernel(params, Solver(method="exact"), args.periods, args.repeat)
    sm, code_sm = rate_kernel(params, Solver(method="smooth", rtol=1e-8, atol=1e-10),
                              args.smooth_periods, args.repeat)
    sp, nfev = rate_scipy(params, args.scipy_periods, max(1, min(args.repeat, 2)))

    rows = [
        ("exact (closed form + events)", args.periods, ex, f"status {code_ex}"),
        ("smooth RKF45 kernel (numba)", args.smooth_periods, sm, f"status {code_sm}"),
        ("scipy RK45, Python RHS (smooth)", args.scipy_periods, sp, f"nfev {nfev}"),
    ]
    print(f"preset table3, omega = {args.omega}, eta = {params.eta:g}, from X = V = 0")
    print(f"{'method':34s} {'periods':>8s} {'periods/s':>12s}  note")
    for name, n, rate, note in rows:
        print(f"{name:34s} {n:8d} {rate:12.4g}  {note}")
    print(f"exact / scipy RK45   = {ex / sp:10.0f}x   (target >= 3000x)")
    print(f"exact / RKF45 kernel = {ex / sm:10.1f}x")
    print(f"RKF45 / scipy RK45   = {sm / sp:10.1f}x")
    print(f"{args.periods / ex:.4f}")  # last line: seconds of the exact run (side-by-side)
    return 0 if math.isfinite(ex) else 1


if __name__ == "__main__":
    raise SystemExit(main())
