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
    if m == "smooth":
        parts.append(f"switch model ({a.get('transition', 'eq13')}), RKF45")
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


def run_poincare(ctx, params, *, x0=IC[0], v0=IC[1], method="smooth", transition="eq13",
                 record=None, transient=None):
    from ...analysis.poincare import poincare
    return poincare(params, record=record or ctx.setting("fig10, fig12", "record"),
                    transient=transient or ctx.setting("fig10, fig12", "transient"), x0=x0, v0=v0,
                    method=method, transition=transition, orbit_samples=1000)


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
