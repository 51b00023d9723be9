"""Models: non-smooth forced systems as data plus small compiled functions.

``nonsmooth.models()`` lists the built-in models, ``nonsmooth.model(name)`` returns one (a
:class:`~nonsmooth.models.base.Model`), ``model.params(**values)`` validates its parameters.
A user model is a :class:`Model` built in a Python script; ``model("path/to/file.py:NAME")``
loads it (``NAME`` defaults to ``MODEL``). The contract a model implements is in
:mod:`nonsmooth.models.base`; one module per built-in model: ``support`` (the paper's
oscillator with a spring-damper support across a gap), ``two_sided``, ``impact``,
``stick_slip``.
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import os
import sys
import types

from .._numba_cache import configure as _configure_cache

_configure_cache()  # before any compiled module of this package is imported

from ..errors import ParameterError  # noqa: E402
from .base import BUILTIN, Method, Model, ModelParams, Param, param_index  # noqa: E402

__all__ = ["Model", "Method", "Param", "ModelParams", "param_index", "model", "models",
           "BUILTIN"]

_USER: dict = {}

#: the models this process has used (a ``Model`` given to ``model``, or loaded from a file),
#: by name: a result names its model only by name, and a figure drawn in the same process
#: finds a user's model here (``used``)
_USED: dict = {}


def used(name: str):
    """The model called ``name`` that this process used last (``model``), or None."""
    return _USED.get(name)


def models() -> tuple:
    """Names of the built-in models."""
    return tuple(BUILTIN)


def model(name) -> Model:
    """The model called ``name`` (built-in), or ``"path/to/file.py:NAME"`` (a ``Model`` named
    ``NAME``, default ``MODEL``, defined in a user's script), or a ``Model`` itself."""
    if isinstance(name, Model):
        _USED[name.name] = name
        return name
    if not isinstance(name, str) or not name:
        raise ParameterError(f"model: expected a model name, got {name!r}")
    if name in BUILTIN:
        return importlib.import_module(BUILTIN[name]).MODEL
    path, attr = _split_source(name)
    if path.endswith(".py"):
        m = _load_user(path, attr or "MODEL")
        _USED[m.name] = m
        return m
    raise ParameterError(f"model: unknown model {name!r} (built-in: {', '.join(BUILTIN)}; or "
                         f"path/to/file.py:NAME for your own)")


def _is_drive(name: str) -> bool:
    return len(name) > 1 and name[1] == ":" and name.count(":") == 1


def _split_source(name: str) -> tuple[str, str]:
    """(path, NAME) of a model given as ``path.py:NAME`` (NAME "" where it is not given)."""
    path, _, attr = name.partition(":") if name.count(":") and not _is_drive(name) else \
        (name, "", "")
    return path, attr


def safe_name(text: str) -> str:
    """``text`` with every character but letters and digits replaced by ``_``: a name for the
    modules and cache files of users' models."""
    return "".join(ch if ch.isalnum() else "_" for ch in text)


def file_digest(source: str) -> str | None:
    """sha1 (16 hex digits) of the contents of a model's file (``path.py[:NAME]``, e.g. a
    ``Model.source``), or None where it cannot be read."""
    try:
        with open(_split_source(source)[0], "rb") as fh:
            return hashlib.sha1(fh.read()).hexdigest()[:16]
    except OSError:
        return None


def _load_user(path: str, attr: str) -> Model:
    full = os.path.abspath(path)
    key = (full, attr)
    if key in _USER:
        return _USER[key]
    if not os.path.isfile(full):
        raise ParameterError(f"model: no such file {path!r}")
    # the module's name comes from the file's name and contents; its numba functions are
    # cached under that name (``_numba_cache.register_user_file``), whatever folder it is in
    modname = f"nonsmooth_user_model_{safe_name(os.path.basename(full))}_{file_digest(full)}"
    from .._numba_cache import register_user_file
    register_user_file(full, modname)
    spec = importlib.util.spec_from_file_location(modname, full)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[modname] = mod
    try:
        spec.loader.exec_module(mod)
    except ParameterError:
        raise
    except Exception as exc:
        raise ParameterError(f"model: {path} failed to load: {type(exc).__name__}: "
                             f"{str(exc).splitlines()[0] if str(exc) else ''}") from None
    obj = getattr(mod, attr, None)
    if not isinstance(obj, Model):
        raise ParameterError(f"model: {path} defines no Model named {attr!r}")
    # compile and sample-check every method now: a malformed model fails here, with one
    # ParameterError naming the problem, before any command computes with it
    if obj.source == "built-in":
        object.__setattr__(obj, "source", f"{full}:{attr}")
    for method in obj.methods:
        obj.fns(method)
    _USER[key] = obj
    return obj


def __getattr__(name: str):
    """The built-in models' modules as attributes (``nonsmooth.models.support``), loaded on
    first use."""
    if name in BUILTIN:
        return importlib.import_module(BUILTIN[name])
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class _CallablePackage(types.ModuleType):
    """``nonsmooth.models`` is this package and, called, lists the built-in models."""

    def __call__(self):
        return models()


sys.modules[__name__].__class__ = _CallablePackage
