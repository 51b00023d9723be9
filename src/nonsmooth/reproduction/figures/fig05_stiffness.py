"""Fig. 5: the Table 2 response for support stiffnesses up to omega_s = 100."""

from __future__ import annotations

import numpy as np

from ...models.support import MODEL, preset
from ..access import value, x_extrema
from ..core import DIFFERS, NOT_STATED, agree_if, figure, fmt, period_text
from ._common import IC, attractor_note, ic_grid, method_text, note_safely, run_poincare


FIG5_OMEGA_S = (1.0, 3.16, 10.0, 31.6, 100.0)


@figure("fig5", "Table 2 response for several support stiffnesses",
        "the integration has no problems even for high support stiffness (omega_s up to 100)")
def fig5(ctx, rec):
    import time

    import xarray as xr

    from ...plot.reproduce_panels import plot_support_stiffness
    from ...simulate import simulate
    base = preset("table2")
    transient, periods, spp, record = (ctx.setting("fig5", k) for k in
                                       ("transient", "periods", "samples_per_period", "record"))
    rec.use_params(base, preset="table2", omega_s="1, 3.16, 10, 31.6, 100 (not in Table 2)")
    rec.settings = {"initial condition": f"{IC} at t = 0", "transient": f"{transient} periods",
                    "recorded": f"{periods} periods x {spp} samples",
                    "period": f"from {record} section points after the same transient"}
    runs, failures, max_x = [], [], []
    for ws in FIG5_OMEGA_S:
        p = base.replace(omega_s=ws)
        t0 = time.perf_counter()
        try:
            ds = simulate(p, periods=periods, transient=transient, samples_per_period=spp,
                          x0=IC[0], v0=IC[1])
        except Exception as exc:  # noqa: BLE001 - recorded as a failed stiffness
            failures.append((ws, str(exc)))
            continue
        dt = time.perf_counter() - t0
        mx = x_extrema(ds)[0]
        max_x.append((ws, mx))
        ds = ds.expand_dims(omega_s=[ws])
        ds["seconds"] = ("omega_s", [dt], {"long_name": "wall time of the run", "units": "s"})
        runs.append(ds)
        ok = bool(np.all(np.isfinite(ds.X.values)))
        try:
            ex = simulate(p, periods=periods, transient=transient, samples_per_period=spp,
                          x0=IC[0], v0=IC[1], method="exact")
            ev = (f"exact model: max X = {fmt(x_extrema(ex)[0], 7)}, max |X_smooth - X_exact| "
                  f"at the samples = {fmt(np.max(np.abs(ex.X.values - ds.X.values[0])), 3)}")
        except Exception as exc:  # noqa: BLE001
            ev = f"exact model not available: {exc}"
        try:
            sec = run_poincare(ctx, p, record=record, transient=transient)
            per = int(value(sec, "period"))
            ds["period"] = ("omega_s", [per], sec["period"].attrs)
            per = period_text(per)
        except Exception as exc:  # noqa: BLE001
            per = f"period unknown ({exc})"
        rec.check(f"omega_s = {ws:g}: integration succeeds",
                  f"ok in {dt:.2f} s, max X = {fmt(mx, 7)}, contact = {int(mx >= 1)}, {per}",
                  agree_if(ok), ev)
    for ws, err in failures:
        rec.check(f"omega_s = {ws:g}: integration succeeds", f"failed: {err}", DIFFERS)
    if not runs:
        raise RuntimeError("every support stiffness failed")
    ds = xr.concat(runs, dim="omega_s", combine_attrs="drop_conflicts")
    ds.attrs["preset"] = "table2"
    ws = MODEL.param("omega_s")
    ds["omega_s"].attrs.update(long_name=ws.long_name, units=ws.units)
    rec.method = method_text(ds)
    ctx.save(ds, "fig5")
    ctx.savefig(plot_support_stiffness(ds), "fig5")
    rec.check("max X decreases as the support stiffens (not stated)",
              ", ".join(f"{w:g}: {fmt(m, 7)}" for w, m in max_x), NOT_STATED)
    for ws in (31.6, 100.0):  # several attractors coexist there (the runs above show one)
        note_safely(rec, lambda ws=ws: attractor_note(
            ctx, base.replace(omega_s=ws), f"omega_s = {ws:g}: attractors reached from other "
            "initial conditions (the paper states none; the row above follows (0, 0) only)",
            ic_grid(ctx.setting("coexisting attractors", "grid"))))
