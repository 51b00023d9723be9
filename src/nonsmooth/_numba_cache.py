"""Numba's on-disk cache for this package's kernels, invalidated by the kernels' own sources.

Numba keys a cached function on the file that defines it, not on the compiled functions it
calls: after an edit to a kernel, a cached caller (the method dispatcher, a sweep) would keep
running the old kernel. This module registers a cache *locator* that applies only to functions
defined in this package's compiled modules (``KERNEL_SOURCES``): their cache entries are stamped
with a digest of those sources, so an edit to a kernel invalidates every cached function that
may contain its code, and an edit elsewhere (a plot label, the CLI, the reproduction report)
invalidates nothing.

The sources come in layers (``LAYERS``, lowest first): the integrators, the models, the
kernels' dispatch and sweeps, the analyses. Compiled code of one layer calls (and so may
contain) code of its own layer and of the layers below, never above (``tests/test_import.py``
checks every module's imports), so a function's entries are stamped with the digest of its
own layer and those below: an edit to an analysis does not recompile the integrators (about
two minutes on an empty cache), an edit to an integrator recompiles everything.

Nothing else in the process is affected: other numba libraries keep numba's own locators and
``numba.config.CACHE_DIR``. The cache lives in ``$NUMBA_CACHE_DIR/nonsmooth`` when the user set
that variable, else in ``$XDG_CACHE_HOME/nonsmooth/numba`` (``~/.cache``), else in the temporary
directory; where none is writable numba's own locators decide (in-tree ``__pycache__``).
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent

#: Sources whose compiled code (or constants read by compiled code) the kernels depend on, in
#: layers, lowest first: a module may import from its own layer and the layers below only.
#: Every package module with numba code must be listed here.
LAYERS = (("integrate", "status.py"), ("models",), ("kernels.py", "sweep.py"), ("analysis",))
KERNEL_SOURCES = tuple(entry for layer in LAYERS for entry in layer)
#: The layer whose digest stamps the numba functions of users' model files (they may call the
#: models' compiled helpers, nothing above).
USER_LAYER = 1

_digests: dict = {}
_base: Path | None = None


def _files(entries) -> list[Path]:
    files = []
    for entry in entries:
        path = ROOT / entry
        files.extend(sorted(path.rglob("*.py")) if path.is_dir() else [path])
    return files


def kernel_source_files() -> list[Path]:
    return _files(KERNEL_SOURCES)


def layer_of(path: Path) -> int | None:
    """The layer (index into ``LAYERS``) of the package file ``path``, or None."""
    return _kernel_set().get(Path(path).resolve())


def source_digest(layer: int | None = None) -> str:
    """sha256 (16 hex digits) of the paths and contents of the kernel sources of ``layer`` and
    the layers below (None: all of them); computed once per layer."""
    top = len(LAYERS) - 1 if layer is None else layer
    if top not in _digests:
        h = hashlib.sha256()
        for path in _files(e for lay in LAYERS[:top + 1] for e in lay):
            h.update(str(path.relative_to(ROOT)).encode())
            h.update(path.read_bytes())
        _digests[top] = h.hexdigest()[:16]
    return _digests[top]


def cache_base() -> Path | None:
    """The first writable cache directory (see module docstring), or None."""
    global _base
    if _base is None:
        candidates = []
        if os.environ.get("NUMBA_CACHE_DIR"):
            candidates.append(Path(os.environ["NUMBA_CACHE_DIR"]) / "nonsmooth")
        home = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
        candidates += [Path(home) / "nonsmooth" / "numba",
                       Path(tempfile.gettempdir()) / "nonsmooth-cache" / "numba"]
        for d in candidates:
            try:
                d.mkdir(parents=True, exist_ok=True)
                tempfile.TemporaryFile(dir=d).close()
            except OSError:
                continue
            _base = d
            break
    return _base


def is_compiled(module: str) -> bool:
    """True if ``nonsmooth.<module>`` (dotted, e.g. "integrate.hybrid") has cache entries for
    today's kernel sources: used to tell the user once that a first run compiles."""
    base = cache_base()
    if base is None:
        return False
    path = ROOT.joinpath(*module.split(".")).with_suffix(".py")
    sub = base / _subpath(path)
    stem = path.stem
    digest = source_digest(layer_of(path)).encode()
    try:
        return any(_index_is_current(p, digest) for p in sub.glob(f"{stem}.*.nbi"))
    except OSError:
        return False


def _index_is_current(index: Path, digest: bytes) -> bool:
    # the index starts with the pickled source stamp; a stale one names another digest
    try:
        return digest in index.read_bytes()[:256]
    except OSError:
        return False


def _subpath(py_file: Path) -> str:
    rel = py_file.resolve().parent.relative_to(ROOT)
    return "_".join(("nonsmooth",) + rel.parts) + "_" + hashlib.sha1(
        str(py_file.resolve().parent).encode()).hexdigest()[:12]


#: Users' model files (resolved path -> the module name they are loaded under, which names
#: their contents: ``models._load_user``): their numba functions are cached under that name.
user_modules: dict = {}


def register_user_file(path, modname: str) -> None:
    """Cache the numba functions of the user's model file ``path`` (loaded as module
    ``modname``, a name made of its file name and a digest of its contents) in
    ``<cache>/user/<modname>`` rather than in ``__pycache__`` beside it (where no cache
    directory is writable, numba's own locators decide): numba's cache names the module it
    was compiled for, and a cache beside the file travels with a copied folder."""
    user_modules[Path(path).resolve()] = modname


def _locator_class():
    from numba.core import caching

    class KernelCacheLocator(caching._CacheLocator):
        """Cache locator for this package's kernels and the users' model files (see module
        docstring and ``register_user_file``)."""

        def __init__(self, py_func, py_file, user=None, layer=None):
            self._py_file = py_file
            self._lineno = py_func.__code__.co_firstlineno
            self._user = user
            self._layer = USER_LAYER if user else layer
            self._cache_path = str(cache_base() / ("user/" + user if user else
                                                   _subpath(Path(py_file))))

        def get_cache_path(self):
            return self._cache_path

        def get_source_stamp(self):
            return "nonsmooth-kernels-" + source_digest(self._layer) + (
                f"-{self._user}" if self._user else "")

        def get_disambiguator(self):
            return str(self._lineno)

        @classmethod
        def from_function(cls, py_func, py_file):
            try:
                path = Path(py_file).resolve()
            except (OSError, TypeError):
                return None
            user = user_modules.get(path)
            layer = _kernel_set().get(path)
            if cache_base() is None or (user is None and layer is None):
                return None
            self = cls(py_func, py_file, user, layer)
            try:
                self.ensure_cache_path()
            except OSError:
                return None
            return self

    return KernelCacheLocator


_kernel_files: dict | None = None


def _kernel_set() -> dict:
    """Resolved path of every kernel source -> its layer."""
    global _kernel_files
    if _kernel_files is None:
        _kernel_files = {p.resolve(): k for k, layer in enumerate(LAYERS) for p in _files(layer)}
    return _kernel_files


#: Modules whose compilation takes most of a first run's wait.
SLOW_MODULES = ("models.support.smooth_kernel", "models.support.exact_kernel", "integrate.hybrid",
                "kernels")

#: Called once, without arguments, when the kernels are first imported and the cache lacks
#: today's ``SLOW_MODULES`` (compilation follows). The library never prints: the CLI sets
#: this to tell the user.
compile_notice = None


def configure() -> None:
    """Register the locator (idempotent), and call ``compile_notice`` if compilation follows.
    Imports numba's caching module, nothing heavier."""
    global compile_notice
    from numba.core import caching

    impl = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl")
    classes = impl._locator_classes
    if any(getattr(c, "__name__", "") == "KernelCacheLocator" for c in classes):
        return
    classes.insert(0, _locator_class())
    if compile_notice is not None and not all(map(is_compiled, SLOW_MODULES)):
        notice, compile_notice = compile_notice, None
        notice()
