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
    """On an empty numba cache, compile what every worker would otherwise compile for itself,
    in subprocesses, before the workers start: first the generic kernel, by far the longest
    (about two to five minutes), alone on one core, and on the other, one after the other, the
    other kernels and every built-in model's compiled functions (and the derivations of the
    models written as equations); then, side by side, what importing the test modules compiles
    (the kernels' dispatch and the analyses' compiled cores: each worker imports every test
    module the command names, the two at the same time) and the tests' own slow functions
    (``precompile()`` of the modules in ``PRECOMPILED`` that the command names)."""
    if hasattr(config, "workerinput") or not getattr(config.option, "numprocesses", None):
        return
    from nonsmooth import _numba_cache
    # the modules whose first compile takes minutes, less ``kernels``, which imports them
    todo = [m for m in _numba_cache.SLOW_MODULES
            if m != "kernels" and not _numba_cache.is_compiled(m)]
    longest = "integrate.hybrid"
    codes = [f"import nonsmooth.{longest}"] if longest in todo else []
    if todo:
        codes.append("".join(f"import nonsmooth.{m}\n" for m in todo if m != longest)
                     + _BUILTIN_MODELS)
    _side_by_side(codes)
    if todo or not all(map(_numba_cache.is_compiled, ("kernels", "analysis.bifurcation"))):
        here = os.path.dirname(os.path.abspath(__file__))
        tests = _requested_modules(config.args, here)
        path = f"import sys\nsys.path.insert(0, {here!r})\n"
        # (quiet: a test module that fails to import says so again, in its place, when the
        # workers collect it)
        _side_by_side([path + "".join(f"import {m}\n" for m in tests),
                       path + "".join(f"import {m}\n{m}.precompile()\n"
                                      for m in PRECOMPILED if m in tests)],
                      quiet=True)


#: Test modules with a ``precompile()`` that compiles (or loads from the cache) their slow
#: compiled functions.
PRECOMPILED = ("test_hybrid_kernel",)


def _requested_modules(args, here):
    """The test modules (names) that the command line's paths name: every one for a folder
    that holds this one (``pytest``, ``pytest tests``), else those of the files named."""
    every = sorted(f[:-3] for f in os.listdir(here) if f.startswith("test_") and f.endswith(".py"))
    named = set()
    for arg in args or ["."]:
        path = os.path.abspath(arg.split("::")[0])
        if os.path.isdir(path) and (here + os.sep).startswith(path.rstrip(os.sep) + os.sep):
            return every
        if os.path.dirname(path) == here and path.endswith(".py"):
            named.add(os.path.basename(path)[:-3])
    return [m for m in every if m in named]


def _side_by_side(codes, quiet=False):
    """Run each code in a Python process of its own, all at once; wait for them all."""
    out = subprocess.DEVNULL if quiet else None
    procs = [subprocess.Popen([sys.executable, "-c", code], stdout=out, stderr=out)
             for code in codes]
    for p in procs:
        p.wait()


_BUILTIN_MODELS = """
from nonsmooth.models import BUILTIN, model
for name in BUILTIN:
    m = model(name)
    for method in m.methods:
        m.fns(method)
"""
