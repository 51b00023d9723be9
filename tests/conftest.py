"""The suite runs in parallel processes (pytest-xdist, ``-n auto --dist loadfile`` in
pyproject.toml: a test file's module fixtures are computed once, in one process)."""

import os
import subprocess
import sys

# Several test processes share the cores, each running numba's parallel loops on all of them:
# OpenMP's idle threads then spin on cores that another process's threads need (a manifold
# test of thousands of small parallel calls took 44 s instead of 33). Idle threads sleep here,
# in the test processes and the commands they start; a user's own runs keep OpenMP's default.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

#: Most processes the suite starts: each compiles what its tests need on an empty numba cache
#: (the kernels take 1-2 GB while compiling), and the compiled sweeps use every core anyway.
MAX_WORKERS = 4


def pytest_xdist_auto_num_workers(config):
    return max(1, min(MAX_WORKERS, os.cpu_count() or 1))


def pytest_configure(config):
    """On an empty numba cache, compile the slow kernels in subprocesses before the workers
    start (otherwise every worker compiles the same kernels at once, one after the other within
    each worker): the generic kernel, by far the longest (about two minutes), alone on one
    core; on another, one after the other, the other kernels and then every built-in model's
    compiled functions (and the derivations of the models written as equations), which every
    worker would otherwise build for itself."""
    if hasattr(config, "workerinput") or not getattr(config.option, "numprocesses", None):
        return
    from nonsmooth import _numba_cache
    # the modules whose first compile takes minutes, less ``kernels``, which imports them
    todo = [m for m in _numba_cache.SLOW_MODULES
            if m != "kernels" and not _numba_cache.is_compiled(m)]
    if not todo:
        return
    longest = "integrate.hybrid"
    codes = [f"import nonsmooth.{longest}"] if longest in todo else []
    codes.append("".join(f"import nonsmooth.{m}\n" for m in todo if m != longest)
                 + _BUILTIN_MODELS)
    procs = [subprocess.Popen([sys.executable, "-c", code]) for code in codes]
    for p in procs:
        p.wait()


_BUILTIN_MODELS = """
from nonsmooth.models import BUILTIN, model
for name in BUILTIN:
    m = model(name)
    for method in m.methods:
        m.fns(method)
"""
