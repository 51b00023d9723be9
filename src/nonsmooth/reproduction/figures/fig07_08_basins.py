"""Figs. 7 and 8: basins of attraction and the coexisting periodic attractors."""

from __future__ import annotations

import math

import numpy as np

from ...models.support import preset
from ..core import DIFFERS, NOT_STATED, agree_if, figure, fmt, period_text
from ._common import BASIN_WINDOW, find_orbit, gap, method_text, note_safely, orbit_text
from .fig06_resonance import jump_width, resonance


def basins_at(ctx, omega):
    from ...analysis.basins import basins
    p = preset("fig7").replace(omega=omega)
    g = ctx.setting("fig7", "grid")
    kw = dict(x=BASIN_WINDOW[0], v=BASIN_WINDOW[1], grid=g, method="smooth", workers=ctx.workers)
    return ctx.shared(f"basins:{omega}", lambda: basins(p, **kw))


def attractor_table(ds):
    """[(index, fraction, period, contact)] of the attractors, largest basin first."""
    n = ds.sizes.get("attractor", 0)
    rows = []
    for i in range(n):
        rows.append((i, float(ds["fraction"].values[i]), int(ds["period"].values[i]),
                     int(ds["contact"].values[i])))
    return sorted(rows, key=lambda r: -r[1])


def contact_fraction(ds):
    return sum(f for _, f, _, c in attractor_table(ds) if c == 1)


def undecided_fraction(ds):
    lab = ds["label"].values
    return float(np.mean(lab < 0))


def _basin_checks(rec, ds, omega):
    rows = attractor_table(ds)
    desc = "; ".join(f"#{i}: {100 * f:.1f}% of ICs, {period_text(p)}, "
                     f"{'contact' if c else 'no contact'}" for i, f, p, c in rows)
    big = [r for r in rows if r[1] >= 0.001]
    rec.check(f"omega = {omega}: two coexisting periodic attractors",
              f"{len(rows)} attractor(s) ({desc}); undecided {100 * undecided_fraction(ds):.1f}%",
              agree_if(len(big) == 2 and all(r[2] > 0 for r in big)))
    rec.check(f"omega = {omega}: one attractor with contact, one without",
              f"contact flags of the attractors: {sorted(r[3] for r in big)}",
              agree_if(sorted(r[3] for r in big) == [0, 1]))


def _fig7(ctx, rec, omega, name):
    from ...plot.basins import plot_basins
    ds = basins_at(ctx, omega)
    p = preset("fig7").replace(omega=omega)
    rec.use_params(p, preset="fig7")
    rec.method = method_text(ds)
    g = ds.sizes.get("x0", 0)
    rec.settings = {"grid": f"{g} x {ds.sizes.get('v0', 0)} on X0 in {BASIN_WINDOW[0]}, "
                            f"V0 in {BASIN_WINDOW[1]} at forcing phase 0",
                    **{k: str(ds.attrs[k]) for k in ("transient", "max_periods", "points")
                       if k in ds.attrs}}
    ds = ds.copy()
    ds.attrs["preset"] = "fig7"
    ctx.save(ds, name)
    _basin_checks(rec, ds, omega)
    ctx.savefig(plot_basins(ds), name)
    return ds


@figure("fig7a", "Basins of attraction, omega_s = 3.16, omega = 1.10",
        "two coexisting periodic attractors, one with contact and one without")
def fig7a(ctx, rec):
    ds = _fig7(ctx, rec, 1.10, "fig7a")
    rec.check("contact basin share at omega = 1.10 (not stated)",
              f"{100 * contact_fraction(ds):.1f}% of the grid", NOT_STATED)


@figure("fig7b", "Basins of attraction, omega_s = 3.16, omega = 1.18",
        "as Fig. 7a; 'the light attractor increases its size' as omega goes from 1.10 to 1.18")
def fig7b(ctx, rec):
    ds = _fig7(ctx, rec, 1.18, "fig7b")
    fb = contact_fraction(ds)
    nb_ = 1.0 - fb - undecided_fraction(ds)
    try:
        da = basins_at(ctx, 1.10)
    except Exception as exc:  # noqa: BLE001
        rec.check("the light (no-contact) basin grows from omega = 1.10 to 1.18",
                  f"basins at 1.10 not available: {exc}", DIFFERS)
        return
    fa = contact_fraction(da)
    na = 1.0 - fa - undecided_fraction(da)
    gap(ctx, "fig7", f"no-contact basin {100 * na:.1f}% -> {100 * nb_:.1f}% and contact basin "
                     f"{100 * fa:.1f}% -> {100 * fb:.1f}% of the grid from omega = 1.10 to 1.18")
    # The paper first defines light = no contact; its next two sentences swap the colours.
    rec.check("'the light attractor increases its size' with light = no contact (the paper's "
              "definition of the colours)",
              f"no-contact basin {100 * na:.1f}% -> {100 * nb_:.1f}% of the grid",
              agree_if(nb_ > na))
    ev, verdict = basin_ends_evidence(ctx)
    rec.check("'when omega = omega_b all initial conditions lead to the non-impact attractor'; "
              "'when omega = omega_c all lead to the impact basin'", ev, verdict,
              "the paper's later sentences call the non-impact attractor dark and the impact "
              "basin light, the reverse of its definition; read with the definition (light = "
              "no contact) they would say the opposite ends, which is what the branches show")


def basin_ends_evidence(ctx):
    """Which attractor survives at each end of the hysteresis interval, from the Fig. 6a
    resonance branches: the only branch just below omega_b and just above omega_c."""
    try:
        ds = resonance(ctx, "fig6a")
    except Exception as exc:  # noqa: BLE001
        return f"(resonance curve of Fig. 6a not available: {exc})", NOT_STATED
    _, lo, hi, _ = jump_width(ds)
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return "no hysteresis interval found in the Fig. 6a data", NOT_STATED
    om = ds["omega"].values
    below = int(np.searchsorted(om, lo)) - 1
    above = int(np.searchsorted(om, hi, side="right"))
    if below < 0 or above >= om.size:
        return "the hysteresis interval touches the swept range", NOT_STATED
    c_below = sorted(set(int(v) for v in ds["contact"].values[:, below]))
    c_above = sorted(set(int(v) for v in ds["contact"].values[:, above]))
    txt = (f"Fig. 6a branches (up and down sweeps): just below omega_b = {fmt(lo, 5)} "
           f"(omega = {fmt(om[below], 4)}) the only attractor has contact = {c_below}; just above "
           f"omega_c = {fmt(hi, 5)} (omega = {fmt(om[above], 4)}) it has contact = {c_above}. "
           f"Below omega_b the free response would exceed the gap, so no non-impact orbit "
           f"exists there; the contact (hardening) branch ends at omega_c.")
    return txt, agree_if(c_below == [0] and c_above == [1])


@figure("fig8", "Coexisting periodic attractors at omega = 1.10",
        "at omega = 1.10 two periodic attractors coexist (one with contact, one without)")
def fig8(ctx, rec):
    import xarray as xr

    from ...analysis.poincare import poincare
    from ...plot.reproduce_panels import plot_coexisting
    bas = basins_at(ctx, 1.10)
    p = preset("fig7")
    rec.use_params(p, preset="fig7")
    rows = attractor_table(bas)
    label = bas["label"].values
    xs, vs = bas["x0"].values, bas["v0"].values
    orbits = []
    for i, frac, per, con in rows:
        if frac < 0.001:
            continue
        idx = np.argwhere(label == i)
        # the IC of the basin closest to its centroid (deterministic, inside the basin)
        c = idx.mean(axis=0)
        j = idx[int(np.argmin(((idx - c) ** 2).sum(axis=1)))]
        x0, v0 = float(xs[j[0]]), float(vs[j[1]])
        ds = poincare(p, record=ctx.setting("fig8", "record"),
                      transient=ctx.setting("fig8", "transient"), x0=x0, v0=v0,
                      orbit_periods=max(per, 1))
        o = ds[["X", "V", "orbit_X", "orbit_V", "orbit_region", "period", "contact",
                "max_X"]].reset_coords(drop=True).expand_dims(attractor=[i])
        o["x0"] = ("attractor", [x0], {"long_name": "initial X of the orbit", "units": "1"})
        o["v0"] = ("attractor", [v0], {"long_name": "initial V of the orbit", "units": "1/s"})
        o["basin_fraction"] = ("attractor", [frac], {
            "long_name": "fraction of the Fig. 7a grid in the attractor's basin", "units": "1"})
        orbits.append(o)
        rec.method = method_text(ds)
    if not orbits:
        raise RuntimeError("the basins at omega = 1.10 found no attractor")
    ods = xr.concat(orbits, dim="attractor", join="outer")
    ods.attrs.update({k: v for k, v in bas.attrs.items() if isinstance(v, (int, float, str))})
    ods.attrs["analysis"] = "coexisting attractors (from the Fig. 7a basins)"
    ods["attractor"].attrs.update(long_name="attractor label of the Fig. 7a basins", units="1")
    rec.settings = {"initial conditions": "one per basin, the grid point nearest the basin's "
                                          "centroid (from the Fig. 7a basins)"}
    ctx.save(ods, "fig8")
    ctx.savefig(plot_coexisting(ods), "fig8")
    per = [int(v) for v in ods.period.values]
    con = [int(v) for v in ods.contact.values]
    rec.check("two coexisting periodic attractors at omega = 1.10",
              "; ".join(f"IC ({fmt(a)}, {fmt(b)}): {period_text(q)}, max X {fmt(m)}"
                        for a, b, q, m in zip(ods.x0.values, ods.v0.values, per, ods.max_X.values)),
              agree_if(len(per) == 2 and all(q > 0 for q in per)))
    rec.check("one with contact, one without", f"contact flags {sorted(con)}",
              agree_if(sorted(con) == [0, 1]))
    note_safely(rec, lambda: saddle_note(p))


#: A start from which Newton shooting reaches the saddle period-1 orbit between the two
#: attractors (found by scanning starts on a grid; every start that converges there gives the
#: same orbit).
SADDLE_START = (-1.5, 0.25)


def saddle_note(p) -> str:
    """The unstable period-1 orbit between the two attractors (not in the paper), by Newton
    shooting on the exact model: its multipliers straddle the unit circle."""
    o = find_orbit(p, 1, *SADDLE_START, method="exact")
    return ("Saddle orbit between the two coexisting attractors (not in the paper; exact model, "
            f"Newton shooting from (X, V) = {SADDLE_START}): " + orbit_text(o))
