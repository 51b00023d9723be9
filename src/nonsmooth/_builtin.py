"""The built-in models by name (the module defining each ``MODEL``), the paper's first.

A light module (no numpy, numba or model code): the CLI reads it for its defaults without
loading a model."""

BUILTIN = {
    "support": "nonsmooth.models.support",
    "two_sided": "nonsmooth.models.two_sided",
    "impact": "nonsmooth.models.impact",
    "stick_slip": "nonsmooth.models.stick_slip",
    "bouncing_ball": "nonsmooth.models.bouncing_ball",
    "impact_2dof": "nonsmooth.models.impact_2dof",
    "jeffcott_rotor": "nonsmooth.models.jeffcott_rotor",
}

#: The model a command uses when none is named: the paper's.
DEFAULT_MODEL = next(iter(BUILTIN))
