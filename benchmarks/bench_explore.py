"""How responsive `nonsmooth explore` is (issue 22's targets, warm, on this machine):

* a parameter change: the current orbit (time response, section, period) recomputed and
  drawn, target <= 200 ms, then its lambda1 (a second stage); measured as what the page
  computes (``explore.compute.current_orbit`` without and with lambda1) for every built-in
  model and method, and, with ``--browser`` (needs the system Chromium), from typing a value
  in the page to the new status with lambda1 drawn (the whole round trip);
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
    """Typing a value of F0 (not the slice's parameter, so a 200-value slice restarts beside
    the orbit) to (a) the new section drawn, (b) the status with lambda1; best and median."""
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
    server = Server("--preset", "table3", "--method", "exact", "--set", "omega=0.92")
    try:
        d.get(server.url)
        page = Page(d, server)
        wait_for(page.settled, "the first orbit")
        # timed in the page itself (performance.now()): from the Enter key to the section's
        # data source changed, and to the status with lambda1; Selenium's polling not counted
        el = page.element("param_F0", "input")
        page.js("""
            const doc = Bokeh.documents[0];
            window.nsT = {enter: null, drawn: null, full: null};
            arguments[0].addEventListener('keydown', e => {
                if (e.key === 'Enter') window.nsT = {enter: performance.now(), drawn: null,
                                                     full: null}; }, true);
            doc.get_model_by_name('section_source').change.connect(() => {
                if (window.nsT.enter !== null && window.nsT.drawn === null)
                    window.nsT.drawn = performance.now(); });
            doc.get_model_by_name('status').change.connect(() => {
                const s = doc.get_model_by_name('status').text;
                if (window.nsT.enter !== null && s.includes('λ1 =') && window.nsT.full === null)
                    window.nsT.full = performance.now(); });""", el)
        drawn, full = [], []
        for k in range(rounds + 1):
            page.type_into("param_F0", f"{0.31 + 0.001 * k:.4f}")
            t = wait_for(lambda: page.js("return window.nsT.full !== null && window.nsT"),
                         "lambda1")
            drawn.append((t["drawn"] - t["enter"]) / 1000)
            full.append((t["full"] - t["enter"]) / 1000)
        return [(min(x[1:]), float(np.median(x[1:]))) for x in (drawn, full)]
    finally:
        server.stop()
        d.quit()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--browser", action="store_true")
    a = ap.parse_args()
    print(f"{'model':16s} {'method':12s} {'drawn: best [ms]':>17s} {'median':>7s} "
          f"{'with lambda1: best':>19s} {'median':>7s}")
    for name, preset, sets in CASES:
        p = params_of(name, preset, sets)
        for method in p.model.methods:
            u0 = [0.0] * len(p.model.state_names)
            if name == "bouncing_ball" or name == "impact_2dof":
                u0[0] = 0.1 if name == "impact_2dof" else 0.0
            d, dmed = best(lambda: compute.current_orbit(p, method, u0, lyapunov=False),
                           a.rounds)
            b, med = best(lambda: compute.current_orbit(p, method, u0), a.rounds)
            print(f"{name:16s} {method:12s} {1000 * d:17.1f} {1000 * dmed:7.1f} "
                  f"{1000 * b:19.1f} {1000 * med:7.1f}")
    if a.browser:
        rt = browser_round_trip(a.rounds)
        if rt:
            (db, dm), (fb, fm) = rt
            print(f"browser, support exact at omega = 0.92 (chaotic), F0 typed while a slice "
                  f"runs: section drawn after best {1000 * db:.0f} ms (median {1000 * dm:.0f}), "
                  f"with lambda1 after {1000 * fb:.0f} ms (median {1000 * fm:.0f})")
    smooth = slice_seconds(params_of("support", "table3", {}), "smooth", "omega", 0.8, 1.0,
                           a.rounds)
    print(f"orbit-diagram slice, 200 values of omega, support smooth: best {smooth[0]:.3f} s")
    exact = slice_seconds(params_of("support", "table3", {}), "exact", "omega", 0.8, 1.0,
                          a.rounds)
    print(f"orbit-diagram slice, 200 values of omega, support exact: best {exact[0]:.3f} s")
    print(f"{exact[0]:.4f}")


if __name__ == "__main__":
    main()
