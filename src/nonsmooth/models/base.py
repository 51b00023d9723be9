"""The model interface: what a non-smooth system declares so that every kernel, analysis, plot
and CLI command of ``nonsmooth`` runs on it.

A model is plain data plus a few small compiled functions (numba ``cfunc`` s with the fixed
signatures of :mod:`nonsmooth.integrate.contract`). It declares

* **parameters** (:class:`Param`): names, defaults, allowed ranges, units, long names and a
  plot symbol; a cross-field ``check`` for constraints between parameters; named ``presets``.
  Compiled code reads a parameter by an index derived from the names in one place
  (:func:`param_index`), never by a hard-coded position;
* the **forcing**: harmonic with frequency ``omega`` (a parameter name); the period
  T = 2 pi / omega frames time (output intervals, the stroboscopic section at t = t_s + kT, and
  the local time that restarts at t_s every period; t_s = section_phase / omega, 0 by
  default, so t runs over [t_s, t_s + T)). Functions receive t and (c, s) = (cos omega t,
  sin omega t), so they never evaluate a cosine. A forcing of any other periodic form names
  its **period** instead (``omega=None, period="T"``, a parameter): T frames time as above,
  (c, s) = (cos 2 pi t / T, sin 2 pi t / T), and the functions compute the forcing from t in
  [t_s, t_s + T) (several harmonics, a pulse train: modes whose guards are affine in c and s
  switch exactly where a pulse starts and ends). A self-excited system may declare no forcing
  (``omega=None``): its time unit is then 2 pi (c, s are cos t, sin t and mean nothing), the
  stroboscopic analyses refuse it in one line, and it is studied on section surfaces
  (``limit_cycle``, ``surface_basins``, ``equilibria``, see :mod:`nonsmooth.analysis.autonomous`);
* the **state** u of dimension n >= 2 (``state_names``; u[0] is the displacement X that
  analyses and plots show, u[1] its rate V), and ``n_memory`` slots of discrete memory ``mem``
  (e.g. the entry velocity X_dot_a of the paper's eq. 13a) that transitions may write;
* **modes** (``mode_names``, at most 8): each mode has a smooth vector field and its Jacobian;
* per **method** (:class:`Method`: ``"smooth"`` for a switch model with band eta, ``"exact"``
  for the non-smooth system, event-driven), the functions

  ``field(mode, t, c, s, u, p, mem, du) -> 0``
      du/dt in ``mode`` (write du[0:n]). Fields must extend smoothly past their mode's
      borders: a step is taken with the field of the current mode held fixed.
  ``jacobian(mode, t, c, s, u, p, mem, J) -> 0``
      d field / du (write J[0:n, 0:n]); checked against finite differences at definition.
  ``guards(mode, p, mem, G) -> n_g``
      the switching surfaces watched in ``mode``, as affine rows: surface k is
      g_k = G[k, :n] . u + G[k, n] + G[k, n+1] cos(omega t) + G[k, n+2] sin(omega t), and
      **every g_k >= 0 inside the mode**; the mode is left through k when g_k turns negative.
      (Affine in the state and the forcing covers gaps, velocity surfaces and friction
      limits; ``mem`` may select which surfaces are active.)
  ``transition(mode, k, t, c, s, u, p, mem) -> new_mode``
      called at the located crossing of surface k: the new mode; may reset u in place (an
      impact law) and write mem; may return ``mode`` itself (a reset-only event). Physical
      chatter must be resolved here (e.g. switch to a sticking mode when the impact velocity
      is negligible); the kernel reports ``status.ZENO`` for a model that does not.
  ``initial(c, s, u, p, mem) -> mode``
      the mode of a state at t = 0 (and its memory).
  ``curved(mode, k, t, c, s, u, p, mem, grad) -> g`` (optional)
      guards of any smooth form: a row that ``guards`` marks curved (``curved_row(G, k)``,
      from ``nonsmooth.models``) is g_k = curved(mode, k, ...), with its gradient written to
      grad[0:n] (d g / d u) and grad[n] (d g / d t at fixed u); a rotor rubbing a circular
      stator has g = (delta^2 - x^2 - y^2) / (2 delta) >= 0 in free flight. Curved guards
      are located on the step's interpolant like affine ones, grazing dips included (the
      true g is evaluated at the interpolant's critical points), and their gradient enters
      the saltation matrix; a mode with a curved guard is not taken in the oscillator's closed
      form (a general linear mode, kind 2 of ``linear``, is). ``label_row(G, k)`` marks a
      curved surface a *label*: the mode across it has the same field, the transition
      resets nothing and it is the only surface of both modes (a smoothed method's modes
      that only name a side); the kernel then
      switches the mode at the first step end past it instead of locating the crossing
      (checked at the sample point; ``model_from_equations`` marks such surfaces itself).
  ``linear(mode, p, out) -> 0, 1 or 2`` (optional)
      1 (n = 2) if the mode is X'' + c X' + k X = F cos(omega t) + b with k > 0, c >= 0 (out[0:4] =
      k, c, b, F); 2 (any n, any stiffness) if it is u' = A u + b + f_c cos(omega t) +
      f_s sin(omega t) with constant coefficients (out[0:n*n] = A row-major, then b, f_c,
      f_s, n each; ``out`` has max(4, n^2 + 3n) slots): with ``closed_form=True`` the method then propagates it in closed form
      (the oscillator's formulas, or the series of the augmented matrix exponential,
      :mod:`nonsmooth.integrate.linmodes`). A general row with n = 2 that is the oscillator
      (X' = V, V' = -k X - c V + b + f_c cos + f_s sin, k > 0 and c >= 0, or free flight,
      k = c = 0) takes the oscillator's formulas too (``integrate.pwlinear``).

* what analyses and plots need: ``contact(params, mask, max_X, min_X)`` (does an orbit with
  this visited-mode mask and these extremes of X count as "in contact", named
  ``contact_name``; default: a mode of the bit mask ``contact_modes`` visited; ``contact_label``
  a short name of those modes in tables, e.g. ``Gamma+``), ``mode_long_name`` what a mode code
  is in result files (default "mode"; the paper's model: "region of eq. 14"),
  ``contact_level(params)`` (the X at which contact starts, for the contact onset omega_a of
  ``resonance_curve``; None where it has no meaning), ``lines(params, method)`` (values of X to draw, with labels;
  ``params`` may be None when a result's parameters cannot be read), display data for figures
  and the CLI (``mode_labels``: mathtext legend labels per mode, default ``mode_names``;
  ``axis_labels``: mathtext axis labels of the state components, default ``state_names``;
  ``line_labels``: mathtext for the labels of ``lines``; ``mode_word``: what the modes are
  called, e.g. "regions") and, per
  method, ``flow_is_homeomorphism`` (false where trajectories merge, e.g. in sticking: basins
  then never use the certified early labelling, which assumes an injective map).

From these, the compiled generic kernel (:mod:`nonsmooth.integrate.hybrid`: RKF45 with located
switches and resets, closed-form pieces for linear modes) integrates the model, and
``simulate``, ``poincare``, ``bifurcation_diagram``, ``resonance_curve``, ``basins``,
``eta_study`` and the CLI work for it. The functions are compiled once (``cfunc``,
``cache=True``) and cached on disk like the built-in kernels. A built-in model may also name a
specialised kernel (``Method.kernel``) compiled with its functions inlined.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field as _field
from typing import Callable

import numpy as np

from .._builtin import BUILTIN, DEFAULT_MODEL  # noqa: F401 - the registry's names
from ..errors import ParameterError

#: Kernel codes of :func:`nonsmooth.kernels.run`: the generic kernel, and the specialised
#: kernels of the built-in ``support`` model.
KERNEL_GENERIC = 2
KERNEL_SUPPORT_SMOOTH = 0
KERNEL_SUPPORT_EXACT = 1

MAX_MODES = 8


# ---- parameters ------------------------------------------------------------------------------
@dataclass(frozen=True)
class Param:
    """One named parameter: default, allowed interval (``low``/``high``, open or closed ends),
    units, long name and plot symbol (matplotlib mathtext)."""

    name: str
    default: float | None = None
    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False
    high_open: bool = False
    units: str = "1"
    long_name: str = ""
    symbol: str = ""

    @property
    def range_text(self) -> str:
        """The allowed range as text, e.g. ``0 < eta < 0.5``."""
        lo = None if self.low == -math.inf else f"{self.low:g} {'<' if self.low_open else '<='} "
        hi = None if self.high == math.inf else f" {'<' if self.high_open else '<='} {self.high:g}"
        if lo is None and hi is None:
            return "any finite value"
        return f"{lo or ''}{self.name}{hi or ''}"

    def check(self, value) -> float:
        """``value`` as a float in range, else a one-line ParameterError naming the field."""
        if isinstance(value, (bool, np.bool_)):
            raise ParameterError(f"{self.name}: expected a number, got {value!r}")
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise ParameterError(f"{self.name}: expected a number, got {value!r}") from None
        if not math.isfinite(v):
            raise ParameterError(f"{self.name}: must be finite, got {v!r} "
                                 f"(allowed: {self.range_text})")
        bad_lo = v <= self.low if self.low_open else v < self.low
        bad_hi = v >= self.high if self.high_open else v > self.high
        if bad_lo or bad_hi:
            raise ParameterError(f"{self.name}: must satisfy {self.range_text}, got {v:g}")
        return v


def param_index(params) -> dict:
    """name -> position in the packed parameter array: the one place that fixes the layout."""
    return {p.name: i for i, p in enumerate(params)}


class ParamsBase:
    """Marker base of a model's validated parameters (:class:`ModelParams`); ``params.model``
    is their model."""

    __slots__ = ()


class ModelParams(ParamsBase):
    """Validated, immutable parameter values of one model (``model.params(**values)``).

    Values are attributes (``p.omega``); ``pack()`` gives the float64 array the kernels read,
    in the order of ``model.param_names``."""

    __slots__ = ("_model", "_values")

    def __init__(self, model: "Model", **values):
        object.__setattr__(self, "_model", model)
        object.__setattr__(self, "_values", model.validate(values))

    # mapping-like access
    def __getattr__(self, name):
        try:
            return self._values[name]
        except KeyError:
            raise AttributeError(name) from None

    def __setattr__(self, name, value):
        raise AttributeError("parameters are immutable; use replace(...)")

    def __eq__(self, other):
        return (isinstance(other, ModelParams) and other.model is self.model
                and other.as_dict() == self.as_dict())

    def __hash__(self):
        return hash((self.model.name, tuple(self.as_dict().items())))

    def __repr__(self):
        inner = ", ".join(f"{k}={v!r}" for k, v in self.as_dict().items())
        return f"{self.model.name}.params({inner})"

    @property
    def model(self) -> "Model":
        return self._model

    def as_dict(self) -> dict:
        return dict(self._values)

    def replace(self, **changes) -> "ModelParams":
        """A copy with some values changed (validated again)."""
        return self.model.params(**{**self.as_dict(), **changes})

    def pack(self) -> np.ndarray:
        """The values in the order of ``model.param_names``; a model without forcing
        gets one more slot, its time unit's frequency 1 (``frame_index``)."""
        vals = [self._values[n] for n in self.model.param_names]
        if self.model.autonomous:
            vals.append(1.0)
        return np.array(vals, dtype=np.float64)

    @property
    def period(self) -> float:
        """Forcing period T = 2 pi / omega, or the value of the model's ``period`` parameter
        (a model without forcing: its time unit 2 pi)."""
        m = self.model
        if m.period is not None:
            return float(self._values[m.period])
        if m.omega is None:
            return 2.0 * math.pi
        return 2.0 * math.pi / self._values[m.omega]

    def attrs(self) -> dict:
        """Flat netCDF attributes: ``model`` and ``param_<name>``."""
        return {"model": self.model.name,
                **{f"param_{k}": float(v) for k, v in self.as_dict().items()}}


# ---- methods and models ----------------------------------------------------------------------
@dataclass(frozen=True)
class Method:
    """How one method (``"smooth"`` or ``"exact"``) of a model is integrated.

    ``field``, ``jacobian``, ``guards``, ``transition``, ``initial``, ``linear``, ``curved``:
    plain Python functions that numba can compile with the signatures of ``integrate.contract`` (see the
    module docstring). ``closed_form``: propagate the modes ``linear`` declares in closed
    form. ``modes``: the mode codes this method uses. ``rtol``/``atol``: tolerances it
    enforces at most (the exact method of a model with nonlinear modes integrates those at a
    tight tolerance). ``kernel``: a specialised kernel code of a built-in model, else the
    generic kernel; ``variant``: which variant of its method that kernel runs (``opts`` slot
    ``OPT_VARIANT``; the generic kernel ignores it). ``continuous_memory``: the memory slots that are continuous functions of
    the state (e.g. an entry velocity), as opposed to discrete flags; tangent dynamics carry
    them, and ``jacobian`` must give the field's derivative with respect to slot i in column
    n + i of J (J has n + n_memory columns, the memory ones zeroed before each call).
    ``admissible``: None, or a plain Python function ``admissible(u, params) -> bool`` telling
    whether a state may start a trajectory (a ball above its table), with ``admissible_text``
    saying what it requires; analyses refuse other starts in one line. ``dop853``: the generic
    kernel integrates modes without closed form by DOP853 where the tolerance is below 1e-10
    (``integrate.rk8``); False keeps the RKF45 there, for a method whose such modes are crossed
    in a few short steps (a thin band), where 6 stages a step cost less than 15.
    ``evidence``: None, or another method of the model that solves the same equations (the
    same field, Jacobian, guards, transitions, initial classification, modes and memory)
    more precisely and faster; the lambda1 evidence of sweeps (``bifurcation_diagram``,
    ``poincare``, ``basins``, ``parameter_map``) is then computed by that method's tangent
    dynamics from this method's attractor states (support's and two_sided's ``smooth``:
    ``smooth_closed_form``: table3's bifurcation diagram's evidence in 0.09 s instead of the
    RKF45 tangent's 0.83 s). lambda1 is
    a property of the equations, not of the integrator; an explicit ``lyapunov_spectrum``
    or ``floquet`` keeps the method asked for. ``unused``: the parameters this method does
    not read (the exact method's of a smoothed contact: eta, k_c); figures leave them out of
    their titles (results still carry every parameter)."""

    field: Callable
    jacobian: Callable
    guards: Callable
    transition: Callable
    initial: Callable
    linear: Callable | None = None
    closed_form: bool = False
    flow_is_homeomorphism: bool = False
    modes: tuple = ()
    description: str = ""
    rtol: float | None = None
    atol: float | None = None
    kernel: int = KERNEL_GENERIC
    continuous_memory: tuple = ()
    variant: int = 0
    admissible: Callable | None = None
    admissible_text: str = ""
    curved: Callable | None = None
    dop853: bool = True
    evidence: str | None = None
    unused: tuple = ()


def _no_linear(mode, p, out):
    return 0


def _no_curved(mode, k, t, c, s, u, p, mem, grad):
    return math.nan


@dataclass(frozen=True, eq=False)
class Model:
    """A non-smooth forced system (see the module docstring for the contract)."""

    name: str
    description: str
    parameters: tuple
    state_names: tuple
    mode_names: tuple
    methods: dict
    omega: str | None = "omega"
    period: str | None = None
    forcing_amplitude: str | None = "F0"
    n_memory: int = 0
    state_units: tuple = ()
    state_long_names: tuple = ()
    references: tuple = ()
    presets: dict = _field(default_factory=dict)
    check: Callable | None = None
    contact_modes: int = 0
    contact: Callable | None = None
    contact_name: str = "contact"
    mode_long_name: str = "mode"
    contact_level: Callable | None = None
    lines: Callable | None = None
    mode_labels: tuple = ()
    axis_labels: tuple = ()
    line_labels: dict = _field(default_factory=dict)
    mode_word: str = "modes"
    contact_label: str = ""
    source: str = "built-in"

    def __post_init__(self):
        bad = lambda msg: ParameterError(f"model {self.name}: {msg}")  # noqa: E731
        names = [p.name for p in self.parameters]
        if len(set(names)) != len(names):
            raise bad("parameter names must be unique")
        if self.period is not None:
            if self.omega is not None:
                raise bad("a forcing has a frequency (omega) or a period (period), not both: "
                          "give omega=None with period")
            if self.period not in names:
                raise bad(f"the forcing period {self.period!r} must be a parameter")
        elif self.omega is None:
            if self.forcing_amplitude is not None:
                raise bad("a model without forcing (omega=None) has no forcing_amplitude")
        elif self.omega not in names:
            raise bad(f"the forcing frequency {self.omega!r} must be a parameter")
        n = len(self.state_names)
        if n < 2:
            raise bad(f"the state needs n >= 2 components (X, V, ...), got {n}")
        if n - 2 + self.n_memory > 11:
            raise bad("n - 2 + n_memory must be <= 11")
        if not 1 <= len(self.mode_names) <= MAX_MODES:
            raise bad(f"between 1 and {MAX_MODES} modes, got {len(self.mode_names)}")
        if not self.methods:
            raise bad("at least one method ('smooth' or 'exact') is needed")
        for mname, m in self.methods.items():
            if not isinstance(m, Method):
                raise bad(f"method {mname!r} must be a nonsmooth.models.Method")
            for part in ("field", "jacobian", "guards", "transition", "initial"):
                if not callable(getattr(m, part)):
                    raise bad(f"method {mname!r}: {part} is missing (a function is needed)")
            for mode in m.modes:
                if not 0 <= mode < len(self.mode_names):
                    raise bad(f"method {mname!r}: mode {mode} is not one of the "
                              f"{len(self.mode_names)} modes")
            if m.evidence is not None:
                e = self.methods.get(m.evidence)
                same = ("field", "jacobian", "guards", "transition", "initial", "modes",
                        "continuous_memory")
                if e is None or e.evidence is not None or any(
                        getattr(e, k) != getattr(m, k) for k in same):
                    raise bad(f"method {mname!r}: evidence {m.evidence!r} must name another "
                              f"method with the same {', '.join(same)}")
        object.__setattr__(self, "_compiled", {})

    # ---- parameters ----
    @property
    def param_names(self) -> tuple:
        return tuple(p.name for p in self.parameters)

    @property
    def frame_index(self) -> int:
        """Where the kernels read what frames time: the forcing frequency's slot (T = 2 pi /
        omega), the forcing period's (``period``: T itself), or for a model without forcing
        the extra slot that ``pack`` appends (frequency 1: a time unit of 2 pi)."""
        if self.period is not None:
            return self.index[self.period]
        return len(self.parameters) if self.omega is None else self.index[self.omega]

    @property
    def forcing_param(self) -> str | None:
        """The parameter that sets the forcing's period: ``omega`` (a frequency) or
        ``period``; None without forcing."""
        return self.period if self.period is not None else self.omega

    def frequency(self, P):
        """omega = 2 pi / T of packed parameter rows ``P`` (the last axis: parameters)."""
        f = np.asarray(P, dtype=np.float64)[..., self.frame_index]
        return 2.0 * math.pi / f if self.period is not None else f

    def forcing_range(self, omega_lo: float, omega_hi: float) -> tuple:
        """A default range of forcing frequencies (omega_lo < omega_hi) in the units of
        ``forcing_param``: itself for a frequency, (2 pi / omega_hi, 2 pi / omega_lo) for a
        period (the same forcings, ascending)."""
        if self.period is not None:
            return 2.0 * math.pi / omega_hi, 2.0 * math.pi / omega_lo
        return omega_lo, omega_hi

    @property
    def autonomous(self) -> bool:
        """True for a model that declares no forcing (``omega=None`` and no ``period``)."""
        return self.omega is None and self.period is None

    @property
    def index(self) -> dict:
        return param_index(self.parameters)

    @property
    def n(self) -> int:
        return len(self.state_names)

    def param(self, name: str) -> Param:
        for p in self.parameters:
            if p.name == name:
                return p
        raise ParameterError(self.unknown_message(name))

    def unknown_message(self, name: str) -> str:
        other = [m for m in _other_models_with(name) if m != self.name]
        where = f" (a parameter of {', '.join(other)})" if other else ""
        return (f"{name}: not a parameter of model {self.name!r}{where}; its parameters: "
                f"{', '.join(self.param_names)}")

    def validate(self, values: dict) -> dict:
        """Checked values (defaults filled in), in parameter order; one-line errors."""
        for k in values:
            if k not in self.param_names:
                raise ParameterError(self.unknown_message(k))
        out = {}
        for p in self.parameters:
            if p.name in values:
                out[p.name] = p.check(values[p.name])
            elif p.default is not None:
                out[p.name] = float(p.default)
            else:
                raise ParameterError(f"{p.name}: required by model {self.name!r} "
                                     f"({p.long_name or 'no default'}; {p.range_text})")
        fp = self.forcing_param
        if fp is not None and not out[fp] > 0:  # (a plain number's range is any finite value)
            what = "period" if self.period is not None else "frequency"
            raise ParameterError(f"{fp}: the forcing {what} must be > 0, got {out[fp]:g}")
        if self.check is not None:
            self.check(out)
        return out

    def params(self, **values):
        """Validated parameters of this model (defaults for the ones not given)."""
        return ModelParams(self, **values)

    def preset(self, name: str):
        try:
            values, _ = self.presets[name]
        except KeyError:
            raise ParameterError(f"preset: unknown preset {name!r} of model {self.name!r} "
                                 f"(known: {', '.join(self.presets) or 'none'})") from None
        return self.params(**values)

    def params_from_attrs(self, source, _call: str = "from_attrs", **point):
        """The parameters of a result (``param_<name>`` attrs; swept ones given in ``point``);
        ``_call`` is how the messages name the call."""
        variables = getattr(source, "variables", {})
        attrs = getattr(source, "attrs", source)
        for k in point:
            if k not in self.param_names:
                raise ParameterError(self.unknown_message(k))
        values = {}
        for n in self.param_names:
            if n in point:
                values[n] = point[n]
            elif n in variables:
                raise ParameterError(f"{n}: swept in this dataset; give the point, e.g. "
                                     f"{_call}(ds, {n}=...)")
            elif f"param_{n}" in attrs:
                values[n] = float(attrs[f"param_{n}"])
            else:
                raise ParameterError(f"{n}: no param_{n} attribute (a swept parameter?); give "
                                     f"its value, e.g. {_call}(attrs, {n}=...)")
        return self.params(**values)

    # ---- methods ----
    def method(self, name: str) -> Method:
        try:
            return self.methods[name]
        except KeyError:
            raise ParameterError(f"method: model {self.name!r} has no method {name!r} "
                                 f"(known: {', '.join(self.methods)})") from None

    def fns(self, method: str) -> tuple:
        """The compiled functions of ``method`` (cached): the ``fns`` tuple of the generic
        kernel."""
        cache = self._compiled
        if method not in cache:
            cache[method] = compile_method(self, method)
        return cache[method]

    def is_contact(self, params, mask: int, max_X: float, min_X: float) -> bool:
        """Does an orbit with visited-mode ``mask`` and these extremes count as contact?"""
        if self.contact is not None:
            return bool(self.contact(params, int(mask), float(max_X), float(min_X)))
        return bool(int(mask) & self.contact_modes)

    def plot_lines(self, params, method: str) -> list:
        """[(X value, label), ...] to draw on time responses and sections."""
        return list(self.lines(params, method)) if self.lines is not None else []

    @property
    def contact_text(self) -> str:
        """The full-contact modes as the CLI's tables name them (``contact_label``, else the
        names of the ``contact_modes``, else "contact")."""
        return self.contact_label or " or ".join(
            nm for i, nm in enumerate(self.mode_names) if self.contact_modes >> i & 1) or "contact"

    def summary(self) -> dict:
        return {"name": self.name, "description": self.description,
                "parameters": {p.name: dict(default=p.default, range=p.range_text,
                                            units=p.units, long_name=p.long_name)
                               for p in self.parameters},
                "methods": list(self.methods), "modes": list(self.mode_names),
                "state": list(self.state_names), "references": list(self.references),
                "presets": list(self.presets), "source": self.source}


# ---- compiling a method ----------------------------------------------------------------------
def compile_method(model: Model, method: str) -> tuple:
    """Compile the functions of ``model.methods[method]`` as cached ``cfunc`` s and check them
    at a sample point (defaults of the parameters, u = 0.5, mem = 0) for every mode: field
    finite, Jacobian equal to finite differences of the field, guard count within bounds,
    transitions into known modes. One ParameterError naming the model, method and function
    otherwise."""
    import numba as nb

    from ..integrate.contract import MAX_GUARDS, MODEL_SIGNATURES, CompiledFunction, ModelFns
    m = model.method(method)
    parts = ("field", "jacobian", "guards", "transition", "initial", "linear", "curved")
    fns = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", nb.NumbaExperimentalFeatureWarning)
        for part, sig in zip(parts, MODEL_SIGNATURES):
            fn = getattr(m, part) or (_no_curved if part == "curved" else _no_linear)
            try:
                fns.append(nb.cfunc(sig, cache=True, error_model="numpy")(fn))
            except Exception as exc:
                raise ParameterError(f"model {model.name}: {method}.{part} "
                                     f"({getattr(fn, '__name__', part)}) does not compile with "
                                     f"numba: {_numba_reason(exc)}") from None
    fns = ModelFns(CompiledFunction(f) for f in fns)
    _sample_check(model, method, m, fns, MAX_GUARDS)
    return fns


def _numba_reason(exc) -> str:
    """The informative line of a numba compilation error, with its source location."""
    lines = [ln.strip() for ln in str(exc).splitlines() if ln.strip()]
    skip = ("Failed in ", "During:", "<source elided>", "^")
    reason = next((ln for ln in lines if not ln.startswith(skip) and not ln.startswith("File ")),
                  type(exc).__name__)
    where = next((ln.replace('"', "") for ln in lines if ln.startswith("File ")), "")
    return f"{reason} ({where})" if where else reason


def _sample_check(model, method, m, fns, max_guards):
    from ._probe import (call_curved, call_field, call_guards, call_jacobian, call_linear,
                         call_transition)
    n = model.n
    bad = lambda msg: ParameterError(f"model {model.name}: {method}.{msg}")  # noqa: E731
    cm = tuple(m.continuous_memory)
    if any(not (isinstance(i, int) and 0 <= i < model.n_memory) for i in cm):
        raise bad(f"continuous_memory {cm} names slots outside 0..{model.n_memory - 1}")
    if len(set(cm)) != len(cm):  # (the tangent kernel keeps one column per slot named)
        raise bad(f"continuous_memory {cm} names a slot twice")
    try:
        p = model.params().pack()
    except ParameterError:
        return  # no complete defaults: nothing to sample
    mem = np.zeros(max(1, model.n_memory))
    u = np.full(n, 0.5)
    du = np.zeros(n)
    J = np.zeros((n, n + model.n_memory))
    G = np.zeros((max_guards, n + 3))
    t, c, s = 0.1, math.cos(0.1), math.sin(0.1)
    for mode in (m.modes or tuple(range(len(model.mode_names)))):
        name = model.mode_names[mode]
        call_field(fns, mode, t, c, s, u, p, mem, du)
        if not np.all(np.isfinite(du)):
            raise bad(f"field is not finite in mode {name} at the sample point u = 0.5")
        J[:] = 0.0
        call_jacobian(fns, mode, t, c, s, u, p, mem, J)
        cols = list(range(n)) + [n + i for i in cm]
        fd = np.zeros_like(J)
        for j in cols:  # the state's columns, then the continuous memory's
            v = u if j < n else mem
            jj = j if j < n else j - n
            h = 1e-6 * max(1.0, abs(v[jj]))
            dp, dm = np.empty(n), np.empty(n)
            for sign, out in ((1.0, dp), (-1.0, dm)):
                w = v.copy()
                w[jj] += sign * h
                uu, mm = (w, mem) if j < n else (u, w)
                call_field(fns, mode, t, c, s, uu, p, mm, out)
            fd[:, j] = (dp - dm) / (2 * h)
        scale = max(1.0, float(np.max(np.abs(fd[:, cols]))))
        err = np.abs(J - fd)[:, cols]
        if not np.all(err <= 1e-5 * scale):
            i, j = np.unravel_index(np.argmax(err), err.shape)
            j = cols[j]
            raise bad(f"jacobian disagrees with the field in mode {name}: J[{i},{j}] = "
                      f"{J[i, j]:.6g}, finite differences give {fd[i, j]:.6g}")
        if m.closed_form and m.linear is not None:
            _check_linear(model, fns, mode, p, u, mem, t, c, s, du, bad, call_linear)
        ng = int(call_guards(fns, mode, p, mem, G))
        if not 0 <= ng <= max_guards:
            raise bad(f"guards returns {ng} surfaces in mode {name} (allowed 0..{max_guards})")
        for k in range(ng):
            if math.isnan(G[k, n]):
                _check_curved(model, m, fns, mode, k, p, u, mem, bad, call_curved)
            uk, mk = u.copy(), mem.copy()
            new = int(call_transition(fns, mode, k, t, c, s, uk, p, mk))
            if not 0 <= new < len(model.mode_names):
                raise bad(f"transition from mode {name} through surface {k} goes to unknown "
                          f"mode {new} (modes: 0..{len(model.mode_names) - 1})")
            if math.isnan(G[k, n]) and G[k, n + 1] == 1.0:  # a label (``label_row``)
                du2 = np.zeros(n)
                call_field(fns, new, t, c, s, u, p, mem, du2)
                if not (np.array_equal(uk, u) and np.array_equal(mk, mem)
                        and np.allclose(du2, du, rtol=1e-12, atol=1e-12)):
                    raise bad(f"guards marks surface {k} of mode {name} a label, but the "
                              f"mode it enters ({model.mode_names[new]}) has another field or "
                              f"the transition resets the state")
                G2 = np.zeros_like(G)
                ng2 = int(call_guards(fns, new, p, mem, G2))
                if ng != 1 or ng2 != 1 or not (math.isnan(G2[0, n]) and G2[0, n + 1] == 1.0):
                    raise bad(f"guards marks surface {k} of mode {name} a label, but a label "
                              f"must be the only surface of both modes it separates (the "
                              f"kernel does not look for another surface up to the step's "
                              f"end)")


def _check_linear(model, fns, mode, p, u, mem, t, c, s, du, bad, call_linear):
    """A mode that ``linear`` declares (1: the oscillator, 2: the general form) has the field
    it declares, at the sample point (``du`` holds the field there)."""
    n = model.n
    out = np.zeros(max(4, n * n + 3 * n))
    r = int(call_linear(fns, mode, p, out))
    if r == 1 and n == 2:
        want = np.array([u[1], -out[0] * u[0] - out[1] * u[1] + out[3] * c + out[2]])
    elif r == 2:
        A = out[:n * n].reshape(n, n)
        b, fc, fs = out[n * n:n * n + n], out[n * n + n:n * n + 2 * n], out[n * n + 2 * n:]
        want = A @ u + b + fc * c + fs * s
    else:
        return
    if not np.allclose(du, want, rtol=1e-9, atol=1e-9 * max(1.0, float(np.abs(du).max()))):
        i = int(np.argmax(np.abs(du - want)))
        raise bad(f"linear: mode {model.mode_names[mode]} is not the linear mode it declares: "
                  f"d{model.state_names[i]}/dt = {du[i]:.6g} by the field, {want[i]:.6g} by "
                  f"linear (kind {r}) at the sample point u = 0.5")


def _check_curved(model, m, fns, mode, k, p, u, mem, bad, call_curved):
    """A curved guard (``curved_row``) at the sample point: ``curved`` given, finite, and its
    gradient (state and time) equal to finite differences."""
    name = model.mode_names[mode]
    if m.curved is None:
        raise bad(f"guards marks surface {k} of mode {name} curved, but the method has no "
                  "curved function")
    n = model.n
    om = float(model.frequency(p))

    def g_at(t, uu):
        grad = np.zeros(n + 1)
        return float(call_curved(fns, mode, k, t, math.cos(om * t), math.sin(om * t), uu, p,
                                 mem, grad)), grad

    t = 0.1
    g, grad = g_at(t, u)
    if not (math.isfinite(g) and np.all(np.isfinite(grad))):
        raise bad(f"curved: surface {k} of mode {name} is not finite at the sample point "
                  "u = 0.5")
    fd = np.zeros(n + 1)
    for j in range(n + 1):
        h = 1e-6
        if j < n:
            up, um = u.copy(), u.copy()
            up[j] += h
            um[j] -= h
            fd[j] = (g_at(t, up)[0] - g_at(t, um)[0]) / (2 * h)
        else:
            fd[j] = (g_at(t + h, u)[0] - g_at(t - h, u)[0]) / (2 * h)
    scale = max(1.0, float(np.max(np.abs(fd))))
    err = np.abs(grad - fd)
    if not np.all(err <= 1e-5 * scale):
        j = int(np.argmax(err))
        what = f"d g / d u[{j}]" if j < n else "d g / d t"
        raise bad(f"curved: the gradient of surface {k} in mode {name} disagrees with the "
                  f"surface: {what} = {grad[j]:.6g}, finite differences give {fd[j]:.6g}")


# ---- registry --------------------------------------------------------------------------------

#: Parameter names of the built-in models (for "a parameter of another model" messages),
#: filled as models load.
_PARAM_NAMES: dict = {}


def _other_models_with(name: str) -> list:
    import importlib
    for mod in BUILTIN.values():  # registered as they load
        try:
            importlib.import_module(mod)
        except ImportError:
            pass
    return [m for m, names in _PARAM_NAMES.items() if name in names]
