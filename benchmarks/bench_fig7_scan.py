"""Benchmark: ``examples/fig7_boundary_scan.py`` (the manifolds of Fig. 7's saddle grown at
each value of omega, F0 and xi: periodic orbits by Newton, manifolds, homoclinic crossings),
timed as a whole after a warm-up of ``ns.manifolds`` on fig7 (compilation / cache load
outside the timing).

Usage::

    python benchmarks/bench_fig7_scan.py

The last stdout line is the seconds of the scan (for ``../shared/tools/side-by-side``, which
runs this file under an earlier commit too: the example is read from this checkout, so both
sides run the same scan). 66.9 s at ``991ea28`` against 85.1 s at ``5d3f7d8`` side by side
(``benchmarks/HISTORY.md``, 2026-11-30).
"""

import contextlib
import io
import pathlib
import runpy
import time

import nonsmooth as ns

EXAMPLE = pathlib.Path(__file__).resolve().parent.parent / "examples" / "fig7_boundary_scan.py"


def main():
    p = ns.preset("fig7")
    ns.manifolds(p, ns.periodic_orbit(p, x0=-1.5, v0=0.25), x=(-3, 3), v=(-3, 3))  # warm-up
    t = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()):
        runpy.run_path(str(EXAMPLE), run_name="__main__")
    print(f"{time.perf_counter() - t:.3f}")


if __name__ == "__main__":
    main()
