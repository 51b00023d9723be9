"""What every figure entry shares: the fixed choices where the paper is silent (quoted in the
report), the section runs, and how the report writes methods, periods and regions."""

from __future__ import annotations

from ..access import number, value
from ..core import fmt, period_text

# -- fixed choices where the paper is silent (quoted in the report) ---------------------------
#: initial condition of every single-trajectory run unless the figure states another
IC = (0.0, 0.0)
#: window of the basins of attraction (the paper's Fig. 7 axes are not given in the text)
BASIN_WINDOW = ((-3.0, 3.0), (-3.0, 3.0))
#: "just after grazing": the first chaotic value lies within this fraction of the swept range
#: after the first value with contact
JUST_AFTER = 0.05
#: the initial conditions tried when a detected attractor differs from the paper's
EXPLORE_ICS = ((0.0, 0.0), (0.5, 0.0), (1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0),
               (-2.0, 2.0), (2.0, -2.0))
#: the regions of eq. 14 by code, as the report writes them
REGIONS = ("Gamma-", "Sigma_alpha", "Sigma_beta", "Gamma+")


def method_text(ds) -> str:
    a = ds.attrs
    m = str(a.get("method", "smooth"))
    parts = [m]
    if m in ("smooth", "smooth_eq12"):
        parts.append(f"switch model ({'eq12' if m == 'smooth_eq12' else 'eq13'}), RKF45")
    elif m == "smooth_closed_form":
        parts.append("switch model (eq13) solved exactly: closed form, RKF45 in Sigma_alpha")
    else:
        parts.append("exact non-smooth, closed form between events")
    if "rtol" in a:
        parts.append(f"rtol={fmt(a['rtol'], 2)}, atol={fmt(a.get('atol', float('nan')), 2)}")
    return ", ".join(parts)


def gap(ctx, key: str, text: str) -> None:
    """Evidence for the report's section on the paper's gaps (computed by this figure)."""
    ctx.current.gaps.append([key, text])


def point_summary(ds) -> str:
    return (f"{period_text(value(ds, 'period'))}, max X = {fmt(value(ds, 'max_X'), 7)}, "
            f"contact = {int(value(ds, 'contact', 0))}")


def run_poincare(ctx, params, *, x0=IC[0], v0=IC[1], method="smooth", record=None,
                 transient=None):
    from ...analysis.poincare import poincare
    return poincare(params, record=record or ctx.setting("fig10, fig12", "record"),
                    transient=transient or ctx.setting("fig10, fig12", "transient"), x0=x0, v0=v0,
                    method=method, orbit_samples=1000,
                    # lambda1 where the figures report it (not for the eq. 12 variant runs)
                    lyapunov=method != "smooth_eq12")


def try_exact(ctx, params, **kw):
    """Poincaré data of the exact model at the same point, or the error text."""
    try:
        return run_poincare(ctx, params, method="exact", **kw), ""
    except Exception as exc:  # noqa: BLE001 - evidence only
        return None, f"{type(exc).__name__}: {exc}"


def settle_text(ds) -> str:
    return (f"IC ({fmt(ds.attrs.get('x0', 0))}, {fmt(ds.attrs.get('v0', 0))}) at t = 0, "
            f"transient {int(number(ds, 'transient'))} periods, {ds.sizes.get('n', 0)} section "
            f"points at t = kT (forcing phase 0)")


def region_names(mask: int) -> str:
    """The regions of a visited bit mask (bit r = region code r), as the report writes them."""
    return ", ".join(n for r, n in enumerate(REGIONS) if mask >> r & 1) or "no region"


# -- coexisting attractors (notes: the paper mentions none of them) -----------------------------
def ic_grid(n: int, window=BASIN_WINDOW) -> list[tuple[float, float]]:
    """n x n initial conditions (X0, V0) on the basin window, at forcing phase 0."""
    import numpy as np
    return [(float(x), float(v)) for x in np.linspace(*window[0], n)
            for v in np.linspace(*window[1], n)]


def orbit_text(o) -> str:
    """A ``periodic_orbit`` result: section point, Floquet multipliers and stability."""
    import numpy as np
    k = o.sizes.get("point", 1)
    if o.attrs.get("status") != "converged":
        return f"Newton shooting for period {k}: {o.attrs.get('status')}"
    mu = np.asarray(o["multiplier_real"].values) + 1j * np.asarray(o["multiplier_imag"].values)
    mus = ", ".join(f"{m.real:.4g}{m.imag:+.4g}i" if abs(m.imag) > 1e-12 else f"{m.real:.4g}"
                    for m in mu)
    return (f"period-{k} orbit through (X, V) = ({fmt(o['X_section'].values[0], 6)}, "
            f"{fmt(o['V_section'].values[0], 6)}), Floquet multipliers {mus} (largest |mu| = "
            f"{fmt(np.max(np.abs(mu)), 4)}): {'stable' if bool(o['stable']) else 'unstable'}, "
            f"max X = {fmt(o['max_X'], 6)} (Newton residual {fmt(o.attrs.get('residual'), 2)})")


def find_orbit(params, k: int, x0: float, v0: float, method: str = "exact"):
    from ...analysis.stability import periodic_orbit
    return periodic_orbit(params, k=k, x0=x0, v0=v0, method=method)


def attractor_scan(ctx, params, ics, method: str = "exact"):
    """The attractors reached from ``ics``: {period: [(ic, last section point, lambda1 text)]}
    (Poincaré sections after the "coexisting attractors" transient, lambda1 over the recorded
    periods)."""
    from ..core import lyapunov_text
    transient, record = (ctx.setting("coexisting attractors", k) for k in ("transient", "record"))
    found: dict = {}
    for x0, v0 in ics:
        ds = run_poincare(ctx, params, x0=x0, v0=v0, method=method, transient=transient,
                          record=record)
        per = int(value(ds, "period"))
        found.setdefault(per, []).append(((x0, v0), (float(ds["X"].values[-1]),
                                                     float(ds["V"].values[-1])),
                                          lyapunov_text(ds, with_period=False)))
    return found


def attractor_note(ctx, params, label: str, ics, method: str = "exact") -> str:
    """One note: which attractors the initial conditions ``ics`` reach, each periodic one
    confirmed by Newton shooting (Floquet multipliers), each non-periodic one with lambda1."""
    from ..core import period_text
    transient, record = (ctx.setting("coexisting attractors", k) for k in ("transient", "record"))
    found = attractor_scan(ctx, params, ics, method)
    parts = []
    for per in sorted(found, key=lambda q: (q <= 0, q)):
        hits = found[per]
        (a, b), (xs, vs), ltxt = hits[0]
        txt = f"{period_text(per)} from {len(hits)} of {len(ics)} initial conditions (e.g. ({fmt(a)}, {fmt(b)}))"
        if per > 0:
            try:
                txt += ": " + orbit_text(find_orbit(params, per, xs, vs, method))
            except Exception as exc:  # noqa: BLE001 - evidence only
                txt += f": Newton shooting failed ({exc})"
        else:
            txt += f": {ltxt}"
        parts.append(txt)
    n = int(round(len(ics) ** 0.5))
    return (f"{label} ({method} model; {len(ics)} initial conditions on a {n} x {n} grid of X0 "
            f"in {BASIN_WINDOW[0]}, V0 in {BASIN_WINDOW[1]} at phase 0; transient {transient} "
            f"periods, {record} recorded): " + "; ".join(parts))


def note_safely(rec, make) -> None:
    """Add the note ``make()`` computes; a failure becomes a note too (evidence never stops a
    figure)."""
    try:
        rec.note(make())
    except Exception as exc:  # noqa: BLE001
        rec.note(f"coexisting attractors: computation failed ({type(exc).__name__}: {exc})")
