"""The support model's parameters (eq. 3), their cross-field rule, the paper's parameter sets
(Tables 1-4 and the figures built on them) and the construction from dimensional quantities.

Plain data: the model (``MODEL`` in this package) is built from it, and its compiled functions
read the packed array through :data:`IDX`.
"""

from __future__ import annotations

import math

from ...errors import ParameterError
from ..base import Param, param_index

PARAMETERS = (
    Param("omega0", 1.0, low=0.0, low_open=True, units="rad/s",
          long_name="natural frequency sqrt(k/m)", symbol=r"$\omega_0$"),
    Param("omega_s", 17.32, low=0.0, units="rad/s",
          long_name="support frequency sqrt(k_s/m)", symbol=r"$\omega_s$"),
    Param("xi", 0.05, low=0.0, units="1/s",
          long_name="damping c/m (multiplies X' directly)", symbol=r"$\xi$"),
    Param("xi_s", 0.6, low=0.0, units="1/s", long_name="support damping c_s/m",
          symbol=r"$\xi_s$"),
    Param("F0", 0.3125, units="1/s^2", long_name="forcing amplitude f0/(m g)", symbol=r"$F_0$"),
    Param("omega", 0.91, low=0.0, low_open=True, units="rad/s", long_name="forcing frequency",
          symbol=r"$\omega$"),
    Param("eta", 1e-5, low=0.0, high=0.5, low_open=True, high_open=True, units="1",
          long_name="half-width of the switching bands (eta_hat / g)", symbol=r"$\eta$"),
)

#: Order of the packed parameter array, and the index of each name in it.
PARAM_NAMES = tuple(p.name for p in PARAMETERS)
IDX = param_index(PARAMETERS)


def check(values: dict) -> None:
    """The rule between parameters: h_beta of eq. 7 divides by omega_s^2, so a support without
    stiffness (omega_s = 0) has no damping either."""
    if values["omega_s"] == 0 and values["xi_s"] > 0:
        raise ParameterError(
            "omega_s: must be > 0 when xi_s > 0 (h_beta of eq. 7 divides by omega_s^2); "
            "use xi_s = 0 for a support without stiffness")


_TABLE1 = dict(omega0=4.5, omega_s=38.0, xi=1.04, xi_s=0.72, F0=144.9, omega=5.0)
# Table 2 leaves omega_s free (Fig. 5 varies it over 1 ... 100); the preset takes 10.
_TABLE2 = dict(omega0=1.0, omega_s=10.0, xi=0.05, xi_s=0.30, F0=0.125, omega=1.0)
_TABLE3 = dict(omega0=1.0, omega_s=17.32, xi=0.05, xi_s=0.60, F0=0.3125, omega=0.91)
# Table 4 prints "xi" twice; the second column is xi_s (same value 0.60 as Table 3).
_TABLE4 = dict(omega0=1.0, omega_s=31.6, xi=0.05, xi_s=0.60, F0=0.225, omega=0.9)

#: name -> (parameters as a dict, source in the paper)
PRESETS: dict[str, tuple[dict, str]] = {
    "table1": ({**_TABLE1, "eta": 7.14e-3}, "Table 1, Fig. 3 (eta = 7.14e-3)"),
    "fig4": ({**_TABLE1, "F0": 76.24, "omega": 9.55, "eta": 2.8e-3},
             "Table 1 with F0 = 76.24, omega = 9.55 (chaotic), Fig. 4"),
    "table2": ({**_TABLE2, "eta": 2.5e-6},
               "Table 2, Fig. 5 (eta = 2.5e-6; omega_s not in the table, 10 chosen)"),
    "fig6a": ({**_TABLE2, "omega_s": 3.16, "eta": 2.5e-6}, "Table 2 with omega_s = 3.16, Fig. 6a"),
    "fig6b": ({**_TABLE2, "omega_s": 7.07, "eta": 2.5e-6}, "Table 2 with omega_s = 7.07, Fig. 6b"),
    "fig7": ({**_TABLE2, "omega_s": 3.16, "omega": 1.10, "eta": 2.5e-6},
             "Table 2 with omega_s = 3.16, omega = 1.10, Figs. 7a and 8"),
    "table3": ({**_TABLE3, "eta": 6.25e-6}, "Table 3, omega = 0.91 (Fig. 10a), eta = 6.25e-6, Fig. 9"),
    "table4": ({**_TABLE4, "eta": 5e-6}, "Table 4, F0 = 0.225 (Fig. 12a), eta = 5e-6, Fig. 11"),
}


def dimensionless(*, m: float, k: float, c: float, k_s: float, c_s: float, f0: float, g: float,
                  omega: float, eta_hat: float = 1e-5) -> dict:
    """The non-dimensional values of eq. 3 from dimensional quantities: mass m, stiffnesses k,
    k_s, dampings c, c_s, forcing amplitude f0, gap g, forcing frequency omega and band width
    eta_hat (same length unit as g). One-line ParameterError naming the quantity otherwise."""
    from ...checks import check_float
    vals = {name: check_float(name, v) for name, v in dict(
        m=m, k=k, c=c, k_s=k_s, c_s=c_s, f0=f0, g=g, omega=omega, eta_hat=eta_hat).items()}
    for name in ("m", "g", "k"):
        if vals[name] <= 0:
            raise ParameterError(f"{name}: must be > 0, got {vals[name]}")
    for name in ("c", "k_s", "c_s"):
        if vals[name] < 0:
            raise ParameterError(f"{name}: must be >= 0, got {vals[name]}")
    m_, g_ = vals["m"], vals["g"]
    return dict(omega0=math.sqrt(vals["k"] / m_), omega_s=math.sqrt(vals["k_s"] / m_),
                xi=vals["c"] / m_, xi_s=vals["c_s"] / m_, F0=vals["f0"] / (m_ * g_),
                omega=vals["omega"], eta=vals["eta_hat"] / g_)
