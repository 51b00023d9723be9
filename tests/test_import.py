"""Importing the package is cheap and has no side effects (each check in a fresh interpreter)."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import nonsmooth as ns

HEAVY = ("numba", "xarray", "matplotlib", "scipy")


def _python(code: str, **env) -> subprocess.CompletedProcess:
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                       env={**os.environ, **env})
    assert r.returncode == 0, r.stderr
    return r


def _loaded(code: str) -> set:
    out = _python(code + "\nimport sys; print(' '.join(sorted(sys.modules)))").stdout
    return {m.split(".")[0] for m in out.split()}


def test_import_loads_no_heavy_module():
    assert not _loaded("import nonsmooth").intersection(HEAVY)


def test_cli_help_and_version_load_no_heavy_module():
    for arg in ("--help", "--version", "simulate --help"):
        code = (f"from nonsmooth.cli import main\ntry:\n    main({arg.split()!r})\n"
                f"except SystemExit as e:\n    assert e.code in (0, None)")
        assert not _loaded(code).intersection(HEAVY), arg


def test_every_public_name_resolves():
    for name in ns.__all__:
        assert getattr(ns, name) is not None, name
        assert name in dir(ns)
    for mod in ("io", "plot", "errors", "status"):
        assert getattr(ns, mod).__name__ == f"nonsmooth.{mod}"
    assert ns.ParameterError is ns.errors.ParameterError


def test_simulate_stays_the_function_when_its_module_is_imported_first():
    # analyses import the module nonsmooth.simulate; the package attribute is the function
    r = _python("import nonsmooth.simulate, types, nonsmooth as ns\n"
                "assert not isinstance(ns.simulate, types.ModuleType), ns.simulate\n"
                "from nonsmooth import simulate\nassert simulate is ns.simulate")
    assert r.returncode == 0


def test_plot_package_leaves_the_backend_and_pyplot_alone(tmp_path):
    code = ("import matplotlib\nmatplotlib.use('svg')\nimport sys, nonsmooth.plot\n"
            "from nonsmooth.plot.common import new_figure\nfrom nonsmooth.io import save_figure\n"
            "fig, ax = new_figure()\nax.plot([0, 1], [1, 0])\n"
            f"p = save_figure(fig, {str(tmp_path / 'f.png')!r})\n"
            "for name in nonsmooth.plot.__all__:\n    getattr(nonsmooth.plot, name)\n"
            "assert 'matplotlib.pyplot' not in sys.modules\n"
            "assert matplotlib.get_backend() == 'svg', matplotlib.get_backend()\nprint(p)")
    r = _python(code, MPLBACKEND="")
    assert r.stdout.strip() == str(tmp_path / "f.png")
    assert (tmp_path / "f.png").read_bytes()[:4] == b"\x89PNG"


def test_plot_functions_are_found_from_nonsmooth_plot():
    import nonsmooth.plot as nplot
    for name in ("plot_time_response", "plot_poincare", "plot_bifurcation", "plot_resonance",
                 "plot_eta_study", "plot_basins", "plot_attractors"):
        assert callable(getattr(nplot, name)) and name in dir(nplot)


def test_python_dash_m_nonsmooth():
    r = subprocess.run([sys.executable, "-m", "nonsmooth", "--version"], capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 0 and r.stdout.strip() == f"nonsmooth {ns.__version__}"


@pytest.mark.parametrize("cache_dir", [None, "numba-cache"])
def test_numba_cache_of_other_libraries_is_untouched(tmp_path, cache_dir):
    # another numba library, imported after nonsmooth's kernels: numba's own CACHE_DIR and
    # locators still apply to it (its __pycache__ beside the source, or NUMBA_CACHE_DIR when the
    # user set one)
    (tmp_path / "otherlib.py").write_text(
        "import numba\n@numba.njit(cache=True)\ndef f(x):\n    return x + 1\n")
    code = ("import numba\nbefore = numba.config.CACHE_DIR\n"
            "import nonsmooth.integrate, nonsmooth.models, nonsmooth.analysis\n"
            "import otherlib\nassert otherlib.f(1) == 2\n"
            "assert numba.config.CACHE_DIR == before, numba.config.CACHE_DIR")
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["PYTHONPATH"] = str(tmp_path)
    where = tmp_path / "__pycache__"
    if cache_dir:
        where = tmp_path / cache_dir
        env["NUMBA_CACHE_DIR"] = str(where)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                       cwd=tmp_path, env=env)
    assert r.returncode == 0, r.stderr
    assert list(where.rglob("otherlib.f-*.nbi"))
    if cache_dir:
        assert not (tmp_path / "__pycache__").exists() or not list(
            (tmp_path / "__pycache__").glob("otherlib.f-*.nbi"))


def test_source_digest_covers_the_kernels_only(tmp_path):
    # a copy of the package: editing a plot label keeps the digest, editing a kernel changes it
    src = Path(ns.__file__).parent
    shutil.copytree(src, tmp_path / "nonsmooth", ignore=shutil.ignore_patterns("__pycache__"))
    digest = ("import nonsmooth._numba_cache as c; "
              "assert c.ROOT == __import__('pathlib').Path(c.__file__).parent; "
              "print(*(c.source_digest(k) for k in range(len(c.LAYERS))), c.source_digest())")

    def current():
        return _python(digest, PYTHONPATH=str(tmp_path)).stdout.split()

    def edit(rel, text):
        with open(tmp_path / "nonsmooth" / rel, "a") as f:
            f.write(f"\n# {text}\n")

    d0 = current()
    assert len(d0) == 5 and d0[3] == d0[4]  # (the top layer's digest is the whole digest)
    edit("plot/common.py", "an edited label")
    edit("cli/common.py", "an edited help text")
    assert current() == d0
    # an edited analysis: its layer's stamp changes, the integrators' and models' do not
    edit("analysis/stability.py", "an edited analysis")
    d1 = current()
    assert d1[:3] == d0[:3] and d1[3] != d0[3]
    # an edited integrator: every stamp changes
    edit("integrate/record.py", "an edited kernel")
    d2 = current()
    assert all(a != b for a, b in zip(d2, d1))


def _module_file(root, parts):
    """The file of module ``nonsmooth.<parts>`` (a module or a package's __init__), or None."""
    path = root.joinpath(*parts)
    if path.with_suffix(".py").is_file():
        return path.with_suffix(".py").resolve()
    if (path / "__init__.py").is_file():
        return (path / "__init__.py").resolve()
    return None


def test_kernel_layers_import_only_from_their_own_layer_and_below():
    # a cached function is stamped with the digest of its layer and the layers below
    # (``_numba_cache.LAYERS``): its compiled code must not contain code from a layer above,
    # so no kernel module imports from one (at any depth: also imports inside functions)
    import ast

    from nonsmooth import _numba_cache as c
    layers = c._kernel_set()
    assert set(layers) == {p.resolve() for p in c.kernel_source_files()}
    bad = []
    for path, k in layers.items():
        pkg = list(path.parent.relative_to(c.ROOT).parts)
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                if node.level == 0:
                    if not (node.module or "").split(".")[0] == "nonsmooth":
                        continue
                    parts = node.module.split(".")[1:]
                else:
                    parts = pkg[:len(pkg) - (node.level - 1)] + (
                        node.module.split(".") if node.module else [])
                targets = [parts + [a.name] for a in node.names] + [parts]
            elif isinstance(node, ast.Import):
                targets = [a.name.split(".")[1:] for a in node.names
                           if a.name.split(".")[0] == "nonsmooth"]
            else:
                continue
            for t in targets:
                f = _module_file(c.ROOT, t)
                if f is not None and layers.get(f, -1) > k:
                    bad.append(f"{path.relative_to(c.ROOT)} (layer {k}) imports "
                               f"{f.relative_to(c.ROOT)} (layer {layers[f]})")
    assert not bad, "\n".join(bad)
    # the check sees imports at all: integrate/hybrid.py imports status, layer 0
    assert layers[c.ROOT / "status.py"] == 0


def test_fast_math_kernel_code_has_no_power_operator():
    """``x ** 2`` compiles to numba's integer-power helper, which numba compiles once per
    process with the fast-math flags of whichever function needed it first and then links
    into every later caller. In a fast-math function (or one inlined into such) LLVM then fuses
    a multiply-add or not depending on that order, so the same source gave kernels that
    differed in the last bits (1e-14 after 50 periods of fig7, smoothed) depending on whether
    the integrators were compiled in the same process or loaded from the cache. Products
    written out are lowered with the function's own flags."""
    import ast

    from nonsmooth import _numba_cache as c
    bad = []
    for path in c._kernel_set():
        for fn in ast.walk(ast.parse(path.read_text())):
            if not isinstance(fn, ast.FunctionDef):
                continue
            dec = " ".join(ast.unparse(d) for d in fn.decorator_list)
            if "fastmath" not in dec and "inline='always'" not in dec:
                continue
            for node in ast.walk(fn):
                if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
                    bad.append(f"{path.relative_to(c.ROOT)}:{node.lineno} {fn.name}: "
                               f"{ast.unparse(node)}")
    assert not bad, "\n".join(bad)
    # the check sees the functions at all: the generic kernel's RKF45 step is one of them
    src = (c.ROOT / "integrate" / "hybrid.py").read_text()
    assert "def _rk_step(" in src and "inline=\"always\", fastmath=_FM)\ndef _rk_step(" in src
