"""Spike of issue 20, item 1: "glide", the RKF45 steps of one mode compiled per (model,
method) with the model's field called directly, against today's generic kernel.

The generic kernel calls the model's field through a first-class function pointer, six times
per RKF45 step. ``spike_glide.patch`` adds an eighth model function, ``glide``, compiled per
(model, method) as a ``cfunc`` with the field as a direct call: it takes the steps of a mode
while no guard can be crossed (the generic kernel's own exit tests, operation for operation)
and returns to the generic kernel at the first step that needs event location, which that
kernel then takes again. One pointer call per run of uneventful steps instead of six per step.

This script copies the package to a temporary folder, applies the patch there, and runs the
same trajectories (``bench_models``' cases, 3,000 periods from rest, CPU time, best of 3) with
the package as it is and with the patch, in alternating processes (``--rounds``); it prints
periods/s of both, their ratio, whether the outputs are bit for bit the same (sha256 of every
output and the final state), and the time glide took to compile per (model, method). The
patched copy compiles its kernel into a numba cache of its own (a few minutes, once).

Usage::

    python benchmarks/spike_glide.py [--models two_sided,stick_slip] [--rounds 2]
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

CASES = (("two_sided", "preset", "table3"), ("impact", "params", dict(F0=0.5, omega=0.8, r=0.8)),
         ("stick_slip", "params", {}), ("stick_slip", "preset", "stribeck"),
         ("bouncing_ball", "preset", "period_one"), ("impact_2dof", "params", {}))


def worker(models: list[str]) -> None:
    import numpy as np

    from nonsmooth import kernels
    from nonsmooth.models import model
    out = []
    for name, how, arg in CASES:
        if name not in models:
            continue
        m = model(name)
        params = m.preset(arg) if how == "preset" else m.params(**arg)
        for method in ("smooth", "exact"):
            solver = kernels.Solver(model=m, method=method)
            p, code, fns, o = params.pack(), solver.code, solver.fns, solver.opts()

            def go(periods):
                st = kernels.new_state(0.0, 0.0)
                buf = kernels.output_buffers(periods)
                t = time.process_time()
                status = kernels.run(code, fns, p, o, st, 1, 0, periods, *buf)
                return time.process_time() - t, status, buf, st
            go(3)
            _, status, buf, st = go(300)
            sha = hashlib.sha256(b"".join(np.ascontiguousarray(b).tobytes() for b in buf)
                                 + st.tobytes()).hexdigest()[:16]
            best = min(go(3000)[0] for _ in range(3))
            out.append(dict(case=f"{name} {arg if how == 'preset' else 'params'} {method}",
                            status=int(status), sha=sha, rate=3000 / best))
    print(json.dumps(out))


def run(src: Path, cache: str | None, models: str) -> list[dict]:
    env = dict(os.environ, PYTHONPATH=str(src))
    if cache:
        env["NUMBA_CACHE_DIR"] = cache
    r = subprocess.run([sys.executable, __file__, "--worker", models], env=env,
                       capture_output=True, text=True, check=True)
    res = json.loads(r.stdout.strip().splitlines()[-1])
    glide = dict(re.findall(r"glide (\S+ \S+): ([\d.]+) s", r.stderr))
    for row in res:
        name, method = row["case"].split()[0], row["case"].split()[-1]
        row["glide_compile"] = float(glide.get(f"{name} {method}", "nan"))
    return res


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--models", default="two_sided,impact,stick_slip,bouncing_ball,impact_2dof")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--worker", default=None, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.worker is not None:
        return worker(a.worker.split(","))
    tmp = Path(tempfile.mkdtemp(prefix="spike-glide-"))
    files = subprocess.run(["git", "ls-files", "src"], cwd=ROOT, capture_output=True, text=True,
                           check=True).stdout.split()
    for f in files:
        (tmp / f).parent.mkdir(parents=True, exist_ok=True)
        (tmp / f).write_bytes((ROOT / f).read_bytes())
    subprocess.run(["git", "apply", str(HERE / "spike_glide.patch")], cwd=tmp, check=True)
    cache = str(tmp / "numba-cache")
    best: dict[str, dict] = {}
    for r in range(a.rounds):
        for label, src, c in (("today", ROOT / "src", None), ("glide", tmp / "src", cache)):
            for row in run(src, c, a.models):
                key = (label, row["case"])
                if key not in best or row["rate"] > best[key]["rate"]:
                    best[key] = row
        print(f"round {r + 1} done", file=sys.stderr)
    print(f"{'case':40s} {'today/s':>10s} {'glide/s':>10s} {'ratio':>6s}  same bits  "
          f"glide compile")
    for (label, case), row in best.items():
        if label != "today":
            continue
        g = best[("glide", case)]
        print(f"{case:40s} {row['rate']:10.0f} {g['rate']:10.0f} {g['rate'] / row['rate']:6.2f}"
              f"  {str(row['sha'] == g['sha']):9s}  {g['glide_compile']:.1f} s")


if __name__ == "__main__":
    main()
