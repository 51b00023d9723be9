"""Benchmark: start-up time of the package and of the command line.

Times, in fresh subprocesses (wall clock, best of ``--repeat``, since other load on a shared
machine only ever slows a run down):

* ``import nonsmooth`` cold: empty numba cache (``NUMBA_CACHE_DIR`` and ``XDG_CACHE_HOME`` set
  to new temporary folders), what a fresh install sees (target <= 1 s);
* ``import nonsmooth`` warm: the user's cache, after one import that filled it;
* ``nonsmooth --help`` and ``nonsmooth --version`` warm (target <= 0.5 s).

Usage::

    python benchmarks/bench_import.py [--repeat 5] [--cold-repeat 2] [--src DIR]

``--src DIR`` times another source tree (e.g. an export of an older commit:
``git archive 8d0d1d5 | tar -x -C /tmp/old`` then ``--src /tmp/old/src``) with the same
interpreter. The last line printed is the warm ``nonsmooth --help`` time in seconds.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time

IMPORT = [sys.executable, "-c", "import nonsmooth"]
CLI = [sys.executable, "-m", "nonsmooth.cli"]


def run_once(cmd, env) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0


def best(cmd, env, repeat: int, fresh_cache: bool = False) -> float:
    times = []
    for _ in range(repeat):
        run_env = dict(env)
        with tempfile.TemporaryDirectory() as numba_dir, tempfile.TemporaryDirectory() as xdg:
            if fresh_cache:
                run_env.update(NUMBA_CACHE_DIR=numba_dir, XDG_CACHE_HOME=xdg)
            times.append(run_once(cmd, run_env))
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=5, help="runs per warm timing")
    ap.add_argument("--cold-repeat", type=int, default=2, help="runs per cold timing")
    ap.add_argument("--src", help="source folder holding the nonsmooth package to time")
    args = ap.parse_args()

    env = dict(os.environ)
    for var in ("NUMBA_CACHE_DIR", "XDG_CACHE_HOME"):
        env.pop(var, None)
    if args.src:
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [args.src, env.get("PYTHONPATH")]))
    where = subprocess.run(IMPORT[:2] + ["import nonsmooth; print(nonsmooth.__file__)"],
                           env=env, check=True, capture_output=True, text=True).stdout.strip()
    print(f"package: {where}")

    cold = best(IMPORT, env, args.cold_repeat, fresh_cache=True)
    print(f"import nonsmooth, cold (empty numba cache): {cold:.3f} s")
    run_once(IMPORT, env)  # fills the user's cache where the import compiles anything
    warm = best(IMPORT, env, args.repeat)
    print(f"import nonsmooth, warm: {warm:.3f} s")
    version = best(CLI + ["--version"], env, args.repeat)
    print(f"nonsmooth --version, warm: {version:.3f} s")
    helps = best(CLI + ["--help"], env, args.repeat)
    print(f"nonsmooth --help, warm: {helps:.3f} s")
    print(f"{helps:.3f}")


if __name__ == "__main__":
    main()
