"""The run settings of every figure as (full, quick) pairs: the one place where a --quick run
differs from a full one (the report prints this table)."""

from __future__ import annotations

#: group -> setting -> (full, quick); a group is a figure or a kind of run shared by figures
SETTINGS: dict[str, dict[str, tuple]] = {
    "fig3": {"transient": (20, 10), "periods": (3, 2), "samples_per_period": (20000, 4000)},
    # Fig. 4: the agreement of a chaotic smoothed attractor with the exact one, hence the
    # recommended eta, depends on the number of section points: the same in both modes
    "fig4": {"transient": (500, 500), "record": (400, 400),
             "excursion samples_per_period": (100, 100),
             # lambda1 of the claimed-chaotic small eta (ns.lyapunov from the same start, after
             # the same transient): 400 periods leave lambda1 within 3 errors of 0
             "lambda1 periods": (2000, 2000)},
    # Fig. 5: at omega_s = 31.6 the period-4 orbit settles slowly (after 150 periods it still
    # looks like period 8): the same transient in both modes
    "fig5": {"transient": (400, 400), "periods": (5, 3), "samples_per_period": (400, 200),
             "record": (200, 200)},
    "fig6": {"omega values": (441, 111), "transient": (500, 200), "record": (50, 30)},
    "fig7": {"grid": (400, 60)},
    "fig8": {"transient": (1000, 300), "record": (200, 50)},
    # Figs. 9, 11: the grid step is the coarse step divided by this (so that the paper's single
    # points of Figs. 10, 12 are grid values in both modes). The same transient in both modes:
    # at omega = 0.91 the down sweep passes a chaotic transient that 150 periods did not always
    # outlast (whether it did depended on the last bits of the arithmetic)
    "fig9, fig11": {"step divisor": (16, 1), "transient": (500, 500), "record": (200, 60)},
    # single points (Figs. 10, 12) and their eq. 12 / eta = 1e-5 variants
    "fig10, fig12": {"transient": (2000, 500), "record": (2000, 200)},
    # the other initial conditions tried when a period differs (and a 4x longer transient)
    "fig10, fig12: other ICs": {"transient": (2000, 500), "record": (400, 150)},
    # the attractors beside the paper's (Figs. 4, 5, 10b; notes, no verdict): a 7 x 7 grid of
    # initial conditions, exact model; periodic ones confirmed by Newton shooting
    "coexisting attractors": {"grid": (7, 7), "transient": (500, 500), "record": (200, 200)},
    # Fig. 10b: the omega range of the coexisting period-3 orbit and chaos (exact model: a down
    # sweep from (0, 0) and a continuation of the period-3 orbit by Newton shooting)
    "fig10b: coexistence range": {"omega from": (0.905, 0.905),
                                   "omega to": (0.935, 0.935), "omega step": (0.0005, 0.0005),
                                   "transient": (500, 500), "record": (300, 300)},
}


def rows() -> list[tuple[str, str, object, object]]:
    """(group, setting, full, quick) for the report."""
    return [(g, k, full, quick) for g, kv in SETTINGS.items() for k, (full, quick) in kv.items()]
