"""Figs. 10 and 12: single points of the diagrams (phase portrait and Poincaré section)."""

from __future__ import annotations

import math

import numpy as np

from ...models.support import preset
from ..access import number, value
from ..core import DIFFERS, agree_if, figure, fmt, lyapunov_text, period_text, verdict_period
from ._common import (EXPLORE_ICS, attractor_note, find_orbit, gap, ic_grid, method_text,
                      note_safely, orbit_text, point_summary, run_poincare, settle_text,
                      try_exact)
from .fig09_11_bifurcation import branch


def _point_figure(ctx, rec, fid, name, changes, claimed_period, title, contact_claim=None):
    from ...plot.reproduce_panels import plot_section_panel
    p = preset(name).replace(**changes)
    ds = run_poincare(ctx, p)
    ds.attrs["preset"] = name
    rec.use_params(p, preset=name)
    rec.method = method_text(ds)
    rec.settings = {"section": settle_text(ds)}
    exact, err = try_exact(ctx, p)
    ev = (f"exact model, same IC: {point_summary(exact)}" if exact is not None
          else f"exact model not available ({err})")
    got = int(value(ds, "period"))
    v = verdict_period(claimed_period, got)
    lyap = ""
    if claimed_period == 0 or got == 0:  # a claim of chaos: lambda1 over the recorded periods
        lyap = f"; {lyapunov_text(ds, with_period=False)}"
        if exact is not None:
            ev += f" ({lyapunov_text(exact, with_period=False)})"
    if v == DIFFERS:
        ev += "; " + explore(ctx, p, claimed_period)
    rec.check(f"{title}: {period_text(claimed_period)}",
              f"{period_text(got)} (max X = {fmt(value(ds, 'max_X'), 5)}){lyap}", v, ev)
    if contact_claim is not None:
        text, want_contact = contact_claim
        con = int(value(ds, "contact"))
        ev2 = contact_evidence(ctx, p, exact)
        rec.check(text, f"contact = {con}, max X = {fmt(value(ds, 'max_X'), 5)}",
                  agree_if(con == want_contact), ev2)
    if exact is not None:
        exact.attrs["preset"] = name
        ctx.save(exact, f"{fid}_exact")
    ctx.save(ds, fid)
    ctx.savefig(plot_section_panel(ds, title=f"Fig. {fid[3:]}: {title}", exact=exact), fid)
    return p, ds


def explore(ctx, params, claimed_period: int) -> str:
    """Evidence for a differing period: other initial conditions, a 4x longer transient and the
    exact model at the same parameters. Returns one paragraph."""
    record, transient = (ctx.setting("fig10, fig12: other ICs", k)
                         for k in ("record", "transient"))
    found = []
    for x0, v0 in EXPLORE_ICS:
        try:
            ds = run_poincare(ctx, params, x0=x0, v0=v0, record=record, transient=transient)
            found.append(((x0, v0), int(value(ds, "period")), int(value(ds, "contact"))))
        except Exception as exc:  # noqa: BLE001
            found.append(((x0, v0), None, str(exc)))
    hits = [ic for ic, p, _ in found if p == claimed_period]
    periods = sorted({p for _, p, _ in found if p is not None})
    txt = (f"initial conditions {', '.join(f'({a:g},{b:g})' for (a, b), _, _ in found)} give "
           f"periods {periods} (0 = not periodic, -1 = not settled)")
    if hits:
        txt += (f"; the paper's period {claimed_period} is reached from "
                f"{', '.join(f'({a:g},{b:g})' for a, b in hits)}: coexisting attractors, the paper's "
                "initial condition is not stated")
    else:
        txt += f"; none reaches the paper's period {claimed_period}"
    try:
        long = run_poincare(ctx, params, transient=4 * transient, record=record)
        txt += f"; with a 4x longer transient from (0,0): {period_text(value(long, 'period'))}"
    except Exception as exc:  # noqa: BLE001
        txt += f"; longer transient failed: {exc}"
    return txt


def linear_amplitude(p) -> float:
    """Steady amplitude of the free (no-contact, linear) oscillator: F0/sqrt((w0^2-w^2)^2+(xi w)^2)."""
    return p.F0 / math.hypot(p.omega0 ** 2 - p.omega ** 2, p.xi * p.omega)


def contact_evidence(ctx, p, exact) -> str:
    """Why an orbit touches the support or not, from numbers of this run."""
    a = linear_amplitude(p)
    parts = [f"without contact the oscillator is linear: its only steady response is period 1 "
             f"with amplitude {a:.4f} {'>' if a > 1 else '<='} 1 (the gap), so any period > 1 "
             f"orbit must touch the support"]
    if exact is not None:
        parts.append(f"exact model: max X = {fmt(value(exact, 'max_X'), 5)}, "
                     f"contact {int(value(exact, 'contact'))}")
    for key, entry in ctx.cache.items():
        if not key.startswith("bifurcation:"):
            continue
        kind, ds = entry
        if kind == "ok" and ds.attrs.get("swept_param") == "omega" \
                and math.isclose(number(ds, "param_F0"), p.F0):
            values, _, con = branch(ds, "up")
            if np.any(con > 0):
                parts.append(f"the Fig. 9 up sweep first touches the support at omega = "
                             f"{fmt(values[np.argmax(con > 0)], 5)}")
    return "; ".join(parts)


def variant_evidence(ctx, p, ds, label, eta_used):
    """For the report's gap section: the same point with eta = 1e-5 (the stated reference) and
    with the convex transitions of eq. 12."""
    try:
        alt = run_poincare(ctx, p.replace(eta=1e-5))
        gap(ctx, "eta", f"{label} with eta = 1e-5 instead of {eta_used:g}: {point_summary(alt)} "
                        f"(with {eta_used:g}: {point_summary(ds)})")
        alt12 = run_poincare(ctx, p, method="smooth_eq12")
        gap(ctx, "eq12", f"{label} with eq. 12: {point_summary(alt12)} "
                         f"(with eq. 13: {point_summary(ds)})")
    except Exception as exc:  # noqa: BLE001
        gap(ctx, "eta", f"{label} variant runs failed: {exc}")


@figure("fig10a", "Table 3, omega = 0.91", "period-3 orbit, in the imminence of grazing contact")
def fig10a(ctx, rec):
    p, ds = _point_figure(ctx, rec, "fig10a", "table3", {"omega": 0.91}, 3, "omega = 0.91",
                          ("'in the imminence of grazing contact': the orbit does not yet touch "
                           "the support (max X < 1)", 0))
    variant_evidence(ctx, p, ds, "Fig. 10a", 6.25e-6)


@figure("fig10b", "Table 3, omega = 0.92", "chaotic: the orbit reaches the support")
def fig10b(ctx, rec):
    p, _ = _point_figure(ctx, rec, "fig10b", "table3", {"omega": 0.92}, 0, "omega = 0.92",
                         ("the system reaches the support (contact)", 1))
    note_safely(rec, lambda: attractor_note(
        ctx, p, "Coexisting attractors at omega = 0.92 (not in the paper)",
        ic_grid(ctx.setting("coexisting attractors", "grid"))))
    note_safely(rec, lambda: coexistence_range(ctx, p))


def coexistence_range(ctx, p) -> str:
    """Where the period-3 orbit of Fig. 10a and the chaotic attractor of Fig. 10b coexist (exact
    model): the period-3 orbit continued in omega by Newton shooting from the Fig. 10a orbit
    (stable while all |mu| < 1), and the chaotic attractor followed by a down sweep from (0, 0)
    (chaotic while lambda1 > 3 errors)."""
    from ...analysis.bifurcation import bifurcation_diagram
    from ...analysis.stability import CHAOTIC
    g = "fig10b: coexistence range"
    lo, hi, step, transient, record = (ctx.setting(g, k) for k in (
        "omega from", "omega to", "omega step", "transient", "record"))
    values = np.round(lo + step * np.arange(int(round((hi - lo) / step)) + 1), 10)
    # the period-3 orbit, continued up and down from omega = 0.91 (Fig. 10a)
    start = run_poincare(ctx, p.replace(omega=0.91), method="exact", transient=transient,
                         record=60)
    seed = (float(start["X"].values[-1]), float(start["V"].values[-1]))
    stable, last = {}, {}
    for side in (values[values >= 0.91], values[values < 0.91][::-1]):
        x, v = seed
        for om in side:
            o = find_orbit(p.replace(omega=float(om)), 3, x, v)
            if o.attrs.get("status") != "converged" or o.sizes.get("point") != 3:
                break
            x, v = float(o["X_section"].values[0]), float(o["V_section"].values[0])
            stable[float(om)] = bool(o["stable"])
            last[float(om)] = o
    p3 = sorted(om for om, s in stable.items() if s)
    # the chaotic attractor, by a down sweep (each value from the state of the previous one)
    ds = bifurcation_diagram(p, "omega", values, sweep="down", transient=transient, record=record,
                             method="exact", x0=0.0, v0=0.0, workers=ctx.workers)
    om = np.asarray(ds["omega"].values, dtype=float)
    mot = np.asarray(ds["motion"].values).reshape(-1, om.size)[0]
    chaos = om[mot == CHAOTIC]
    both = [w for w in p3 if w in set(chaos.tolist())]
    txt = (f"omega range of the coexistence (exact model, omega = {fmt(lo)} .. {fmt(hi)} in steps "
           f"of {fmt(step)}): a stable period-3 orbit (continued from Fig. 10a's by Newton "
           f"shooting) exists for omega = {fmt(p3[0], 5)} .. {fmt(p3[-1], 5)}" if p3 else
           "omega range of the coexistence: no stable period-3 orbit found by continuation")
    if p3:
        o_hi = last[p3[-1]]
        txt += (f" (largest |mu| = {fmt(np.max(o_hi['multiplier_abs'].values), 4)} at "
                f"{fmt(p3[-1], 5)}; Newton shooting finds no period-3 orbit at "
                f"{fmt(p3[-1] + step, 5)}" if p3[-1] + step <= hi + 1e-12 else ")")
        txt += ")" if p3[-1] + step <= hi + 1e-12 else ""
    txt += (f"; a down sweep from (0, 0) stays chaotic (lambda1 > 3 errors) for omega = "
            f"{fmt(chaos.min(), 5)} .. {fmt(chaos.max(), 5)} ({chaos.size} of {om.size} values, "
            f"transient {transient}, {record} recorded)" if chaos.size else
            "; the down sweep finds no chaotic value")
    if both:
        txt += (f"; both attractors coexist for omega = {fmt(min(both), 5)} .. "
                f"{fmt(max(both), 5)} ({len(both)} grid values)")
    else:
        txt += "; no value where both were found"
    return txt


@figure("fig12a", "Table 4, F0 = 0.225", "period-4 orbit")
def fig12a(ctx, rec):
    p, ds = _point_figure(ctx, rec, "fig12a", "table4", {"F0": 0.225}, 4, "F0 = 0.225")
    variant_evidence(ctx, p, ds, "Fig. 12a", 5e-6)


@figure("fig12b", "Table 4, F0 = 0.35", "chaotic")
def fig12b(ctx, rec):
    _point_figure(ctx, rec, "fig12b", "table4", {"F0": 0.35}, 0, "F0 = 0.35")


@figure("fig12c", "Table 4, F0 = 0.40", "period-2 orbit")
def fig12c(ctx, rec):
    p, ds = _point_figure(ctx, rec, "fig12c", "table4", {"F0": 0.40}, 2, "F0 = 0.40")
    gap(ctx, "table4", f"Fig. 12 runs use xi = {p.xi:g} and xi_s = {p.xi_s:g} (the second 'xi' "
                       f"column of Table 4 read as xi_s)")
