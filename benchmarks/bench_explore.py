"""How responsive `nonsmooth explore` is (issue 22's targets, warm, on this machine):

* a parameter change: the current orbit (time response, section, period, lambda1) recomputed,
  target <= 200 ms; measured as what the page computes (``explore.compute.current_orbit``) for
  every built-in model and method, and, with ``--browser`` (needs the system Chromium), from
  typing a value in the page to the new status drawn (the whole round trip);
* an orbit-diagram slice of 200 values (exact), target <= 2 s: ``explore.compute.orbit_slice``
  with the page's settings, chunks included.

Usage: python benchmarks/bench_explore.py [--rounds 5] [--browser]
Prints a table; the last line is the 200-value slice's seconds (support, exact).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import nonsmooth as ns
from nonsmooth.explore import compute

CASES = [("support", "table3", {"omega": 0.92}), ("two_sided", "table3", {}),
         ("impact", None, {}), ("stick_slip", "stribeck", {}), ("bouncing_ball", "chaotic", {}),
         ("impact_2dof", "period_one", {}), ("jeffcott_rotor", "chaotic_rub", {})]


def params_of(name, preset, sets):
    m = ns.model(name)
    p = m.preset(preset) if preset else m.params()
    return p.replace(**sets) if sets else p


def best(fn, rounds):
    fn()  # warm: compile or load the kernels
    times = []
    for _ in range(rounds):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times), float(np.median(times))


def slice_seconds(p, method, param, lo, hi, rounds):
    def run():
        for _ in compute.orbit_slice(p, method, param, np.linspace(lo, hi, 200),
                                     [0.0] * len(p.model.state_names)):
            pass
    return best(run, rounds)


def browser_round_trip(rounds):
    import shutil
    import sys
    sys.path.insert(0, "tests")
    from test_explore import CHROMEDRIVER, CHROMIUM, Page, Server, wait_for  # noqa: E402
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    if not (CHROMIUM and CHROMEDRIVER and shutil.which("chromium")):
        return None
    opts = webdriver.ChromeOptions()
    opts.binary_location = CHROMIUM
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--window-size=1500,1300"):
        opts.add_argument(a)
    d = webdriver.Chrome(service=Service(CHROMEDRIVER), options=opts)
    server = Server("--preset", "table3", "--method", "exact")
    try:
        d.get(server.url)
        page = Page(d, server)
        wait_for(page.settled, "the first orbit")
        times = []
        for k in range(rounds + 1):
            before = page.status()
            t0 = time.perf_counter()
            page.type_into("param_omega", f"{0.90 + 0.002 * (k % 5) + 0.0001 * k:.4f}")
            wait_for(lambda: page.settled() and page.status() != before, "the new orbit")
            times.append(time.perf_counter() - t0)
        return min(times[1:]), float(np.median(times[1:]))
    finally:
        server.stop()
        d.quit()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--browser", action="store_true")
    a = ap.parse_args()
    print(f"{'model':16s} {'method':8s} {'orbit best [ms]':>16s} {'median':>8s}")
    for name, preset, sets in CASES:
        p = params_of(name, preset, sets)
        for method in p.model.methods:
            u0 = [0.0] * len(p.model.state_names)
            if name == "bouncing_ball" or name == "impact_2dof":
                u0[0] = 0.1 if name == "impact_2dof" else 0.0
            b, med = best(lambda: compute.current_orbit(p, method, u0), a.rounds)
            print(f"{name:16s} {method:8s} {1000 * b:16.1f} {1000 * med:8.1f}")
    if a.browser:
        rt = browser_round_trip(a.rounds)
        if rt:
            print(f"browser round trip (support exact, type -> new status): best {1000 * rt[0]:.0f} ms, "
                  f"median {1000 * rt[1]:.0f} ms")
    smooth = slice_seconds(params_of("support", "table3", {}), "smooth", "omega", 0.8, 1.0,
                           a.rounds)
    print(f"orbit-diagram slice, 200 values of omega, support smooth: best {smooth[0]:.3f} s")
    exact = slice_seconds(params_of("support", "table3", {}), "exact", "omega", 0.8, 1.0,
                          a.rounds)
    print(f"orbit-diagram slice, 200 values of omega, support exact: best {exact[0]:.3f} s")
    print(f"{exact[0]:.4f}")


if __name__ == "__main__":
    main()
