"""Shared pieces of the benchmarks: the scipy reference on the smoothed model."""

from __future__ import annotations

import math
import os
import time

from scipy.integrate import solve_ivp


def scipy_switch_rhs(params):
    """Plain-Python right-hand side of eqs. 10-14 (eq. 13 transitions) with the Sigma_alpha
    entry-velocity memory tracked in a closure: what a user would hand to solve_ivp."""
    w02, ws2 = params.omega0**2, params.omega_s**2
    xi, xis, F0, om, eta = params.xi, params.xi_s, params.F0, params.omega, params.eta
    r = xis / ws2 if ws2 > 0 else 0.0
    mem = {"in_alpha": False, "Va": 0.0}

    def f(t, y):
        X, V = y
        ha = X - 1.0
        hb = -ha - r * V
        base = -w02 * X - xi * V + F0 * math.cos(om * t)
        if ha <= -eta or hb >= eta:
            mem["in_alpha"] = False
            return [V, base]
        if ha >= eta and hb <= -eta:
            mem["in_alpha"] = False
            return [V, base - ws2 * ha - xis * V]
        if ha < eta and hb <= -ha:
            if not mem["in_alpha"]:
                mem["in_alpha"] = True
                mem["Va"] = V
            q = (ha + eta) / (2 * eta)
            return [V, base - xis * V - 0.5 * ws2 * (ha + eta) + xis * mem["Va"] * (1 - q)]
        mem["in_alpha"] = False
        return [V, base - 0.5 * ws2 * (ha + eta) - 0.5 * xis * V]

    return f


def scipy_rate(params, periods, rtol=1e-8, atol=1e-10, method="RK45", x0=0.0, v0=0.0, repeats=3):
    """Forcing periods per second of scipy solve_ivp on the smoothed model (best of
    ``repeats``, CPU time of this process, so other load on the machine matters less)."""
    T = params.period
    best = float("inf")
    for _ in range(repeats):
        f = scipy_switch_rhs(params)
        t0 = time.process_time()
        sol = solve_ivp(f, (0.0, periods * T), [x0, v0], method=method, rtol=rtol, atol=atol)
        best = min(best, time.process_time() - t0)
    return periods / best, sol


def cpu_timer():
    """CPU time of this process: single-threaded rates compared in one run, under load."""
    return time.process_time()


def machine_line() -> str:
    load = os.getloadavg()
    return f"cpus={os.cpu_count()} load(1m,5m)={load[0]:.2f},{load[1]:.2f}"


def best_of(rounds, call, clock=time.perf_counter):
    """(best ``clock`` seconds of ``rounds`` calls of ``call``, the last result)."""
    best, out = float("inf"), None
    for _ in range(rounds):
        t0 = clock()
        out = call()
        best = min(best, clock() - t0)
    return best, out
