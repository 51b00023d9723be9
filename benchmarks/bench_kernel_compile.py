"""Benchmark: the first compile of the generic kernels on an empty numba cache (what a fresh
machine, CI and a newcomer's first run pay once).

Importing ``nonsmooth.integrate.hybrid`` compiles ``advance_generic`` and ``advance_tangent``
for their explicit signatures. A child process does it with an empty ``NUMBA_CACHE_DIR`` of
its own and records numba's compile events: the wall time of the import, and the inclusive
time of each compiled function (a function compiled twice, for two argument types, appears
twice). Until the literal ``qr = 0`` of ``advance_generic`` became an int64, ``_advance``, the
body of both kernels, was compiled twice.

Usage::

    python benchmarks/bench_kernel_compile.py [--top 8]

The last line is the import's wall seconds (for ``../shared/tools/side-by-side``).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile

CHILD = r'''
import sys, time
from numba.core import event as ev
with ev.install_recorder("numba:compile") as rec:
    t = time.perf_counter()
    import nonsmooth.integrate.hybrid  # noqa: F401
    wall = time.perf_counter() - t
spans, starts = [], []
for ts, e in rec.buffer:
    if e.is_start:
        starts.append((ts, e))
    else:
        t0, e0 = starts.pop()
        spans.append((ts - t0, getattr(e0.data["dispatcher"], "py_func", None)))
spans.sort(key=lambda s: -s[0])
for d, f in spans[:int(sys.argv[1])]:
    print(f"  {d:7.1f} s  {getattr(f, '__name__', f)}")
print(f"{wall:.1f}")
'''


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--top", type=int, default=8, help="compiled functions listed")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        out = subprocess.run([sys.executable, "-c", CHILD, str(a.top)], env=env, check=True,
                             capture_output=True, text=True).stdout.splitlines()
    print("generic kernels, empty numba cache: inclusive compile time of the slowest functions")
    print("\n".join(out[:-1]))
    print(f"import of nonsmooth.integrate.hybrid (both kernels compiled): {out[-1]} s")
    print(out[-1])


if __name__ == "__main__":
    main()
