"""Point numba's on-disk cache at a directory keyed by a hash of this package's source.

Numba keys a cached function on the file that defines it, not on the compiled functions it
calls: after an edit to a kernel, a cached caller (the method dispatcher, a sweep) would keep
running the old kernel. Keying the whole cache directory on the package source makes that
impossible. A ``NUMBA_CACHE_DIR`` set by the user is respected.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path


def source_digest() -> str:
    h = hashlib.sha256()
    root = Path(__file__).parent
    for path in sorted(root.rglob("*.py")):
        h.update(str(path.relative_to(root)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def configure() -> str | None:
    if os.environ.get("NUMBA_CACHE_DIR"):
        return None
    import numba

    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "nonsmooth"
    digest = source_digest()
    for parent in (base, Path(tempfile.gettempdir()) / "nonsmooth-cache"):
        d = parent / f"numba-{digest}"
        try:
            d.mkdir(parents=True, exist_ok=True)
            probe = d / ".write-test"
            probe.touch()
            probe.unlink()
        except OSError:
            continue
        numba.config.CACHE_DIR = str(d)
        _prune(parent, keep=d)
        return str(d)
    return None


def _prune(parent: Path, keep: Path, n_keep: int = 4) -> None:
    """Remove all but the ``n_keep`` most recently used cache directories of older sources."""
    import shutil

    try:
        dirs = sorted((p for p in parent.glob("numba-*") if p.is_dir() and p != keep),
                      key=lambda p: p.stat().st_mtime, reverse=True)
        for old in dirs[n_keep - 1:]:
            shutil.rmtree(old, ignore_errors=True)
    except OSError:
        pass
