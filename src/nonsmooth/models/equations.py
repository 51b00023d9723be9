"""Models written as equations: :func:`model_from_equations` turns the states, parameters, the
vector field of every mode and the switching surfaces with their transitions and resets,
written as expressions (strings or SymPy), into an ordinary :class:`~nonsmooth.models.base.Model`.

It derives what the model interface (:mod:`nonsmooth.models.base`) asks for by hand:

* the Jacobian of every mode's field (SymPy differentiation, common subexpressions shared);
* the guards: a surface affine in the state and in cos(omega t), sin(omega t) (coefficients
  may depend on the parameters) becomes an affine row, its coefficients read off exactly;
  any other smooth surface (a circle sqrt(X^2 + Y^2) = delta, a surface with t) becomes a
  *curved* guard, evaluated with its derived gradient (state and time) by the generated
  ``curved`` function. A surface that depends on neither the state nor the time is refused
  with one line naming it (one of the phase alone is a timed exit, e.g. a stuck mass
  released when the forcing turns);
* the closed form of linear modes: u' = A u + b + f_c cos(omega t) + f_s sin(omega t) with
  coefficients of the parameters only, any dimension and any stiffness (free flight, gravity,
  several coupled masses, a mass resting on a stop), propagated by the series of the
  augmented matrix exponential (``integrate.linmodes``), and the oscillator's own closed form
  (two states X, V with X' = V, V' = -k X - c V + F cos(omega t) + b, k > 0) where it applies:
  the ``exact`` method then propagates them exactly, as the built-in models do;
* ``transition`` (the first branch whose condition holds; resets evaluated with the values
  before the event) and ``initial`` (the first of the given (condition, mode) pairs that
  holds, else the first mode whose surfaces are all >= 0, else the first mode).

In expressions: the state and parameter names, ``t`` (the time within the forcing period,
0 <= t < T = 2 pi / omega, whatever the section phase: any function of it is a periodic
forcing),
``pi`` and the functions sin, cos, tan, exp, log, sqrt, sinh, cosh, tanh, asin, acos, atan,
atan2, Abs, sign, Min, Max, floor and Piecewise, and logistic(z) = 1 / (1 + exp(-z)) and
softplus(y) = log(1 + exp(y)) for regularised laws (evaluated and differentiated without
overflow). ``cos(omega*t)`` and ``sin(omega*t)`` are
read from the kernel's rotation, without a transcendental call.

The generated functions are written to a Python file in the package's cache directory, named
by a digest of the equations and the package version, and compiled by numba with its disk
cache: a model compiles once per machine (see the README for the times).
"""

from __future__ import annotations

import hashlib
import importlib.util
import json
import keyword
import os
import sys
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path

from .._version import __version__
from ..errors import ParameterError
from . import safe_name
from .base import Method, Model, Param

#: Functions allowed in expressions (SymPy names), and the two of regularised contact and
#: friction laws that the package adds: ``logistic(z) = 1 / (1 + exp(-z))`` and
#: ``softplus(y) = log(1 + exp(y))``, evaluated and differentiated without overflow (their
#: derivatives are logistic (1 - logistic) and logistic: a Jacobian written with exp would
#: give inf / inf far from the band).
FUNCTIONS = ("sin", "cos", "tan", "exp", "log", "sqrt", "sinh", "cosh", "tanh", "asin", "acos",
             "atan", "atan2", "Abs", "sign", "Min", "Max", "floor", "Piecewise")
SMOOTH_STEPS = ("logistic", "softplus")
#: Tolerances an ``exact`` method enforces where a mode has no closed form (as the built-in
#: models do): its pieces (DOP853 at this rtol) are then accurate to round-off, not to the
#: solver's rtol.
EXACT_RTOL, EXACT_ATOL = 1e-12, 1e-14
#: Names the generated code uses itself: a state or parameter may not take them.
_RESERVED = {"t", "pi", *FUNCTIONS, *SMOOTH_STEPS}  # (the generated code renames the rest)


@dataclass(frozen=True)
class Guard:
    """A switching surface of one mode: ``surface`` is >= 0 inside the mode and the mode is
    left when it turns negative (any smooth expression of the state, the parameters and t;
    affine ones are the kernel's fast case).

    ``to``: the mode entered (a name), or branches ``[(condition, mode), ...]`` or
    ``[(condition, mode, reset), ...]`` tried in order at the event: the first whose condition
    holds is taken ("True" for the last, catch-all branch; where none holds the mode is kept,
    without reset). ``reset``: new values of states at the event, ``{"V": "-r*V"}``, evaluated
    with the values before it (the default of every branch that gives none)."""

    surface: object
    to: object
    reset: dict | None = None


class _Default(str):
    """A default argument that a call can tell from the same value given explicitly."""


_OMEGA = _Default("omega")  # model_from_equations' omega unless a period is given


def model_from_equations(name: str, *, states, parameters, modes: dict | None = None,
                         guards: dict | None = None, initial=None, method: str = "exact",
                         methods: dict | None = None, omega: str | None = _OMEGA,
                         period: str | None = None, forcing_amplitude: str | None = None, description: str = "",
                         flow_is_homeomorphism: bool = False, closed_form: bool = True,
                         rtol: float | None = None, atol: float | None = None,
                         admissible=None, contact_modes=(), memory=None,
                         compile_now: bool = True, **model_kw) -> Model:
    """A :class:`Model` from equations (see the module documentation).

    ``states``: names, e.g. ``("X", "V")``. ``parameters``: ``{name: default}``,
    ``{name: Param(...)}`` / ``{name: dict(default=..., low=..., ...)}`` (keywords of
    :class:`Param`), or a sequence of :class:`Param`. ``modes``: ``{mode name: [d state/dt,
    ...]}`` (one expression per state, in order). ``guards``: ``{mode name: [Guard, ...]}`` (a
    tuple ``(surface, to)`` or ``(surface, to, reset)`` is read as a Guard). ``rtol``/``atol``:
    the tolerances the method enforces at most (default for an "exact" method with a mode
    that has no closed form: :data:`EXACT_RTOL`, :data:`EXACT_ATOL`). ``admissible``: a
    condition on the state and the parameters that a start must satisfy (e.g.
    ``"X <= delta"``). ``initial``:
    ``[(condition, mode), ...]`` classifying a state at t = 0 (default: the first mode whose
    surfaces hold). ``method``: the name of the method these equations define ("exact"
    for a non-smooth system, "smooth" for a regularised one). Several methods:
    ``methods={"exact": dict(modes=..., guards=..., initial=..., rtol=..., atol=...,
    description=..., flow_is_homeomorphism=...), "smooth": dict(...)}`` instead of ``modes``,
    ``guards``, ``initial`` and ``method``; the model's modes are those of all methods, in
    order of appearance (a mode of the same name is one mode). ``omega``: the forcing
    frequency parameter (None: a self-excited system without forcing, whose equations do not
    use t; see ``Model.omega``). ``period``: instead of ``omega``, the parameter that is the
    forcing's period T (a forcing of any periodic form written in t; ``cos(2*pi*t/T)`` and
    ``sin(2*pi*t/T)`` are the fast harmonic terms). ``contact_modes``: mode names that count as contact.
    ``memory``: named memory slots, ``{name: value at a fresh start}`` (an expression of the
    state, the parameters and t, e.g. ``{"Va": "V"}``) or a sequence of names (0 at a fresh
    start): values the trajectory carries from event to event (an entry velocity, which side
    of a union region holds). Expressions may use them; a reset may set them
    (``reset={"Va": "V"}``), and so may an ``initial`` entry ``(condition, mode, {"Va":
    "V"})``. A slot that some mode's field varies with, or that takes values varying with the
    state and is read by a reset, is continuous memory (the tangent dynamics carry it; its
    Jacobian column is derived); a surface may vary only with flags (slots set to constants:
    the tangent cannot follow a surface that moves with the state's memory), and a mode whose
    field uses a slot has no closed form. Other keywords
    (``state_units``, ``state_long_names``, ``presets``, ``contact_name``, ``lines``,
    ``references``, ``check``, ...) go to :class:`Model` as they are. ``compile_now``: compile
    and sample-check every method when the derivation is new, so that a malformed model fails
    at its definition (False, as the built-in models: at its first use; importing them then
    compiles nothing).

    Every mistake (an expression that does not parse, an unknown name, a surface that is not
    affine or has no gradient, a mode that does not exist) is one ParameterError naming the
    model and the place.

    The derivation is cached beside the generated functions, under a digest of the arguments
    that shape it and of the package's model and integrator sources: building the same model
    again (a command, a worker process) reads it back without SymPy and leaves the compile
    and the sample check, done when it was first built, to the first use of a method."""
    bad = lambda msg: ParameterError(f"model {name}: {msg}")  # noqa: E731
    if methods is None:
        methods = {method: dict(modes=modes, guards=guards, initial=initial, rtol=rtol,
                                atol=atol, description=description,
                                flow_is_homeomorphism=flow_is_homeomorphism,
                                admissible=admissible)}
    elif modes is not None or guards is not None or initial is not None or method != "exact" \
            or rtol is not None or atol is not None or flow_is_homeomorphism \
            or admissible is not None:
        raise bad("with methods={...}, give modes, guards, initial, rtol, atol, admissible "
                  "and flow_is_homeomorphism per method, not as arguments")
    from dataclasses import fields as _fields
    allowed = {f.name for f in _fields(Model)}
    for k in model_kw:
        if k not in allowed:
            raise bad(f"unknown keyword {k!r}")
    states = tuple(states)
    params = _parameters(parameters, bad)
    pnames = tuple(q.name for q in params)
    memory = _memory(memory, bad)
    if memory and "n_memory" in model_kw:
        raise bad("give memory={...} or n_memory, not both")
    mnames = tuple(memory)
    for nm in states + pnames + mnames:
        if not nm.isidentifier() or keyword.iskeyword(nm) or nm in _RESERVED:
            raise bad(f"{nm!r} cannot name a state, parameter or memory slot (reserved or not "
                      f"an identifier)")
    if len(set(states + pnames + mnames)) != len(states) + len(pnames) + len(mnames):
        raise bad("state, parameter and memory names must all differ")
    if memory:
        model_kw["n_memory"] = len(memory)
    if period is not None:
        if omega is not None and omega is not _OMEGA:
            raise bad("a forcing has a frequency (omega) or a period (period), not both")
        omega = None
        if period not in pnames:
            raise bad(f"the forcing period {period!r} must be a parameter")
    elif omega is not None and omega not in pnames:
        raise bad(f"the forcing frequency {omega!r} must be a parameter")
    omega = None if omega is None else str(omega)  # (a plain str from here on)
    mode_names = tuple(dict.fromkeys(m for spec in methods.values()
                                     for m in (spec.get("modes") or {})))
    if not mode_names:
        raise bad("at least one mode is needed")
    for mname, spec in methods.items():
        unknown = set(spec) - {"modes", "guards", "initial", "rtol", "atol", "description",
                               "flow_is_homeomorphism", "admissible"}
        if unknown:
            raise bad(f"method {mname}: unknown key {sorted(unknown)[0]!r}")
    key = _derivation_key(name, states, params, methods, omega, period, closed_form,
                          tuple(memory.items()) if memory else model_kw.get("n_memory"))
    derived = _cached_derivation(name, key)
    fresh = derived is None
    if fresh:
        import sympy as sp
        sym = {nm: sp.Symbol(nm, real=True) for nm in states + pnames + mnames}
        t = sp.Symbol("t", real=True)
        C, S = sp.Dummy("cos_omega_t", real=True), sp.Dummy("sin_omega_t", real=True)
        w = sym[omega] if omega is not None else 2 * sp.pi / sym[period] if period else None
        ctx = _Context(sp, sym, t, C, S, w, set(states), name)
        ctx.period = period
        ctx.memory = [sym[m] for m in mnames]
        ctx.memory_start = [ctx.parse(v, f"memory {m}") for m, v in memory.items()]
        for m, v in zip(mnames, ctx.memory_start):
            if v.free_symbols & set(ctx.memory):
                raise bad(f"memory {m}: a start value is an expression of the state, the "
                          f"parameters and t, not of memory")
        derived = {mname: _derive(sp, ctx, name, mname, spec, states, pnames, mode_names,
                                  closed_form, bad) for mname, spec in methods.items()}
    built = {mname: _method(name, mname, entry, pnames) for mname, entry in derived.items()}
    if isinstance(contact_modes, (tuple, list)):
        contact_modes = sum(1 << _mode_index(m, mode_names, bad) for m in contact_modes)
    model = Model(name=name, description=description or "a model written as equations",
                  parameters=params, state_names=states, mode_names=mode_names,
                  methods=built, omega=omega, period=period, forcing_amplitude=forcing_amplitude,
                  contact_modes=contact_modes, **model_kw)
    if fresh:
        for mname in built if compile_now else ():
            model.fns(mname)  # compile and sample-check now: a malformed model fails here
        _store_derivation(name, key, derived)
    return model


def _derivation_key(name, states, params, methods, omega, period, closed_form,
                    n_memory) -> str | None:
    """Digest of what a model's derivation and its sample check (at the parameters' defaults)
    depend on (None where an argument has no stable text, e.g. an object shown by its
    address)."""
    from .._numba_cache import USER_LAYER, source_digest
    text = repr((__version__, source_digest(USER_LAYER), name, states, params,
                 sorted((m, sorted(spec.items())) for m, spec in methods.items()), omega,
                 period, closed_form, n_memory))
    if " at 0x" in text:
        return None
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _folder(base: Path) -> Path:
    """Where generated functions and derivations live, beside numba's cache ``base``."""
    return base.parent / "equations" if base.name == "numba" else base / "equations"


def _write_atomic(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a file unique to this process, then rename it (an
    identical file written by another process at the same time is as good); OSError as is."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
    with os.fdopen(fd, "w") as fh:
        fh.write(text)
    os.replace(tmp, path)


def _derivation_path(name: str, key: str | None) -> Path | None:
    """The file of the derivation stored under ``key``; None without a key or a cache."""
    from .._numba_cache import cache_base
    base = cache_base() if key else None
    return None if base is None else _folder(base) / f"{safe_name(name)}_{key}.json"


def _cached_derivation(name: str, key: str | None) -> dict | None:
    """The derivation stored under ``key`` (see :func:`_store_derivation`), or None."""
    path = _derivation_path(name, key)
    try:
        got = json.loads(path.read_text()) if path is not None and path.is_file() else None
    except (OSError, ValueError):
        return None
    return got["methods"] if isinstance(got, dict) and got.get("key") == key else None


def _store_derivation(name: str, key: str | None, derived: dict) -> None:
    """Keep a derivation whose methods compiled and passed their sample check (an unwritable
    cache only means deriving again next time)."""
    path = _derivation_path(name, key)
    if path is None:
        return
    try:
        _write_atomic(path, json.dumps({"key": key, "methods": derived}))
    except OSError:
        pass


def _method(name, mname, entry, pnames) -> Method:
    """One method's :class:`Method` from its derivation (:func:`_derive`): the generated
    functions loaded, the rest as derived."""
    module = _load(f"{name}_{mname}", entry["source"])
    extra = {}
    if entry["admissible"] is not None:
        def admissible(u, params):
            return bool(module.admissible([float(x) for x in u],
                                          [float(getattr(params, k)) for k in pnames]))
        extra = {"admissible": admissible, "admissible_text": entry["admissible"]}
    return Method(module.field, module.jacobian, module.guards, module.transition,
                  module.initial, module.linear if entry["closed_form"] else None,
                  curved=module.curved if entry["curved"] else None,
                  closed_form=entry["closed_form"],
                  flow_is_homeomorphism=entry["flow_is_homeomorphism"],
                  modes=tuple(entry["modes"]), rtol=entry["rtol"], atol=entry["atol"],
                  continuous_memory=tuple(entry.get("continuous_memory", ())),
                  description=entry["description"], unused=tuple(entry.get("unused", ())),
                  **extra)


def _derive(sp, ctx, name, mname, spec, states, pnames, mode_names, closed_form, bad) -> dict:
    """One method's derivation: parse, derive and generate its functions' source; returns
    plain data (:func:`_method` builds the Method)."""
    n = len(states)
    own = tuple(spec.get("modes") or {})
    if not own:
        raise bad(f"method {mname}: at least one mode is needed")
    ctx.used = {s.name for v in ctx.memory_start for s in v.free_symbols}
    if ctx.omega is not None:  # (the forcing frequency: the kernel's, whatever the method)
        ctx.used.update(s.name for s in ctx.omega.free_symbols)
    fields = {}
    for mode, exprs in spec["modes"].items():
        exprs = list(exprs) if not isinstance(exprs, str) else [exprs]
        if len(exprs) != n:
            raise bad(f"mode {mode}: {len(exprs)} expressions for {n} states")
        fields[mode] = [ctx.parse(e, f"mode {mode}, d{states[i]}/dt")
                        for i, e in enumerate(exprs)]
    rows, branches, surfaces = {}, {}, []
    for mode, glist in (spec.get("guards") or {}).items():
        if mode not in own:
            raise bad(f"guards: unknown mode {mode!r} (modes: {', '.join(own)})")
        rows[mode], branches[mode] = [], []
        for j, g in enumerate(glist):
            g = g if isinstance(g, Guard) else Guard(*g)
            where = f"mode {mode}, surface {j}"
            surface = ctx.parse(g.surface, where)
            surfaces.append((where, surface))
            rows[mode].append(ctx.surface(surface, where))
            branches[mode].append(ctx.branches(g, where, own, mode_names))
    init = []
    for i, entry in enumerate(spec.get("initial") or ()):
        if not isinstance(entry, (tuple, list)) or len(entry) not in (2, 3):
            raise bad(f"initial, entry {i}: (condition, mode) or (condition, mode, {{memory: "
                      f"value}}), got {entry!r}")
        _mode_index(entry[1], own, bad)
        sets = ctx.memory_sets(entry[2] if len(entry) == 3 else None, f"initial, entry {i}")
        init.append((ctx.condition(entry[0], f"initial, condition {i}"),
                     mode_names.index(entry[1]), sets))
    cm = _continuous_memory(sp, ctx, fields, branches, init, surfaces, n, bad)
    # the closed form of linear modes: the oscillator's (n = 2, k > 0) where it applies, else
    # the general form (any n, any stiffness: ``integrate.linmodes``); a field that uses
    # memory has none (``linear`` sees the parameters only)
    linear = {m: (ctx.linear(fields[m]) if n == 2 else None, ctx.linear_general(fields[m]))
              for m in own if not any(f.has(q) for f in fields[m] for q in ctx.memory)
              } if closed_form else {}
    linear = {m: v for m, v in linear.items() if v[1] is not None}
    text = spec.get("admissible")
    cond = _admissible(ctx, text, bad) if text is not None else None
    # labels (``integrate.contract``): two modes of the same field that watch one curved
    # surface each, into each other, without a reset (a smoothed method's modes that only
    # name a side): nothing else can happen in either, so the crossing need not be located
    def pure(m):
        brs = branches.get(m, ())
        return len(brs) == 1 and not isinstance(rows[m][0], list) and len(brs[0]) == 1 \
            and brs[0][0][0] is sp.true and not brs[0][0][2]

    labels = set()
    for m in own:
        if pure(m):
            t = mode_names[branches[m][0][0][1]]
            if t != m and pure(t) and mode_names[branches[t][0][0][1]] == m and all(
                    sp.simplify(a - b) == 0 for a, b in zip(fields[m], fields[t])):
                labels.add((m, 0))
    try:
        source = _source(sp, ctx, states, pnames, mode_names, own, fields, rows, branches,
                         init, linear, cond, cm, labels)
    except Exception as exc:  # noqa: BLE001 - an expression SymPy cannot print as Python
        raise bad(f"method {mname}: cannot generate its functions "
                  f"({type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''})"
                  ) from None
    rtol, atol = spec.get("rtol"), spec.get("atol")
    if mname == "exact" and rtol is None and atol is None \
            and not all(m in linear for m in own):
        rtol, atol = EXACT_RTOL, EXACT_ATOL  # nonlinear modes of an exact method: DOP853, tight
    return {"source": source, "closed_form": bool(linear), "continuous_memory": cm,
            "curved": any(not isinstance(r, list) for rs in rows.values() for r in rs),
            "flow_is_homeomorphism": bool(spec.get("flow_is_homeomorphism", False)),
            "modes": [mode_names.index(m) for m in own],
            "rtol": None if rtol is None else float(rtol),
            "atol": None if atol is None else float(atol),
            "description": spec.get("description")
            or f"written as equations ({len(own)} mode{'' if len(own) == 1 else 's'})",
            "admissible": None if text is None else str(text),
            "unused": [k for k in pnames if k not in ctx.used]}


def _depends(sp, e, x) -> bool:
    """Whether expression e varies with the symbol x (a nonzero derivative: a Piecewise whose
    conditions alone use x does not)."""
    if not e.has(x):
        return False
    d = sp.diff(e, x)
    return not (d == 0 or sp.simplify(d) == 0)


def _continuous_memory(sp, ctx, fields, branches, init, surfaces, n, bad) -> list:
    """The memory slots the tangent dynamics must carry (``Method.continuous_memory``): those
    a field varies with, and those that take a value varying with the state (a reset or an
    initial value, through other such slots too) and that a reset reads (the saltation
    differentiates the transition). The other slots are flags (piecewise constant in the
    state). A surface may not vary with a slot that varies with the state: the saltation's
    time shift uses the surface's gradient in the state only."""
    mem = ctx.memory
    states = ctx.states
    resets = [(i, e) for brs in branches.values() for br in brs for _, _, rs in br
              for i, e in rs.items()]
    sets = [(n + j, e) for _, _, st in init for j, e in st.items()] + [
        (n + j, e) for j, e in enumerate(ctx.memory_start)]
    varying = set()  # slots whose values vary with the state
    changed = True
    while changed:
        changed = False
        for i, e in resets + sets:
            j = i - n
            if j >= 0 and j not in varying and any(
                    _depends(sp, e, x) for x in states + [mem[q] for q in varying]):
                varying.add(j)
                changed = True
    read = {j for j, m in enumerate(mem) if any(_depends(sp, e, m) for _, e in resets)}
    cm = sorted({j for j, m in enumerate(mem)
                 if any(_depends(sp, f, m) for fs in fields.values() for f in fs)}
                | (varying & read))
    for where, g in surfaces:
        moving = [mem[q].name for q in sorted(varying | set(cm)) if _depends(sp, g, mem[q])]
        if moving:
            raise bad(f"{where}: the surface varies with the memory slot {moving[0]!r}, which "
                      f"the tangent dynamics carry (a field varies with it, or it takes values "
                      f"that vary with the state): they cannot follow a surface that moves "
                      f"with it; a surface may use flags (slots set to constants that no "
                      f"field uses)")
    return cm


def _admissible(ctx, text, bad):
    """``admissible=`` of a method: a condition on the state and the parameters (no t) that
    every start must meet (the generated ``admissible(u, p)`` evaluates it)."""
    cond = ctx.condition(text, "admissible")
    if ctx.t in cond.free_symbols or ctx.C in cond.free_symbols or ctx.S in cond.free_symbols \
            or cond.free_symbols & set(ctx.memory):
        raise bad("admissible: a condition on the state and the parameters, without t or "
                  "memory")
    return cond


_STEPS: dict = {}


def _smooth_steps(sp) -> dict:
    """The SymPy functions ``logistic`` and ``softplus`` (made once: SymPy is imported late)."""
    if not _STEPS:
        class logistic(sp.Function):  # noqa: N801 - the name users write
            def fdiff(self, argindex=1):
                z = self.args[0]
                return logistic(z) * (1 - logistic(z))

        class softplus(sp.Function):  # noqa: N801
            def fdiff(self, argindex=1):
                return logistic(self.args[0])

        _STEPS.update(logistic=logistic, softplus=softplus)
    return dict(_STEPS)


_HELPERS = """
@numba.njit(cache=True, inline="always")
def _logistic(z):
    if z >= 0.0:
        return 1.0 / (1.0 + math.exp(-z))
    e = math.exp(z)
    return e / (1.0 + e)


@numba.njit(cache=True, inline="always")
def _softplus(y):
    return max(y, 0.0) + math.log1p(math.exp(-abs(y)))

"""


def _parameters(parameters, bad) -> tuple:
    if isinstance(parameters, dict):
        out = []
        for nm, v in parameters.items():
            if isinstance(v, Param):
                out.append(v if v.name == nm else Param(**{**v.__dict__, "name": nm}))
            elif isinstance(v, dict):
                out.append(Param(nm, **v))
            else:
                out.append(Param(nm, v))
        return tuple(out)
    out = tuple(parameters)
    if not all(isinstance(q, Param) for q in out):
        raise bad("parameters: a dict {name: default | Param | dict} or a sequence of Param")
    return out


def _memory(memory, bad) -> dict:
    """``memory=`` as {name: value at a fresh start} (a sequence of names: 0 each)."""
    if memory is None:
        return {}
    if isinstance(memory, str):
        memory = (memory,)
    try:
        out = dict(memory) if isinstance(memory, dict) else {m: 0 for m in memory}
    except TypeError:
        out = None
    if out is None or not all(isinstance(m, str) for m in out):
        raise bad("memory: a dict {name: value at a fresh start} or a sequence of names")
    return out


def _mode_index(m, mode_names, bad) -> int:
    if m not in mode_names:
        raise bad(f"unknown mode {m!r} (modes: {', '.join(mode_names)})")
    return mode_names.index(m)


class _Context:
    """Parsing and the derivations, for one model."""

    def __init__(self, sp, sym, t, C, S, omega, states, name):
        self.sp, self.sym, self.t, self.C, self.S = sp, sym, t, C, S
        self.states = [sym[k] for k in sym if k in states]
        self.omega, self.name = omega, name
        self.period = None  # the forcing period's parameter name, where the model has one
        self.memory = []  # memory slots' symbols (in slot order)
        self.memory_start = []  # their values at a fresh start
        self.local = {**sym, "t": t, "pi": sp.pi, **{f: getattr(sp, f) for f in FUNCTIONS},
                      **_smooth_steps(sp)}
        self.used = set()  # the names the expressions parsed so far use (``_derive`` resets it)

    def bad(self, msg):
        return ParameterError(f"model {self.name}: {msg}")

    def parse(self, text, where):
        sp = self.sp
        if isinstance(text, bool):
            return sp.true if text else sp.false
        if isinstance(text, (int, float)):
            return sp.Float(repr(text), 17) if isinstance(text, float) else sp.Integer(text)
        if isinstance(text, sp.Basic):
            expr = text.xreplace({s: self.local[s.name] for s in text.free_symbols
                                  if s.name in self.local})
        elif isinstance(text, str):
            from sympy.parsing.sympy_parser import parse_expr, standard_transformations
            try:
                expr = parse_expr(text, local_dict=dict(self.local),
                                  global_dict={"Integer": sp.Integer, "Float": sp.Float,
                                               "Rational": sp.Rational, "Symbol": sp.Symbol},
                                  transformations=standard_transformations)
            except Exception as exc:  # noqa: BLE001 - any parse failure is the user's text
                raise self.bad(f"{where}: cannot parse {text!r} ({type(exc).__name__})") from None
            if isinstance(expr, (tuple, list)) or not isinstance(expr, sp.Basic):
                raise self.bad(f"{where}: {text!r} is not an expression")
        else:
            raise self.bad(f"{where}: expected an expression (a string or SymPy), got {text!r}")
        known = set(self.sym.values()) | {self.t}
        unknown = sorted(s.name for s in expr.free_symbols if s not in known)
        if unknown:
            raise self.bad(f"{where}: unknown name {unknown[0]!r} (states and parameters"
                           f"{' and memory' if self.memory else ''}: "
                           f"{', '.join(k for k in self.sym)}; and t)")
        self.used.update(s.name for s in expr.free_symbols)
        for pw in expr.atoms(sp.Piecewise):
            if not any(c is sp.true for _, c in pw.args):
                raise self.bad(f"{where}: a Piecewise needs a last branch (value, True)")
        w, t = self.omega, self.t
        if w is None:
            if t in expr.free_symbols:
                raise self.bad(f"{where}: the model declares no forcing (omega=None), so its "
                               f"equations cannot use the time t")
            return expr
        return expr.subs({self.sp.cos(w * t): self.C, self.sp.sin(w * t): self.S})

    def condition(self, text, where):
        """A condition: an expression whose Python ``and`` / ``or`` / ``not`` and chained
        comparisons (``0 < X < 1``) are read as SymPy's And / Or / Not."""
        import ast
        sp = self.sp
        if not isinstance(text, str):
            return self.parse(text, where)
        try:
            tree = ast.parse(text.strip(), mode="eval").body
        except SyntaxError:
            raise self.bad(f"{where}: cannot parse {text!r} (SyntaxError)") from None

        def walk(node):
            if isinstance(node, ast.BoolOp):
                parts = [walk(v) for v in node.values]
                return sp.And(*parts) if isinstance(node.op, ast.And) else sp.Or(*parts)
            if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
                return sp.Not(walk(node.operand))
            if isinstance(node, ast.Compare) and len(node.ops) > 1:
                terms = [node.left, *node.comparators]
                return sp.And(*(walk(ast.Compare(left=terms[i], ops=[op],
                                                 comparators=[terms[i + 1]]))
                                for i, op in enumerate(node.ops)))
            if isinstance(node, ast.Constant) and isinstance(node.value, bool):
                return sp.true if node.value else sp.false
            if isinstance(node, ast.Compare) and isinstance(node.ops[0], (ast.Eq, ast.NotEq)):
                a, b = (self.parse(ast.unparse(x), where) for x in (node.left,
                                                                   node.comparators[0]))
                return sp.Eq(a, b) if isinstance(node.ops[0], ast.Eq) else sp.Ne(a, b)
            return self.parse(ast.unparse(node), where)
        return walk(tree)

    def surface(self, g, where):
        """An affine surface's row: coefficients [d/du_i ..., constant, cos, sin]; any other
        surface as its expression (a curved guard)."""
        sp = self.sp
        var = self.states + [self.C, self.S]
        if not (g.free_symbols & (set(var) | {self.t})) or all(
                sp.simplify(sp.diff(g, v)) == 0 for v in var + [self.t]):
            raise self.bad(f"{where}: the surface {g} has a zero gradient (it depends on "
                           f"neither the state nor the time)")
        def curved(g):
            if g.has(sp.Piecewise, sp.sign, sp.floor, sp.Abs, sp.Min, sp.Max):
                raise self.bad(f"{where}: the surface {g} is not smooth (Piecewise, sign, "
                               f"floor, Abs, Min or Max): write one surface per smooth piece")
            return g

        if self.t in g.free_symbols:
            return curved(g)
        coef = [sp.diff(g, v) for v in var]
        const = g.subs({v: 0 for v in var})
        rest = sp.simplify(g - sum((c * v for c, v in zip(coef, var)), const))
        if any(c.free_symbols & set(var) for c in coef) or rest.free_symbols & set(var) \
                or rest != 0:
            return curved(g)
        n = len(self.states)
        return coef[:n] + [const, coef[n], coef[n + 1]]

    def branches(self, g, where, own, mode_names):
        """[(condition, mode index, {state index: expression}), ...] of a guard (targets among
        the method's modes ``own``, indices among the model's ``mode_names``)."""
        to = g.to
        if isinstance(to, str):
            to = [("True", to, g.reset)]
        out = []
        for i, br in enumerate(to):
            if len(br) not in (2, 3):
                raise self.bad(f"{where}: a branch is (condition, mode) or (condition, mode, "
                               f"reset), got {br!r}")
            cond, mode = br[0], br[1]
            reset = br[2] if len(br) == 3 and br[2] is not None else g.reset or {}
            if mode not in own:
                raise self.bad(f"{where}: unknown mode {mode!r} (modes: {', '.join(own)})")
            cond = self.sp.true if cond in (True, "True") else self.condition(
                cond, f"{where}, condition {i}")
            names = [s.name for s in self.states] + [m.name for m in self.memory]
            rs = {}
            for k, v in reset.items():
                if k not in names:
                    raise self.bad(f"{where}: reset of {k!r}, which is neither a state nor a "
                                   f"memory slot")
                rs[names.index(k)] = self.parse(v, f"{where}, reset of {k}")
            out.append((cond, mode_names.index(mode), rs))
        return out

    def memory_sets(self, sets, where):
        """{slot index: expression} of an ``initial`` entry's memory values."""
        names = [m.name for m in self.memory]
        out = {}
        for k, v in (sets or {}).items():
            if k not in names:
                raise self.bad(f"{where}: {k!r} is not a memory slot"
                               + (f" (memory: {', '.join(names)})" if names else
                                  " (the model declares no memory=)"))
            out[names.index(k)] = self.parse(v, f"{where}, {k}")
        return out

    def linear_general(self, f):
        """(A, b, f_c, f_s) where the mode is u' = A u + b + f_c cos(omega t) + f_s sin(omega t)
        with coefficients of the parameters only, else None."""
        sp = self.sp
        var = self.states + [self.C, self.S]
        n = len(self.states)
        A, b, fc, fs = [], [], [], []
        for fi in f:
            fi = sp.expand(fi)
            coef = [sp.diff(fi, v) for v in var]
            if any(c.free_symbols & (set(var) | {self.t}) for c in coef):
                return None
            const = fi.subs({v: 0 for v in var})
            if const.free_symbols & {self.t}:
                return None
            if sp.simplify(fi - (sum((c * v for c, v in zip(coef, var)), const))) != 0:
                return None  # a step term (Piecewise, sign) has zero derivatives
            A.append(coef[:n])
            b.append(const)
            fc.append(coef[n])
            fs.append(coef[n + 1])
        return A, b, fc, fs

    def linear(self, f):
        """(k, c, b, F) where the mode is X' = V, V' = -k X - c V + F cos + b with constant
        coefficients (k > 0 is checked at run time), else None."""
        sp = self.sp
        X, V = self.states
        if sp.simplify(f[0] - V) != 0:
            return None
        a = sp.expand(f[1])
        var = [X, V, self.C]
        coef = [sp.diff(a, v) for v in var]
        if any(c.free_symbols & (set(var) | {self.S, self.t}) for c in coef):
            return None
        b = a.subs({v: 0 for v in var})
        if b.free_symbols & {self.S, self.t}:
            return None
        # an affine expression and nothing else (a step term, Piecewise in V say, has zero
        # derivatives but is not constant), and a stiffness that is not identically 0 (free
        # flight has no closed form of the oscillator)
        if sp.simplify(a - (sum((c * v for c, v in zip(coef, var)), b))) != 0 \
                or sp.simplify(coef[0]) == 0:
            return None
        return -coef[0], -coef[1], b, coef[2]


def _source(sp, ctx, states, pnames, mode_names, own, fields, rows, branches, init,
            linear, admissible=None, cm=(), labels=frozenset()) -> str:
    """The Python source of the seven model functions, and of ``admissible(u, p)`` (plain
    Python) where the method has that condition."""
    from sympy.printing.precedence import PRECEDENCE
    from sympy.printing.pycode import PythonCodePrinter

    n = len(states)
    names = {ctx.sym[k]: sp.Symbol(f"_x{i}") for i, k in enumerate(states)}
    names.update({ctx.sym[k]: sp.Symbol(f"_p{i}") for i, k in enumerate(pnames)})
    names.update({m: sp.Symbol(f"_m{j}") for j, m in enumerate(ctx.memory)})
    names.update({ctx.t: sp.Symbol("t"), ctx.C: sp.Symbol("c"), ctx.S: sp.Symbol("s")})
    class Printer(PythonCodePrinter):
        def _print_logistic(self, e):
            return f"_logistic({self._print(e.args[0])})"

        def _print_softplus(self, e):
            return f"_softplus({self._print(e.args[0])})"

        def _print_Pow(self, e, rational=False):
            # x**(k/2) with |k| > 1 (the Jacobian of sqrt(x**2 + y**2), a curved guard's
            # radius) as x**(k // 2) * sqrt(x): numba's pow(x, 1.5) costs several sqrt
            b, x = e.args
            if x.is_Rational and x.q == 2 and abs(x.p) > 1:
                k = abs(x.p) // 2
                lead = self._print(b ** k) if k > 1 else self.parenthesize(b, PRECEDENCE["Pow"])
                r = f"{lead}*math.sqrt({self._print(b)})"
                return f"({r})" if x.p > 0 else f"(1/({r}))"
            return super()._print_Pow(e, rational=rational)

    printer = Printer({"fully_qualified_modules": True, "standard": "python3"})

    def plain(e):
        """Heaviside (the derivative of Max/Min) as a Piecewise the printer writes; the
        derivatives of sign, floor and ceiling (zero almost everywhere) as 0."""
        e = sp.sympify(e).xreplace(names)
        e = e.replace(sp.Heaviside, lambda x, *h: sp.Piecewise((0, x < 0), (1, True)))
        e = e.replace(sp.DiracDelta, lambda *a: sp.Integer(0))
        return e.replace(lambda x: isinstance(x, sp.Derivative)
                         and isinstance(x.expr, (sp.floor, sp.ceiling, sp.sign)),
                         lambda x: sp.Integer(0))

    def code(e):
        e = plain(e)
        if e is sp.true:
            return "True"
        if e is sp.false:
            return "False"
        return printer.doprint(e)

    unpack_p = [f"    _p{i} = p[{i}]" for i in range(len(pnames))]
    unpack_u = [f"    _x{i} = u[{i}]" for i in range(n)]
    unpack_m = [f"    _m{j} = mem[{j}]" for j in range(len(ctx.memory))]
    # t: the time within the forcing period, 0 <= t < T, whatever the section phase (the
    # kernel's periods run from t_s = phase / omega, so t < t_s + T < 2 T)
    # (a model without forcing: the slot its packed parameters append, its time unit's 1)
    # (a model with a period parameter: T is that parameter)
    if ctx.period:
        T_of_p = f"p[{pnames.index(ctx.period)}]"
        omega_of_p = f"(2.0 * math.pi / {T_of_p})"
    else:
        iw = pnames.index(ctx.omega.name) if ctx.omega is not None else len(pnames)
        omega_of_p = f"p[{iw}]"
        T_of_p = f"2.0 * math.pi / {omega_of_p}"
    exprs = [e for f in fields.values() for e in f] + [
        e for c, _, sets in init for e in (c, *sets.values())] + list(ctx.memory_start) + [
        e for brs in branches.values() for br in brs for c, _, rs in br
        for e in (c, *rs.values())] + [
        r for rs in rows.values() for r in rs if not isinstance(r, list)]
    uses_t = any(ctx.t in sp.sympify(e).free_symbols for e in exprs)
    wrap_t = [f"    _T = {T_of_p}", "    if t >= _T:", "        t -= _T"] \
        if uses_t else []

    def by_mode(body_of, indent="    ", default="return 0"):
        out = []
        for m, mname in enumerate(mode_names):
            body = body_of(mname) if mname in own else []
            if body:
                out.append(f"{indent}{'if' if not out else 'elif'} mode == {m}:")
                out += [f"{indent}    {ln}" for ln in body]
        return out + [f"{indent}{default}"]

    def cse_lines(exprs, targets):
        exprs = [plain(e) for e in exprs]
        if any(e.has(sp.Piecewise) for e in exprs):  # branches must not be evaluated early
            reps, red = [], exprs
        else:
            reps, red = sp.cse(exprs, symbols=sp.numbered_symbols("_w"))
        out = [f"{v} = {printer.doprint(e)}" for v, e in reps]
        return out + [f"{tg} = float({printer.doprint(e)})" for tg, e in zip(targets, red)]

    src = ["# generated by nonsmooth.models.equations: do not edit", "import math", "",
           "import numba", _HELPERS]
    src += ["def field(mode, t, c, s, u, p, mem, du):", *wrap_t, *unpack_u, *unpack_p,
            *unpack_m]
    src += by_mode(lambda m: cse_lines(fields[m], [f"du[{i}]" for i in range(n)])
                   + ["return 0"])
    src += ["", "", "def jacobian(mode, t, c, s, u, p, mem, J):", *wrap_t, *unpack_u,
            *unpack_p, *unpack_m]
    X = [ctx.sym[k] for k in states]
    # the columns of the state, then those of the continuous memory slots (n + slot)
    cols = [(j, x) for j, x in enumerate(X)] + [(n + q, ctx.memory[q]) for q in cm]
    src += by_mode(lambda m: cse_lines([sp.diff(f, x) for f in fields[m] for _, x in cols],
                                       [f"J[{i}, {j}]" for i in range(n) for j, _ in cols])
                   + ["return 0"])

    def guard_body(m):
        out = []
        for k, row in enumerate(rows.get(m, ())):
            cols = list(range(n)) + [n, n + 1, n + 2]
            if isinstance(row, list):
                out += [f"G[{k}, {col}] = float({code(v)})" for col, v in zip(cols, row)]
            else:  # curved (``models.oscillator.curved_row``; ``label_row``)
                out += [f"G[{k}, {col}] = 0.0" for col in cols if col != n]
                out += [f"G[{k}, {n}] = math.nan"]
                if (m, k) in labels:
                    out += [f"G[{k}, {n + 1}] = 1.0"]
        return out + [f"return {len(rows.get(m, ()))}"] if out else []

    src += ["", "", "def guards(mode, p, mem, G):", *unpack_p, *unpack_m]
    src += by_mode(guard_body)

    def curved_body(m):
        # g, its gradient in the state and its partial time derivative at fixed u (cos and
        # sin(omega t) turn with t: d/dt = d/dt + omega (-s d/dc + c d/ds))
        out = []
        w = ctx.omega if ctx.omega is not None else sp.Integer(0)
        for k, row in enumerate(rows.get(m, ())):
            if isinstance(row, list):
                continue
            dt = sp.diff(row, ctx.t) + w * (-ctx.S * sp.diff(row, ctx.C)
                                            + ctx.C * sp.diff(row, ctx.S))
            exprs = [row] + [sp.diff(row, x) for x in X] + [dt]
            lines = cse_lines(exprs, ["_g"] + [f"grad[{i}]" for i in range(n + 1)])
            out += [f"if k == {k}:"] + [f"    {ln}" for ln in lines] + ["    return _g"]
        return out + ["return math.nan"] if out else []

    src += ["", "", "def curved(mode, k, t, c, s, u, p, mem, grad):", *wrap_t, *unpack_u,
            *unpack_p, *unpack_m]
    src += by_mode(curved_body, default="return math.nan")

    def transition_body(m):
        out = []
        for k, brs in enumerate(branches.get(m, ())):
            out.append(f"{'if' if not out else 'elif'} k == {k}:")
            for cond, new, reset in brs:
                out.append(f"    if {code(cond)}:")
                tmp = [f"        _r{i} = float({code(e)})" for i, e in reset.items()]
                out += tmp + [f"        u[{i}] = _r{i}" if i < n else f"        mem[{i - n}] = _r{i}"
                              for i in reset] + [f"        return {new}"]
        return out + ["return mode"] if out else []

    src += ["", "", "def transition(mode, k, t, c, s, u, p, mem):", *wrap_t, *unpack_u,
            *unpack_p, *unpack_m]
    src += by_mode(transition_body, default="return mode")

    src += ["", "", "def initial(c, s, u, p, mem):",
            f"    t = (math.atan2(s, c) % (2.0 * math.pi)) / {omega_of_p}", *unpack_u, *unpack_p]
    # a fresh start: every memory slot at its start value, then the entries' own values
    src += [f"    mem[{j}] = float({code(v)})" for j, v in enumerate(ctx.memory_start)]
    src += unpack_m
    for cond, m, sets in init:
        src += [f"    if {code(cond)}:"] + [f"        mem[{j}] = float({code(v)})"
                                            for j, v in sets.items()] + [f"        return {m}"]
    for m, mname in enumerate(mode_names):
        if mname not in own:
            continue
        tests = []
        for row in rows.get(mname, ()):
            g = sum((row[i] * X[i] for i in range(n)), sp.Integer(0)) + row[n] \
                + row[n + 1] * ctx.C + row[n + 2] * ctx.S if isinstance(row, list) else row
            tests.append(f"({code(g)}) >= 0.0")
        src.append(f"    if {' and '.join(tests) or 'True'}:\n        return {m}")
    src += [f"    return {mode_names.index(own[0])}"]

    def linear_body(m):
        if m not in linear:
            return []
        osc, (A, b, fc, fs) = linear[m]
        out = []
        if osc is not None:  # the oscillator's closed form where k > 0
            out += [f"out[{i}] = float({code(v)})" for i, v in enumerate(osc)]
            out += ["if out[0] > 0.0 and out[1] >= 0.0:", "    return 1"]
        flat = [a for row in A for a in row] + list(b) + list(fc) + list(fs)
        return out + [f"out[{i}] = float({code(v)})" for i, v in enumerate(flat)] + ["return 2"]

    src += ["", "", "def linear(mode, p, out):", *unpack_p]
    src += by_mode(linear_body)
    if admissible is not None:
        src += ["", "", "def admissible(u, p):", *unpack_u, *unpack_p,
                f"    return {code(admissible)}"]
    return "\n".join(src) + "\n"


def _load(name: str, source: str):
    """Write ``source`` to the cache directory (named by its digest) and import it: numba
    caches the compiled functions of a module with a file."""
    from .._numba_cache import cache_base
    digest = hashlib.sha256((__version__ + source).encode()).hexdigest()[:16]
    safe = safe_name(name)
    base = cache_base()
    if base is None:
        warnings.warn(f"model {name}: no writable cache directory; its functions compile on "
                      f"every run", stacklevel=3)
        base = Path(tempfile.mkdtemp(prefix="nonsmooth-eq-"))
    folder = _folder(base)
    path = folder / f"{safe}_{digest}.py"
    try:
        if not path.exists() or path.read_text() != source:
            _write_atomic(path, source)
    except OSError as exc:
        raise ParameterError(f"model {name}: cannot write its generated functions to "
                             f"{folder} ({exc.strerror or exc})") from None
    modname = f"nonsmooth_equations_{safe}_{digest}"
    if modname in sys.modules:
        return sys.modules[modname]
    spec = importlib.util.spec_from_file_location(modname, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[modname] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[modname]
        raise
    return module
