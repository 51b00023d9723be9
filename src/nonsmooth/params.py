"""The paper's non-dimensional parameters (eq. 3) with validation.

``Params`` is immutable; ``Params.pack()`` gives the float64 array that crosses into the
compiled kernels, in the order of :data:`PARAM_NAMES`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, replace as _dc_replace

import numpy as np

from .errors import ParameterError
from .models.base import ParamsBase

#: Order of the packed parameter array handed to kernels.
PARAM_NAMES = ("omega0", "omega_s", "xi", "xi_s", "F0", "omega", "eta")

#: Index of each parameter in the packed array.
IDX = {name: i for i, name in enumerate(PARAM_NAMES)}

#: Human-readable description, unit and allowed range of every parameter.
PARAM_INFO = {
    "omega0": ("natural frequency sqrt(k/m)", "rad/s", "omega0 > 0"),
    "omega_s": ("support frequency sqrt(k_s/m)", "rad/s", "omega_s >= 0"),
    "xi": ("damping c/m (multiplies X' directly)", "1/s", "xi >= 0"),
    "xi_s": ("support damping c_s/m", "1/s", "xi_s >= 0"),
    "F0": ("forcing amplitude f0/(m g)", "1/s^2", "any finite value"),
    "omega": ("forcing frequency", "rad/s", "omega > 0"),
    "eta": ("half-width of the switching bands (eta_hat / g)", "1", "0 < eta < 0.5"),
}


def _check_finite(name: str, value) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: expected a number, got {value!r}") from None
    if not math.isfinite(v):
        raise ParameterError(f"{name}: must be finite, got {v!r} (allowed: {PARAM_INFO[name][2]})")
    return v


@dataclass(frozen=True)
class Params(ParamsBase):
    """Non-dimensional parameters of the oscillator with a discontinuous support (eq. 3).

    omega0^2 = k/m, omega_s^2 = k_s/m, xi = c/m, xi_s = c_s/m, F0 = f0/(m g); ``omega`` is the
    forcing frequency and ``eta`` the half-width of the smoothing bands (eq. 14), in units of
    the gap g. Time stays dimensional (seconds), displacement is X = x/g.
    """

    omega0: float
    omega_s: float
    xi: float
    xi_s: float
    F0: float
    omega: float
    eta: float = 1e-5

    def __post_init__(self):
        for f in fields(self):
            object.__setattr__(self, f.name, _check_finite(f.name, getattr(self, f.name)))
        if self.omega0 <= 0:
            raise ParameterError(f"omega0: must be > 0, got {self.omega0}")
        for name in ("omega_s", "xi", "xi_s"):
            if getattr(self, name) < 0:
                raise ParameterError(f"{name}: must be >= 0, got {getattr(self, name)}")
        if self.omega <= 0:
            raise ParameterError(f"omega: must be > 0, got {self.omega}")
        if not 0 < self.eta < 0.5:
            raise ParameterError(f"eta: must satisfy 0 < eta < 0.5, got {self.eta}")
        if self.omega_s == 0 and self.xi_s > 0:
            raise ParameterError(
                "omega_s: must be > 0 when xi_s > 0 (h_beta of eq. 7 divides by omega_s^2); "
                "use xi_s = 0 for a support without stiffness"
            )

    # -- construction -------------------------------------------------------------------
    @classmethod
    def from_dimensional(cls, *, m: float, k: float, c: float, k_s: float, c_s: float,
                         f0: float, g: float, omega: float, eta_hat: float = 1e-5) -> "Params":
        """Build from dimensional quantities (eq. 3): mass m, stiffnesses k, k_s, dampings c,
        c_s, forcing amplitude f0, gap g, forcing frequency omega and band width eta_hat
        (same length unit as g)."""
        vals = {}
        for name, v in dict(m=m, k=k, c=c, k_s=k_s, c_s=c_s, f0=f0, g=g, omega=omega,
                            eta_hat=eta_hat).items():
            try:
                v = float(v)
            except (TypeError, ValueError):
                raise ParameterError(f"{name}: expected a number, got {v!r}") from None
            if not math.isfinite(v):
                raise ParameterError(f"{name}: must be finite, got {v!r}")
            vals[name] = v
        for name in ("m", "g", "k"):
            if vals[name] <= 0:
                raise ParameterError(f"{name}: must be > 0, got {vals[name]}")
        for name in ("c", "k_s", "c_s"):
            if vals[name] < 0:
                raise ParameterError(f"{name}: must be >= 0, got {vals[name]}")
        m_, g_ = vals["m"], vals["g"]
        return cls(
            omega0=math.sqrt(vals["k"] / m_),
            omega_s=math.sqrt(vals["k_s"] / m_),
            xi=vals["c"] / m_,
            xi_s=vals["c_s"] / m_,
            F0=vals["f0"] / (m_ * g_),
            omega=vals["omega"],
            eta=vals["eta_hat"] / g_,
        )

    def replace(self, **changes) -> "Params":
        """A copy with some fields changed (validated again). Unknown names are an error."""
        unknown = sorted(set(changes) - set(PARAM_NAMES))
        if unknown:
            raise ParameterError(
                f"{unknown[0]}: unknown parameter (known: {', '.join(PARAM_NAMES)})")
        return _dc_replace(self, **changes)

    @property
    def model(self):
        """The model these parameters belong to (``support``)."""
        from .models import model
        return model("support")

    # -- views ----------------------------------------------------------------------------
    def pack(self) -> np.ndarray:
        """float64 array in :data:`PARAM_NAMES` order, for the compiled kernels."""
        return np.array([getattr(self, n) for n in PARAM_NAMES], dtype=np.float64)

    def as_dict(self) -> dict:
        return asdict(self)

    @property
    def period(self) -> float:
        """Forcing period T = 2 pi / omega."""
        return 2.0 * math.pi / self.omega

    def attrs(self) -> dict:
        """Flat netCDF attributes (``param_<name>``)."""
        return {f"param_{k}": float(v) for k, v in self.as_dict().items()}

    @classmethod
    def from_attrs(cls, source, **point) -> "Params":
        """The parameters of a result: ``source`` is a Dataset (or an attrs dict) with
        ``param_<name>`` attributes. A parameter swept in the Dataset (a coordinate or variable
        of that name) must be given in ``point`` (``Params.from_attrs(ds, omega=0.92)``): its
        value is a point of the sweep, never an attribute. One-line ParameterError otherwise."""
        if unknown := sorted(set(point) - set(PARAM_NAMES)):
            raise ParameterError(f"{unknown[0]}: unknown parameter (known: {', '.join(PARAM_NAMES)})")
        from .models.support import MODEL
        return MODEL.params_from_attrs(source, _call="Params.from_attrs", **point)


def check_param_name(name: str, params=None) -> str:
    """Return ``name`` if it is a parameter name (of ``params``' model; default the support
    model), else raise a one-line ParameterError."""
    if params is not None and params.model.name != "support":
        params.model.param(name)
        return name
    if name not in PARAM_NAMES:
        raise ParameterError(f"{name}: unknown parameter (known: {', '.join(PARAM_NAMES)})")
    return name


def parse_assignments(items) -> dict:
    """Parse CLI ``name=value`` strings into a dict of floats (names checked)."""
    out = {}
    for item in items or ():
        if "=" not in item:
            raise ParameterError(f"--set {item}: expected NAME=VALUE")
        name, _, value = item.partition("=")
        name = check_param_name(name.strip())
        try:
            out[name] = float(value)
        except ValueError:
            raise ParameterError(f"{name}: expected a number, got {value.strip()!r}") from None
    return out
