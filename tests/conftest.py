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
    """On an empty numba cache, compile the slow kernels side by side in subprocesses before
    the workers start: otherwise every worker compiles the same kernels at once, one after the
    other within each worker."""
    if hasattr(config, "workerinput") or not getattr(config.option, "numprocesses", None):
        return
    from nonsmooth import _numba_cache
    # the modules whose first compile takes minutes, less ``kernels``, which imports them
    todo = [m for m in _numba_cache.SLOW_MODULES
            if m != "kernels" and not _numba_cache.is_compiled(m)]
    procs = [subprocess.Popen([sys.executable, "-c", f"import nonsmooth.{m}"]) for m in todo]
    for p in procs:
        p.wait()
