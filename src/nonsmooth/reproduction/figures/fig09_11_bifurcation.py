"""Figs. 9 and 11: bifurcation diagrams in omega (Table 3) and F0 (Table 4)."""

from __future__ import annotations

import math

import numpy as np

from ...models.support import preset
from ..core import DIFFERS, agree_if, figure, fmt, lyapunov_text, period_text
from ._common import IC, JUST_AFTER, method_text


def bifurcation(ctx, name, param, lo, hi, step):
    """Diagram on a grid of spacing ``step`` (divided by the "step divisor" setting) so that
    the paper's single points (Figs. 10, 12) are grid values."""
    from ...analysis.bifurcation import bifurcation_diagram
    p = preset(name)
    step = step / ctx.setting("fig9, fig11", "step divisor")
    values = np.round(lo + step * np.arange(int(round((hi - lo) / step)) + 1), 10)
    kw = dict(sweep="both", transient=ctx.setting("fig9, fig11", "transient"),
              record=ctx.setting("fig9, fig11", "record"),
              method="smooth", workers=ctx.workers, x0=IC[0], v0=IC[1])
    ds = ctx.shared(f"bifurcation:{name}:{param}",
                    lambda: bifurcation_diagram(p, param, values, **kw))
    return p, values, kw, ds


def branch(ds, sweep="up"):
    """(values, period, contact) of one sweep of a bifurcation Dataset, sorted by value.
    ``contact`` is the Dataset's 0/1 variable, or max X >= 1 when it has none."""
    par = ds.attrs.get("swept_param") or ds.attrs.get("param")
    dims = [d for d in ds["period"].dims if d != "sweep"]
    vname = par if par in ds.coords else dims[0]
    per = ds["period"]
    con = ds["contact"] if "contact" in ds else (ds["max_X"] >= 1.0)
    if "sweep" in per.dims:
        from ...plot.bifurcation import sweep_names
        sweeps = sweep_names(ds)
        k = sweeps.index(sweep) if sweep in sweeps else 0
        per, con = per.isel(sweep=k), con.isel(sweep=k)
    vals = np.asarray(ds[vname].values, dtype=float)
    order = np.argsort(vals)
    return (vals[order], np.asarray(per.values)[order].astype(int),
            np.asarray(con.values)[order].astype(int))


def lambda1_at(ds, v, sweep="up", with_period=False) -> str:
    """:func:`lyapunov_text` of the diagram's point nearest ``v`` in sweep ``sweep``."""
    if "lambda1" not in ds or not math.isfinite(v):
        return "lambda1 not computed"
    par = ds.attrs.get("swept_param") or ds.attrs.get("param")
    sel = {par: float(v)}
    if "sweep" in ds["lambda1"].dims:
        from ...plot.bifurcation import sweep_names
        sweeps = sweep_names(ds)
        sel["sweep"] = sweeps.index(sweep) if sweep in sweeps else 0
    return lyapunov_text(ds, with_period=with_period, **sel)


def motion_counts(ds, sweep, period) -> str:
    """How lambda1 classifies the non-periodic values of one sweep (``period`` from
    :func:`branch`, sorted by value): chaotic / within the errors of 0 / contracting."""
    if "lambda1" not in ds:
        return "lambda1 not computed"
    from ...analysis.stability import CHAOTIC, N_SIGMA
    par = ds.attrs.get("swept_param") or ds.attrs.get("param")
    lam, err, mot = (ds[k] for k in ("lambda1", "lambda1_stderr", "motion"))
    if "sweep" in lam.dims:
        from ...plot.bifurcation import sweep_names
        sweeps = sweep_names(ds)
        k = sweeps.index(sweep) if sweep in sweeps else 0
        lam, err, mot = (a.isel(sweep=k) for a in (lam, err, mot))
    order = np.argsort(np.asarray(ds[par].values, dtype=float))
    lam, err, mot = (np.asarray(a.values)[order] for a in (lam, err, mot))
    z = period == 0
    chaotic = int(np.sum(z & (mot == CHAOTIC)))
    near0 = int(np.sum(z & (np.abs(lam) <= N_SIGMA * err)))
    neg = int(np.sum(z & (lam < -N_SIGMA * err)))
    run = longest_run(z & (mot == CHAOTIC))
    return (f"lambda1 of the {int(z.sum())} non-periodic values: > {N_SIGMA:g} errors above 0 "
            f"(chaotic) at {chaotic}, within {N_SIGMA:g} errors of 0 (quasi-periodic or a long "
            f"transient) at {near0}, below 0 (a transient or a long period) at {neg}; longest run "
            f"of chaotic values {run}; lambda1 over the recorded periods per value")


def grazing_then_chaos(values, period, contact):
    """(first value with contact, first chaotic value at or after it, first chaotic value)."""
    contact = np.where(contact > 0)[0]
    chaos = np.where(period == 0)[0]
    g = values[contact[0]] if contact.size else float("nan")
    c_any = values[chaos[0]] if chaos.size else float("nan")
    after = chaos[chaos >= contact[0]] if contact.size else np.array([], int)
    c = values[after[0]] if after.size else float("nan")
    return g, c, c_any


def longest_run(mask):
    best = cur = 0
    for m in mask:
        cur = cur + 1 if m else 0
        best = max(best, cur)
    return best


def value_at(values, period, contact, v):
    i = int(np.argmin(np.abs(values - v)))
    return values[i], int(period[i]), int(contact[i])


def _bif_figure(ctx, rec, fid, name, param, lo, hi, step):
    from ...plot.bifurcation import plot_bifurcation
    p, values, kw, ds = bifurcation(ctx, name, param, lo, hi, step)
    rec.use_params(p, preset=name, **{param: f"{lo} .. {hi}, {values.size} values (swept)"})
    rec.method = method_text(ds)
    rec.settings = {"sweeps": "up and down, each value starts from the previous state",
                    "start": f"{IC} at the first value",
                    "transient": f"{kw['transient']} periods", "recorded": f"{kw['record']} periods"}
    ds = ds.copy()
    ds.attrs["preset"] = name
    ctx.save(ds, fid)
    ctx.savefig(plot_bifurcation(ds), fid)
    return ds


def point_in_diagram(rec, ds, param, at, want, where):
    """The paper's single point read off both sweeps of the diagram. When the sweeps end on
    different (coexisting) attractors there are two rows: whether one of them is the paper's
    (agrees if so), and the coexistence, which the paper's diagram does not show (differs). A
    sweep that has not settled there counts for neither."""
    got = {}
    for sweep in ("up", "down"):
        values, period, con = branch(ds, sweep)
        v, got[sweep], _ = value_at(values, period, con, at)
    txt = f"at {param} = {fmt(v, 5)}: " + ", ".join(f"{s} sweep {period_text(q)}"
                                                   for s, q in got.items())
    if want == 0 or 0 in got.values():  # a claim of chaos, or a sweep without a period
        txt += " (" + "; ".join(f"{s}: {lambda1_at(ds, v, s)}" for s in got) + ")"
    claim = f"diagram at {param} = {at}: {period_text(want)} ({where})"
    settled = {s: q for s, q in got.items() if q >= 0}  # a not-settled sweep is no attractor
    if len(set(settled.values())) <= 1:
        rec.check(claim, txt, agree_if(want in settled.values()))
        return
    match = [s for s, q in settled.items() if q == want]
    other = [s for s, q in settled.items() if q != want]
    rec.check(claim, f"{txt}: two attractors coexist; the "
                     f"{' and '.join(match) + ' sweep' if match else 'neither sweep'} "
                     "ends on the paper's", agree_if(match))
    rec.check(f"diagram at {param} = {at}: one attractor, the paper's ({where}; the paper "
              "mentions no coexisting attractor)",
              "a coexisting attractor the paper's diagram does not show: "
              + ", ".join(f"{s} sweep {period_text(got[s])}" for s in other), DIFFERS)


def _grazing_checks(rec, ds, param, lo, hi, sweep="up"):
    values, period, con = branch(ds, sweep)
    g, c, c_any = grazing_then_chaos(values, period, con)
    rng = hi - lo
    rec.check(f"{sweep} sweep: no chaos before contact (the free oscillator is linear)",
              f"first chaotic {param} = {fmt(c_any, 5)}, first contact {param} = {fmt(g, 5)}"
              + (f"; at {param} = {fmt(c_any, 5)}: {lambda1_at(ds, c_any, sweep)}"
                 if math.isfinite(c_any) else ""),
              agree_if(math.isfinite(g) and (not math.isfinite(c_any) or c_any >= g)))
    rec.check(f"{sweep} sweep: chaos appears just after grazing "
              f"(within {JUST_AFTER:.0%} of the range)",
              f"grazing at {param} = {fmt(g, 5)}, chaos from {fmt(c, 5)} "
              f"(gap {fmt(c - g, 3)}, limit {fmt(JUST_AFTER * rng, 3)})"
              + (f"; at {param} = {fmt(c, 5)}: {lambda1_at(ds, c, sweep)}" if math.isfinite(c)
                 else ""),
              agree_if(math.isfinite(c) and math.isfinite(g) and 0 <= c - g <= JUST_AFTER * rng))
    run = longest_run(period == 0)
    step = (values[-1] - values[0]) / max(values.size - 1, 1)
    rec.check("the response is irregular over a range of the parameter",
              f"{int(np.sum(period == 0))} of {values.size} values not periodic"
              f"{f', {n} not settled' if (n := int(np.sum(period < 0))) else ''}; longest run "
              f"{run} values ({fmt(run * step, 3)} wide); {motion_counts(ds, sweep, period)}",
              agree_if(run >= 3))
    return values, period, con


@figure("fig9", "Bifurcation diagram in omega (Table 3)",
        "the motion quickly moves into chaos just after grazing, and stays irregular over a "
        "range of frequencies")
def fig9(ctx, rec):
    ds = _bif_figure(ctx, rec, "fig9", "table3", "omega", 0.8, 1.0, 0.0025)
    values, period, con = _grazing_checks(rec, ds, "omega", 0.8, 1.0)
    for om, want in ((0.91, 3), (0.92, 0)):
        point_in_diagram(rec, ds, "omega", om, want, "Fig. 10")


@figure("fig11", "Bifurcation diagram in F0 (Table 4)",
        "after periodic behaviour chaotic regions appear; grazing occurs just before the birth "
        "of the chaotic attractor")
def fig11(ctx, rec):
    ds = _bif_figure(ctx, rec, "fig11", "table4", "F0", 0.1, 0.45, 0.005)
    values, period, con = _grazing_checks(rec, ds, "F0", 0.1, 0.45)
    first = values < values[0] + 0.1 * (values[-1] - values[0])
    rec.check("the diagram starts with periodic behaviour",
              f"periods over the first 10% of the range: {sorted(set(period[first].tolist()))}",
              agree_if(np.all(period[first] > 0)))
    for f0, want in ((0.225, 4), (0.35, 0), (0.40, 2)):
        point_in_diagram(rec, ds, "F0", f0, want, "Fig. 12")
