"""Result files: netCDF with flat provenance attributes, and figure output.

Every file is written atomically (:func:`atomic_path`): to a temporary name in its folder,
renamed onto the target when complete, so a previous result is never destroyed by a failed,
interrupted or killed write, and the files written are recorded (:func:`written_files`).
"""

from __future__ import annotations

import re

import contextlib
import math
import os
import stat
import sys
import uuid
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


def provenance_attrs(params=None, solver=None, swept=(), **extra) -> dict:
    """Flat, netCDF-safe attrs: ``Conventions``, ``param_*`` for the parameters except the
    ``swept`` ones (coordinates of the result: a base value in the attrs would be read back as
    the point, see ``Model.params_from_attrs``), the solver settings, the package version and any
    ``extra`` (bools become 0/1, None becomes "")."""
    import numba
    import scipy
    attrs = {"Conventions": CONVENTIONS, "nonsmooth_version": __version__,
             "numpy_version": np.__version__,
             "scipy_version": scipy.__version__, "numba_version": numba.__version__}
    if params is not None:
        attrs.update({k: v for k, v in params.attrs().items()
                      if k.removeprefix("param_") not in swept})
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
        why = "is a file, not a directory" if parent.exists() else "does not exist"
        raise OutputError(f"{what}: cannot write {str(p)!r}: {str(parent)!r} {why}")
    if not os.access(parent, os.W_OK) or (p.exists() and not os.access(p, os.W_OK)):
        raise OutputError(f"{what}: cannot write {str(p)!r}: permission denied")
    if not p.exists():  # a file made and removed: os.access says yes to root where the
        probe = parent / f".{p.name}.{uuid.uuid4().hex[:8]}.probe"  # filesystem says no (/sys)
        try:
            os.close(os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
            os.unlink(probe)
        except OSError as exc:
            raise OutputError(f"{what}: cannot write {str(p)!r}: {exc.strerror or exc}") from None
    return p


_written: list[Path] = []


def written_files() -> list[Path]:
    """The files this process has written through this module, in order (for the CLI's
    message when a run is interrupted)."""
    return list(_written)


@contextlib.contextmanager
def atomic_path(path, what: str = "output", record: bool = True):
    """Yield a temporary path in the folder of ``path`` to write the whole file to; when the
    block completes the file is renamed onto ``path`` (``os.replace``: readers, even one that
    holds the old file open, see the old file or the new one, never a partial one). On any
    failure or interruption the temporary file is removed and ``path`` is untouched; an OSError
    becomes a one-line OutputError naming ``what`` and the path. ``record``: list the file in
    :func:`written_files` (not for internal files such as chunk stores)."""
    p = check_writable(path, what)
    tmp = p.with_name(f".{p.name}.{uuid.uuid4().hex[:8]}.part")
    try:
        os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))  # umask applies
        if p.exists():
            os.chmod(tmp, stat.S_IMODE(p.stat().st_mode))
        yield tmp
        os.replace(tmp, p)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            tmp.unlink()
        if isinstance(exc, OSError) and not isinstance(exc, OutputError):
            raise OutputError(f"{what}: cannot write {str(p)!r}: "
                              f"{exc.strerror or exc}; {_previous(p)}") from None
        raise
    if record:
        _written.append(p)


def _previous(p: Path) -> str:
    return "the previous file is untouched" if p.exists() else "nothing written"


def write_file(path, data: str | bytes, what: str = "output", record: bool = True) -> Path:
    """Write ``data`` (text as UTF-8, or bytes) to ``path`` atomically (:func:`atomic_path`)."""
    with atomic_path(path, what, record) as tmp:
        tmp.write_bytes(data.encode("utf-8") if isinstance(data, str) else data)
    return Path(path)


def save_dataset(ds, path) -> Path:
    """Write ``ds`` to netCDF4 (h5netcdf engine) atomically (:func:`atomic_path`), with flat
    netCDF-safe attributes and a ``Conventions`` attribute."""
    ds = ds.copy()
    ds.attrs = clean_attrs({"Conventions": CONVENTIONS, **ds.attrs})
    for v in ds.variables.values():
        v.attrs = clean_attrs(v.attrs)
    with atomic_path(path, "output") as tmp:
        try:
            ds.to_netcdf(tmp, engine="h5netcdf")
        except ValueError as exc:  # h5netcdf refuses some types and names
            raise OSError(str(exc)) from None
    return Path(path)


def load_dataset(path):
    """Read a netCDF result file written by :func:`save_dataset` into memory (the file is
    closed on return). A missing or non-netCDF file raises a one-line OutputError."""
    import xarray as xr
    p = Path(path)
    if not p.is_file():
        raise OutputError(f"input: no such file {str(p)!r}")
    try:
        with xr.open_dataset(p, engine="h5netcdf") as ds:
            return ds.load()
    except (OSError, ValueError) as exc:
        raise OutputError(f"input: cannot read {str(p)!r} as netCDF: {exc}") from None


#: names a result file may take: netCDF's suffixes, or none (the CLI's ``-o``)
NETCDF_SUFFIXES = ("", ".nc", ".nc4", ".netcdf", ".cdf", ".h5", ".hdf5")


def figure_formats() -> dict:
    """matplotlib's figure formats (suffix without the dot -> description)."""
    from matplotlib.backend_bases import FigureCanvasBase
    return FigureCanvasBase.get_supported_filetypes()


def figure_path(path, what: str = "plot") -> Path:
    """The file a figure saved to ``path`` is written to: the format is the suffix (one of
    matplotlib's formats, else a one-line OutputError naming ``what``); no suffix means PNG,
    with ``.png`` appended (as matplotlib does). Checks that it can be written."""
    p = Path(path)
    fmt = p.suffix[1:].lower()
    if not fmt:
        p = p.with_name(p.name + ".png")
    elif fmt not in figure_formats():
        known = ", ".join(sorted(figure_formats()))
        raise OutputError(f"{what}: unknown figure format {fmt!r} in {str(path)!r} (known: {known})")
    return check_writable(p, what)


def save_figure(fig, path, dpi: int = 150, what: str = "plot") -> Path:
    """Save a matplotlib figure atomically (format from the suffix, see :func:`figure_path`)
    and return the path written. A pyplot figure is also closed."""
    p = figure_path(path, what)
    try:
        with atomic_path(p, what) as tmp:
            try:
                fig.savefig(tmp, format=p.suffix[1:].lower(), dpi=dpi, bbox_inches="tight")
            except ValueError as exc:
                raise OSError(str(exc)) from None
    finally:
        if "matplotlib.pyplot" in sys.modules:
            sys.modules["matplotlib.pyplot"].close(fig)
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


def check_memory(nbytes: float, field: str, hint: str, fraction: float = 0.8,
                 size: tuple | None = None) -> None:
    """Refuse, before computing, a request whose arrays (``nbytes`` in all) would not fit in
    ``fraction`` of the available memory: one ParameterError naming ``field``, the size, the
    memory available and ``hint`` (what to do instead). ``size = (n, power)``: the request's
    size as the user typed it, with nbytes growing as n**power; the line then also gives the
    largest n that fits."""
    from .errors import ParameterError
    avail = available_memory()
    if avail is not None and nbytes > fraction * avail:
        fits = ""
        if size is not None:
            n, power = size
            largest = int(n * (fraction * avail / nbytes) ** (1.0 / power))
            fits = f"; at most {field} = {largest:,} fits"
        raise ParameterError(f"{field}: the result would need {format_bytes(nbytes)} of memory, "
                             f"{format_bytes(avail)} available{fits}; {hint}")


def finite_or_nan(x) -> float:
    x = float(x)
    return x if math.isfinite(x) else float("nan")


def component_names(state_names) -> list[str]:
    """The variable name of each state component in a result: ``X`` and ``V`` for u[0], u[1]
    (whatever the model calls them: every result names them so), then the model's state
    names (``u<i>`` where a name would clash with X or V)."""
    names = ["X", "V"]
    for i, nm in enumerate(tuple(state_names)[2:], start=2):
        names.append(nm if nm not in _RESULT_NAMES else f"u{i}")
    return names


#: Names the analyses' results use for other things (a state component called so is written
#: as u<i>).
_RESULT_NAMES = frozenset(
    "X V t n i j mode region visited period status sample point special crossing attractor "
    "label kind count fraction stable contact converged multiplier component row col "
    "eigenvalue equilibrium hopf angle unstable level branch".split())


def components(ds, prefix: str = "", suffix: str = ""):
    """The state vector of a result as one DataArray with a trailing dimension ``component``
    (coordinate: the model's state names, from the ``state_names`` attribute): the variables
    ``<prefix>X<suffix>``, ``<prefix>V<suffix>`` and those of the further components, e.g.
    ``components(ds)`` of ``simulate`` (t, component), ``components(ds, "orbit_")`` of
    ``poincare``, ``components(ds, suffix="_section")`` of ``periodic_orbit``. Results are
    written with one variable per component because CF gives a variable one unit."""
    import xarray as xr
    state = str(ds.attrs.get("state_names", "X V")).split()
    names = [f"{prefix}{nm}{suffix}" for nm in component_names(state)]
    missing = [nm for nm in names if nm not in ds.variables]
    if missing:
        from .errors import ParameterError
        raise ParameterError(f"components: the dataset has no variable {missing[0]!r} (give "
                             f"the prefix / suffix of the analysis' state variables)")
    dims = ds[names[0]].dims
    data = np.stack([ds[nm].values for nm in names], axis=-1)
    coords = {d: ds[d] for d in dims if d in ds.coords}
    return xr.DataArray(data, dims=dims + ("component",),
                        coords={**coords, "component": state}, name=f"{prefix}u{suffix}")


_X_NAME = re.compile(r"(^|_)(X|x0)($|_)")
_V_NAME = re.compile(r"(^|_)(V|v0)($|_)")


def xv_units(model) -> tuple:
    """The units of X and V: the model's ``state_units`` ("1", "1/s" where it names none)."""
    return (tuple(model.state_units) + ("1", "1/s")[len(model.state_units):])[:2]


def state_long_name(model, i: int) -> str:
    """The long name of state component i: the model's ``state_long_names``, else
    "displacement X" / "velocity dX/dt" / the component's variable name (``component_names``)."""
    if len(model.state_long_names) > i:
        return model.state_long_names[i]
    return ("displacement X", "velocity dX/dt")[i] if i < 2 else \
        component_names(model.state_names)[i]


def apply_state_units(ds, model):
    """The units of every variable and coordinate of ``ds`` holding X or V (``X``, ``max_X``,
    ``X_section``, ``orbit_V``, ``x0``, ...) from the model's ``state_units`` (the analyses
    write "1" and "1/s", the paper's dimensionless units), and, for a model whose first
    component is not called X (the bouncing ball's Z), that name in their long names
    ("largest Z over ...", "dZ/dt"); returns ``ds``."""
    ux, uv = xv_units(model)
    x = model.state_names[0]
    for name in list(ds.data_vars) + list(ds.coords):
        if _X_NAME.search(str(name)):
            ds[name].attrs["units"] = ux
        elif _V_NAME.search(str(name)):
            ds[name].attrs["units"] = uv
        else:
            continue
        long = ds[name].attrs.get("long_name")
        if x != "X" and isinstance(long, str):
            ds[name].attrs["long_name"] = re.sub(r"\bX\b", x, long.replace("dX/dt", f"d{x}/dt"))
    return ds
