"""Where compiled time goes: perf samples of numba-compiled code attributed to source lines.

perf cannot name numba's JIT code (no perf map, no jitdump from llvmlite's wheels). This tool
compiles everything afresh with debug information (``NUMBA_DEBUGINFO=1``, an empty numba cache
of its own), runs a workload twice under ``perf record``, and after the first run writes the
object code of every compiled function of ``nonsmooth`` (dispatchers and the models' cfuncs)
with its load address. The samples (of both runs) that fall in one of them are then mapped to
lines by ``addr2line`` on that object (with the inlining chain; numba's IR inlining keeps the
inlined function's line numbers but gives them the caller's file name).

Usage (Linux, ``perf`` and ``binutils`` installed)::

    python benchmarks/profile_kernel.py WORKLOAD.py [--top 40] [--frame hybrid.py]

WORKLOAD.py defines ``f()`` (what to profile; it may compute its inputs at import), e.g. the
generic kernel on the support model (fig4, 20,000 periods)::

    import numpy as np, nonsmooth as ns
    from nonsmooth.kernels import KERNEL_GENERIC, Solver, new_state, output_buffers, run
    s = Solver(method="smooth")
    p, o, fns = ns.preset("fig4").pack(), s.opts(), s.fns
    def f():
        run(KERNEL_GENERIC, fns, p, o, new_state(0.0, 0.0), 1, 0, 20000, *output_buffers(20000))

The
report lists the share of the samples per compiled library, per innermost source line, and
per first frame in a file whose name contains ``--frame``. Compiling takes a few minutes.
"""

from __future__ import annotations

import argparse
import collections
import gc
import json
import os
import re
import runpy
import subprocess
import sys
import tempfile
import time


def _dump_objects(out: str) -> None:
    """Object code and load address of every compiled nonsmooth function in this process."""
    from numba.core.ccallback import CFunc
    from numba.core.registry import CPUDispatcher
    cands = [o for o in gc.get_objects() if isinstance(o, (CPUDispatcher, CFunc))]
    libs = []
    for k, fn in enumerate(cands):
        if isinstance(fn, CFunc):
            if getattr(fn, "_library", None) is None:
                continue
            items = [(fn._library, fn._wrapper_name, fn.__qualname__)]
        else:
            items = [(c.library, c.fndesc.llvm_func_name, fn.__qualname__)
                     for c in fn.overloads.values()]
        for i, (lib, name, label) in enumerate(items):
            try:
                obj = lib._get_compiled_object()
                ptr = lib.get_pointer_to_function(name)
            except Exception:  # noqa: BLE001 - a library without object code: skip it
                continue
            path = os.path.join(out, f"{k}.{i}.o")
            with open(path, "wb") as fh:
                fh.write(obj)
            syms = subprocess.run(["nm", "--defined-only", path], capture_output=True,
                                  text=True).stdout.split("\n")
            off = next((int(s.split()[0], 16) for s in syms if s.endswith(" " + name)), None)
            sec = subprocess.run(["readelf", "-S", "-W", path], capture_output=True,
                                 text=True).stdout
            if off is None or not ptr or ".ltext" not in sec:
                continue
            size = int(sec.split(".ltext")[1].split()[3], 16)
            libs.append({"obj": path, "base": ptr - off, "size": size, "name": label})
    with open(os.path.join(out, "libs.json"), "w") as fh:
        json.dump(libs, fh)


def _child(workload: str, out: str) -> None:
    f = runpy.run_path(workload, run_name="profile")["f"]
    f()  # compile
    _dump_objects(out)
    t0 = time.perf_counter()
    f()
    print(f"profiled run: {time.perf_counter() - t0:.2f} s", flush=True)


def _report(data: str, out: str, top: int, frame: str) -> None:
    libs = json.load(open(os.path.join(out, "libs.json")))
    ips = subprocess.run(["perf", "script", "-i", data, "-F", "ip"], capture_output=True,
                         text=True).stdout.split()
    hits = collections.Counter()
    for s in ips:
        try:
            a = int(s, 16)
        except ValueError:
            continue
        for L in libs:
            if L["base"] <= a < L["base"] + L["size"]:
                hits[(L["obj"], L["name"], a - L["base"])] += 1
                break
    total = sum(hits.values())
    if not total:
        print("no samples in compiled nonsmooth code")
        return
    by_obj = collections.defaultdict(list)
    for (obj, name, a) in hits:
        by_obj[(obj, name)].append(a)
    per_lib, inner, outer = collections.Counter(), collections.Counter(), collections.Counter()
    for (obj, name), addrs in by_obj.items():
        addrs.sort()
        lines = subprocess.run(["addr2line", "-a", "-f", "-i", "-j", ".ltext", "-e", obj]
                               + [hex(a) for a in addrs], capture_output=True,
                               text=True).stdout.splitlines()
        groups, cur = {}, None
        for ln in lines:
            if ln.startswith("0x"):
                cur = int(ln, 16)
                groups[cur] = []
            elif cur is not None:
                groups[cur].append(ln)
        for a in addrs:
            c = hits[(obj, name, a)]
            per_lib[name] += c
            g = groups.get(a, [])
            where = [re.sub(r".*/site-packages/|.*/src/", "", g[i + 1]).split(" ")[0]
                     for i in range(0, len(g) - 1, 2)]
            if not where:
                continue
            inner[where[0]] += c
            outer[next((w for w in where if frame in w), where[-1])] += c
    print(f"{total} samples in compiled nonsmooth code")
    for title, cnt in (("by compiled function (library)", per_lib),
                       ("by innermost source line", inner),
                       (f"by first frame in {frame}", outer)):
        print(f"--- {title}")
        for k, c in cnt.most_common(top):
            print(f"{100.0 * c / total:5.1f}%  {k}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("workload")
    ap.add_argument("--top", type=int, default=40)
    ap.add_argument("--frame", default="hybrid.py")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        _child(args.workload, args.child)
        return
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, NUMBA_DEBUGINFO="1", NUMBA_CACHE_DIR=os.path.join(tmp, "cache"),
                   NUMBA_NUM_THREADS=os.environ.get("NUMBA_NUM_THREADS", "1"))
        data = os.path.join(tmp, "perf.data")
        subprocess.run(["perf", "record", "-q", "-F", "1999", "-o", data, sys.executable,
                        __file__, args.workload, "--child", tmp], env=env, check=True)
        _report(data, tmp, args.top, args.frame)


if __name__ == "__main__":
    main()
