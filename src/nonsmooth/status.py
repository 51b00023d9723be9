"""Integer status codes returned by every compiled kernel (kernels never raise)."""

OK = 0
MAX_STEPS = 1
STEP_TOO_SMALL = 2
NON_FINITE = 3
ZENO = 4  # accumulation of ever shorter contacts (exact solver)
EVENT_FAILED = 5  # an event could not be located (should not happen)
RESONANCE = 6  # exact solver: an undamped mode forced exactly at its resonance
GRAZING = 7  # tangent kernel: a switch reached tangentially (unbounded saltation)

MESSAGES = {
    OK: "ok",
    MAX_STEPS: "too many steps",
    STEP_TOO_SMALL: "step size too small",
    NON_FINITE: "non-finite state",
    ZENO: "accumulation of ever shorter contacts (Zeno)",
    EVENT_FAILED: "event location failed",
    RESONANCE: ("undamped mode forced exactly at resonance (xi = 0 and omega = omega0, or in "
                "contact xi + xi_s = 0 and omega^2 = omega0^2 + omega_s^2): the exact solver has "
                "no bounded closed form there; method=\"smooth\" handles it"),
    GRAZING: ("grazing: a switching surface was reached tangentially (g' = 0), where the "
              "saltation matrix is unbounded"),
}

#: One word per status for CF ``flag_meanings``.
FLAG_NAMES = {
    OK: "ok",
    MAX_STEPS: "too_many_steps",
    STEP_TOO_SMALL: "step_size_too_small",
    NON_FINITE: "non_finite_state",
    ZENO: "zeno_accumulation",
    EVENT_FAILED: "event_location_failed",
    RESONANCE: "undamped_resonance",
    GRAZING: "grazing_switch",
}


def message(code: int) -> str:
    return MESSAGES.get(int(code), f"unknown status {int(code)}")
