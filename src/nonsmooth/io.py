"""Result files: netCDF with flat provenance attributes, and figure output."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ._version import __version__
from .errors import OutputError


#: CF version the result files follow (``Conventions`` global attribute).
CONVENTIONS = "CF-1.10"


def flag_attrs(meanings, values=None, *, dtype=np.int8, masks: bool = False, **extra) -> dict:
    """CF flag attributes for an integer variable: ``flag_values`` (or ``flag_masks`` when
    ``masks``: bit k <-> meaning k) of the variable's ``dtype`` and ``flag_meanings`` (words
    joined by blanks; blanks inside a meaning become underscores). ``values`` default to
    0, 1, 2, ...; ``extra`` attrs (``long_name``, ...) are added."""
    words = [str(m).strip().replace(" ", "_") for m in meanings]
    if masks:
        attrs = {"flag_masks": np.asarray([1 << k for k in range(len(words))], dtype=dtype)}
    else:
        vals = range(len(words)) if values is None else values
        attrs = {"flag_values": np.asarray(list(vals), dtype=dtype)}
    attrs["flag_meanings"] = " ".join(words)
    attrs.update(extra)
    return attrs


def status_flags(**extra) -> dict:
    """CF flag attributes of a kernel ``status`` variable (int64, codes of ``status.MESSAGES``)."""
    from . import status as st
    names = {code: st.FLAG_NAMES[code] for code in sorted(st.MESSAGES)}
    return flag_attrs(list(names.values()), list(names), dtype=np.int64, **extra)


def provenance_attrs(params=None, solver=None, **extra) -> dict:
    """Flat, netCDF-safe attrs: ``Conventions``, ``param_*`` for the parameters, the solver
    settings, the package version and any ``extra`` (bools become 0/1, None becomes "")."""
    import numba
    import scipy
    attrs = {"Conventions": CONVENTIONS, "nonsmooth_version": __version__,
             "numpy_version": np.__version__,
             "scipy_version": scipy.__version__, "numba_version": numba.__version__}
    if params is not None:
        attrs.update(params.attrs())
    if solver is not None:
        attrs.update(solver.attrs())
    attrs.update(extra)
    return clean_attrs(attrs)


def clean_attrs(attrs: dict) -> dict:
    out = {}
    for k, v in attrs.items():
        if v is None:
            v = ""
        elif isinstance(v, (bool, np.bool_)):
            v = int(v)
        elif isinstance(v, (list, tuple)):
            v = np.asarray(v)
        elif isinstance(v, dict):
            v = repr(v)
        elif isinstance(v, np.generic):
            v = v.item()
        out[k] = v
    return out


def check_writable(path, what: str = "output") -> Path:
    """Raise a one-line OutputError unless ``path`` can be created or overwritten."""
    p = Path(path)
    parent = p.parent if str(p.parent) else Path(".")
    if p.is_dir():
        raise OutputError(f"{what}: {str(p)!r} is a directory")
    if not parent.is_dir():
        raise OutputError(f"{what}: cannot write {str(p)!r}: directory {str(parent)!r} does not exist")
    if not os.access(parent, os.W_OK) or (p.exists() and not os.access(p, os.W_OK)):
        raise OutputError(f"{what}: cannot write {str(p)!r}: permission denied")
    return p


def save_dataset(ds, path) -> Path:
    """Write ``ds`` to netCDF (h5netcdf engine)."""
    p = check_writable(path, "output")
    ds = ds.copy()
    ds.attrs = clean_attrs(ds.attrs)
    for v in ds.variables.values():
        v.attrs = clean_attrs(v.attrs)
    try:
        ds.to_netcdf(p, engine="h5netcdf")
    except OSError as exc:
        raise OutputError(f"output: cannot write {str(p)!r}: {exc.strerror or exc}") from None
    return p


def load_dataset(path):
    import xarray as xr
    p = Path(path)
    if not p.is_file():
        raise OutputError(f"input: no such file {str(p)!r}")
    with xr.open_dataset(p, engine="h5netcdf") as ds:
        return ds.load()


def save_figure(fig, path, dpi: int = 150) -> Path:
    """Save a matplotlib figure (format from the suffix) and close it."""
    import matplotlib.pyplot as plt
    p = check_writable(path, "plot")
    try:
        fig.savefig(p, dpi=dpi, bbox_inches="tight")
    except (OSError, ValueError) as exc:
        raise OutputError(f"plot: cannot write {str(p)!r}: {exc}") from None
    finally:
        plt.close(fig)
    return p


def available_memory() -> int | None:
    """Bytes of memory available to a new allocation (Linux ``MemAvailable``, else the free
    physical pages), or None when unknown."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def format_bytes(n: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if abs(n) < 1024 or unit == "PiB":
            return f"{n:.1f} {unit}" if unit != "B" else f"{int(n)} B"
        n /= 1024
    return f"{n:.1f} PiB"


def check_memory(nbytes: float, field: str, hint: str, fraction: float = 0.8) -> None:
    """Refuse, before computing, a request whose arrays (``nbytes`` in all) would not fit in
    ``fraction`` of the available memory: one ParameterError naming ``field``, the size, the
    memory available and ``hint`` (what to do instead)."""
    from .errors import ParameterError
    avail = available_memory()
    if avail is not None and nbytes > fraction * avail:
        raise ParameterError(f"{field}: the result would need {format_bytes(nbytes)} of memory, "
                             f"{format_bytes(avail)} available; {hint}")


def finite_or_nan(x) -> float:
    x = float(x)
    return x if math.isfinite(x) else float("nan")
