"""Benchmark: what a compiled core that runs many trajectories costs to compile, calling the
kernel by name against receiving it as a first-class function (``Solver.kernel``, a
``contract.KernelFunction``), as the cores of ``sweep``, ``basins``, ``bifurcation``,
``stability`` and ``manifolds`` do since issue 20's work.

Each variant is a fresh ``parallel=True`` core with ``sweep._run_many``'s body and signature,
compiled in its own subprocess (no cache for the core; the kernels themselves come from the
numba cache, loaded by a warm-up call first):

* ``by name, three kernels``: ``kernels.run(code, fns, ...)`` in the loop (the generic kernel
  and the support model's two specialised kernels, as before);
* ``by name, generic kernel``: ``hybrid.advance_generic(fns, ...)`` in the loop;
* ``first-class``: ``kernel(fns, ...)`` with ``kernel`` typed ``KERNEL_FN_TYPE``.

numba links the machine code of every function a core calls by name into the core and optimises
the whole again, so the first two pay for the kernel at each core (and would pay again for a
kernel compiled per model). Wall seconds, best of ``--repeat``; the last line is the
first-class compile time (for ``../shared/tools/side-by-side``).

Usage::

    python benchmarks/bench_compile.py [--repeat 2]
"""

from __future__ import annotations

import argparse
import subprocess
import sys

CHILD = r'''
import sys, time
import numba as nb
import nonsmooth as ns
from nonsmooth import kernels, sweep
from nonsmooth.integrate.contract import KERNEL_FN_TYPE
from nonsmooth.integrate.hybrid import advance_generic

s = kernels.Solver(method="exact", model="two_sided")
p = s.model.params().pack()
kernels.run(s.code, s.fns, p, s.opts(), kernels.new_state(0.0, 0.0), 1, 0, 5,
            *kernels.output_buffers(5))  # load the kernels from the cache
run = kernels.run
variant = sys.argv[1]
t = time.perf_counter()
if variant == "names3":
    @nb.njit(sweep._RUN_MANY_SIG.return_type(nb.int64, *sweep._RUN_MANY_SIG.args[1:]),
             parallel=True)
    def core(code, fns, P, opts, states, per_period, n_skip, n_out, X, V, R, M, Xa, Xb, status):
        for i in nb.prange(P.shape[0]):
            status[i] = run(code, fns, P[i], opts, states[i], per_period, n_skip, n_out, X[i],
                            V[i], R[i], M[i], Xa[i], Xb[i])
elif variant == "name1":
    @nb.njit(sweep._RUN_MANY_SIG.return_type(nb.int64, *sweep._RUN_MANY_SIG.args[1:]),
             parallel=True)
    def core(code, fns, P, opts, states, per_period, n_skip, n_out, X, V, R, M, Xa, Xb, status):
        for i in nb.prange(P.shape[0]):
            status[i] = advance_generic(fns, P[i], opts, states[i], per_period, n_skip, n_out,
                                        X[i], V[i], R[i], M[i], Xa[i], Xb[i])
else:
    @nb.njit(sweep._RUN_MANY_SIG, parallel=True)
    def core(kernel, fns, P, opts, states, per_period, n_skip, n_out, X, V, R, M, Xa, Xb,
             status):
        for i in nb.prange(P.shape[0]):
            status[i] = kernel(fns, P[i], opts, states[i], per_period, n_skip, n_out, X[i],
                               V[i], R[i], M[i], Xa[i], Xb[i])
print(time.perf_counter() - t)
'''

VARIANTS = (("by name, three kernels (kernels.run)", "names3"),
            ("by name, generic kernel", "name1"),
            ("first-class (Solver.kernel)", "pointer"))


def compile_seconds(variant: str) -> float:
    out = subprocess.run([sys.executable, "-c", CHILD, variant], capture_output=True, text=True,
                         check=True).stdout
    return float(out.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    subprocess.run([sys.executable, "-c", CHILD, "pointer"], capture_output=True, check=True)
    best = {}
    for name, v in VARIANTS:
        best[v] = min(compile_seconds(v) for _ in range(args.repeat))
        print(f"{name:40s} {best[v]:7.2f} s")
    print(f"{best['pointer']:.3f}")


if __name__ == "__main__":
    main()
