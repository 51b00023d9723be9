"""Fig. 6: resonance curves with the contact frequency omega_a and the jumps omega_b, omega_c."""

from __future__ import annotations

import math

import numpy as np

from ...models.support import preset
from ..access import number
from ..core import DIFFERS, NOT_STATED, agree_if, figure, fmt
from ._common import IC, method_text


def resonance(ctx, name):
    from ...analysis.resonance import resonance_curve
    p = preset(name)
    omegas = np.linspace(0.5, 1.6, ctx.setting("fig6", "omega values"))  # steps 0.0025 / 0.01
    kw = dict(method="smooth", workers=ctx.workers, x0=IC[0], v0=IC[1],
              transient=ctx.setting("fig6", "transient"), record=ctx.setting("fig6", "record"))
    return ctx.shared(f"resonance:{name}", lambda: resonance_curve(p, omegas, **kw))


def jump_width(ds):
    a, b, c = (number(ds, k) for k in ("omega_a", "omega_b", "omega_c"))
    lo, hi = (min(b, c), max(b, c)) if math.isfinite(b) and math.isfinite(c) else (b, c)
    return a, lo, hi, (hi - lo) if math.isfinite(b) and math.isfinite(c) else float("nan")


def _fig6(ctx, rec, name):
    from ...plot.resonance import plot_resonance
    ds = resonance(ctx, name)
    p = preset(name)
    om = ds["omega"].values if "omega" in ds.coords else None
    rec.use_params(p, preset=name, omega=(f"{fmt(om.min())} .. {fmt(om.max())}, {om.size} values"
                                          if om is not None else "?"))
    rec.method = method_text(ds)
    rec.settings = {"sweeps": "up and down with continuation",
                    "start": f"{IC} at the first frequency",
                    **{k: str(ds.attrs[k]) for k in ("transient", "record", "points") if k in ds.attrs}}
    ds.attrs["preset"] = name
    ctx.save(ds, name)
    a, lo, hi, w = jump_width(ds)
    rec.check("dynamical jumps: up and down sweeps jump at omega_b < omega_c (hysteresis)",
              f"omega_b = {fmt(lo, 5)}, omega_c = {fmt(hi, 5)} (width {fmt(w, 3)})",
              agree_if(math.isfinite(w) and w > 0))
    rec.check("a discontinuity at omega_a where contact starts",
              f"omega_a = {fmt(a, 5)}", agree_if(math.isfinite(a)))
    if math.isfinite(a) and math.isfinite(lo):
        rec.check("order of the marked frequencies (figure: omega_a < omega_b < omega_c)",
                  f"omega_a {'<' if a < lo else '>='} omega_b", agree_if(a < lo))
    g1, g2 = linear_grazing_frequencies(p)
    rec.check("cross-check (not in the paper): the free linear response has amplitude 1 at "
              "omega_a and omega_b, independent of omega_s",
              f"linear amplitude = 1 at omega = {fmt(g1, 5)} and {fmt(g2, 5)}; measured "
              f"omega_a = {fmt(a, 5)}, omega_b = {fmt(lo, 5)}", NOT_STATED)
    ctx.savefig(plot_resonance(ds), name)
    return ds, w


def linear_grazing_frequencies(p):
    """The two omegas where the free linear amplitude F0/sqrt((w0^2-w^2)^2+(xi w)^2) equals 1
    (NaN when it never does): (w0^2 - w^2)^2 + (xi w)^2 = F0^2 is a quadratic in w^2."""
    # w^4 + (xi^2 - 2 w0^2) w^2 + w0^4 - F0^2 = 0
    b = p.xi ** 2 - 2 * p.omega0 ** 2
    c = p.omega0 ** 4 - p.F0 ** 2
    disc = b * b - 4 * c
    if disc < 0:
        return float("nan"), float("nan")
    roots = sorted(r for r in ((-b - math.sqrt(disc)) / 2, (-b + math.sqrt(disc)) / 2) if r > 0)
    w = [math.sqrt(r) for r in roots]
    return (w[0], w[1]) if len(w) == 2 else (float("nan"), w[0] if w else float("nan"))


@figure("fig6a", "Resonance curve, omega_s = 3.16",
        "the resonance curve shows a contact discontinuity at omega_a and jumps at omega_b, omega_c")
def fig6a(ctx, rec):
    _fig6(ctx, rec, "fig6a")


@figure("fig6b", "Resonance curve, omega_s = 7.07",
        "as Fig. 6a; the stiffer support enlarges the effect of the dynamical jumps")
def fig6b(ctx, rec):
    _, wb = _fig6(ctx, rec, "fig6b")
    try:
        _, _, _, wa = jump_width(resonance(ctx, "fig6a"))
        rec.check("hardening (omega_s 3.16 -> 7.07) enlarges the jumps: wider hysteresis interval",
                  f"omega_c - omega_b = {fmt(wa, 3)} (6a) -> {fmt(wb, 3)} (6b)",
                  agree_if(math.isfinite(wa) and math.isfinite(wb) and wb > wa))
    except Exception as exc:  # noqa: BLE001
        rec.check("hardening enlarges the jumps", f"Fig. 6a not available: {exc}", DIFFERS)
