"""Benchmark: how fast a command stops on Ctrl-C (SIGINT) in the middle of a compiled
computation: the time from the signal to the process's exit, for one long trajectory
(`simulate`), one long sweep value (`bifurcation`) and a basins round whose trajectories run
10^7 periods. The README promises "about a second"; the tests check only that it stops, with
the right line and exit code (their waits are for observable states, never for seconds).

Usage::

    python benchmarks/bench_interrupt.py [--repeat 3]

Prints one line per command (best and worst of ``--repeat``) and, last, the worst time in
seconds (for ``../shared/tools/side-by-side``).
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

COMMANDS = {
    "simulate": ["simulate", "--transient", "1000000000", "--periods", "1"],
    "bifurcation": ["bifurcation", "--steps", "40", "--transient", "1000000000"],
    "basins": ["basins", "--preset", "fig7", "--method", "exact", "--grid", "300",
               "--transient", "10000000", "--max-periods", "10000000"],
}


def _default_sigint():
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def stop_time(argv, workdir: Path) -> float:
    """Seconds from SIGINT to exit, the signal sent 3 s after the command started computing
    (its chunk store or a progress line exists)."""
    out = workdir / "r.nc"
    err = workdir / "err.txt"
    env = dict(os.environ, NONSMOOTH_PROGRESS="1")
    with open(err, "w") as fe:
        proc = subprocess.Popen([sys.executable, "-m", "nonsmooth.cli", *argv, "-o", str(out)],
                                stdout=subprocess.DEVNULL, stderr=fe, env=env, cwd=workdir,
                                preexec_fn=_default_sigint)
        store = workdir / "r.nc.chunks"
        while not (store.exists() or "% of" in err.read_text()):
            if proc.poll() is not None:
                raise SystemExit(f"{argv[0]} ended before it was interrupted: {err.read_text()}")
            time.sleep(0.02)
        time.sleep(3.0)
        t0 = time.perf_counter()
        proc.send_signal(signal.SIGINT)
        code = proc.wait()
        dt = time.perf_counter() - t0
    if code != 130:
        raise SystemExit(f"{argv[0]}: exit {code}, expected 130: {err.read_text()}")
    return dt


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    worst = 0.0
    for name, argv in COMMANDS.items():
        times = []
        for _ in range(args.repeat):
            with tempfile.TemporaryDirectory() as d:
                times.append(stop_time(argv, Path(d)))
        worst = max(worst, max(times))
        print(f"{name:12s} stopped {min(times):.2f} s (best) ... {max(times):.2f} s (worst) "
              f"after SIGINT")
    print(f"{worst:.3f}")


if __name__ == "__main__":
    main()
