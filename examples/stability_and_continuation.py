"""Stability, chaos and continuation of the paper's model, in one script.

1. Fig. 7 (omega = 1.1): the two coexisting period-1 attractors and the saddle orbit between
   them, by Newton shooting, with their Floquet multipliers.
2. Fig. 10b (table 3, omega = 0.92): the Lyapunov spectrum of the chaotic attractor, exact and
   smoothed models; the sum of the exponents is the mean divergence.
3. Fig. 6a: the whole period-1 resonance curve by continuation (the unstable branch between
   the folds included), its grazing and fold points, and the fold pair followed in omega_s.
4. Table 3: the period doubling on the contact branch and the period-2 branch born there.

Usage::

    python examples/stability_and_continuation.py [OUTPUT_DIR]

Writes orbit_fig7.png, lyapunov_fig10b.png, continuation_fig6a.png, folds_omega_s.png.
"""

import sys
from pathlib import Path

import numpy as np

import nonsmooth as ns
from nonsmooth.plot import plot_continuation, plot_lyapunov, plot_orbit
from nonsmooth.plot.continuation import plot_two_parameter


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)

    # 1. Fig. 7: two attractors and the saddle between them
    fig7 = ns.preset("fig7")
    for name, (x0, v0, transient) in {"no contact": (0.0, 0.0, 300),
                                      "contact": (-2.0, -2.0, 300),
                                      "saddle": (-1.5, 0.25, 0)}.items():
        o = ns.periodic_orbit(fig7, x0=x0, v0=v0, transient=transient)
        mu = o.multiplier_real.values + 1j * o.multiplier_imag.values
        print(f"Fig. 7 {name:>10s}: section ({float(o.X_section[0]):+.6f}, "
              f"{float(o.V_section[0]):+.6f}), multipliers {np.round(mu, 4)}, "
              f"{o.attrs['verdict']}, max X = {float(o.max_X):.4f}")
        if name == "saddle":
            plot_orbit(o).savefig(out / "orbit_fig7.png", dpi=120)

    # 2. Fig. 10b: the Lyapunov spectrum of the chaotic attractor
    p10 = ns.preset("table3").replace(omega=0.92)
    for method in ("exact", "smooth"):
        ly = ns.lyapunov(p10, periods=5000, transient=500, method=method)
        print(f"Fig. 10b {method:>6s}: lambda = {np.round(ly.exponent.values, 4)} "
              f"+- {np.round(ly.stderr.values, 4)} 1/s, sum {float(ly.exponent_sum):.5f}: "
              f"{ly.attrs['verdict']}")
        if method == "exact":
            plot_lyapunov(ly).savefig(out / "lyapunov_fig10b.png", dpi=120)

    # 3. Fig. 6a: every period-1 branch, and the folds as omega_s grows
    br = ns.continuation(ns.preset("fig6a").replace(omega=0.5), "omega", bounds=(0.5, 1.6))
    names = {1: "fold", 2: "period doubling", 3: "Neimark-Sacker", 4: "grazing"}
    for t, w in zip(br.special_type.values, br.special_omega.values):
        print(f"Fig. 6a: {names[int(t)]:>15s} at omega = {w:.8f}")
    plot_continuation(br).savefig(out / "continuation_fig6a.png", dpi=120)
    folds = ns.two_parameter_curve(ns.preset("fig6a").replace(omega=0.5), "omega", "omega_s",
                                   np.linspace(3.16, 7.07, 9), special="fold", bounds=(0.5, 1.8))
    plot_two_parameter(folds).savefig(out / "folds_omega_s.png", dpi=120)

    # 4. Table 3: period doubling and the period-2 branch
    t3 = ns.continuation(ns.preset("table3").replace(omega=0.6), "omega", bounds=(0.5, 1.0))
    pd = int(np.flatnonzero(t3.special_type.values == 2)[-1])
    doubled = ns.continuation(ns.preset("table3"), "omega", start=(t3, pd), bounds=(0.9, 1.0),
                              step=0.002, max_points=60)
    print(f"Table 3: period doubling at omega = {float(t3.special_omega[pd]):.8f}; the period-2 "
          f"branch runs from {float(doubled.omega[0]):.5f} to {float(doubled.omega[-1]):.5f} "
          f"({doubled.attrs['status']})")
    print(f"figures in {out}")


if __name__ == "__main__":
    main(Path(sys.argv[1] if len(sys.argv) > 1 else "stability_out"))
