"""Parameter sets of the paper (Tables 1-4 and the figures built on them)."""

from __future__ import annotations

from .errors import ParameterError
from .params import Params

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


def preset(name: str) -> Params:
    """The named parameter set (see :data:`PRESETS` or ``nonsmooth presets``)."""
    try:
        values, _ = PRESETS[name]
    except KeyError:
        raise ParameterError(
            f"preset: unknown preset {name!r} (known: {', '.join(PRESETS)})") from None
    return Params(**values)


def preset_source(name: str) -> str:
    preset(name)
    return PRESETS[name][1]
