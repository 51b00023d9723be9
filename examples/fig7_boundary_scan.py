"""Is Fig. 7's basin boundary ever fractal? The saddle between its two attractors is followed
along omega across the coexistence range (from 1.10 both ways, by Newton shooting) and along
F0 and xi at omega = 1.10; at each value its manifolds are grown in the window of Fig. 7 and
their homoclinic crossings counted (a crossing is where a boundary turns fractal; none means
the boundary is the saddle's smooth stable manifold).

Run: python examples/fig7_boundary_scan.py   (exact method; about 40 s on 2 cores)
"""

import numpy as np

import nonsmooth as ns
from nonsmooth.io import components


def scan(p, orbit, name, values):
    """(value, crossings, saddle multiplier) along ``name``, the saddle continued from
    ``orbit`` (at p); stops where it is lost (a fold of the saddle)."""
    u = components(orbit, suffix="_section").values[0]
    rows = []
    for value in values:
        pv = p.replace(**{name: float(value)})
        o = ns.periodic_orbit(pv, u0=[float(c) for c in u])
        if o.attrs["converged"] != 1 or not float(o.multiplier_abs[0]) > 1.0:
            rows.append((value, None, None))
            break
        u = components(o, suffix="_section").values[0]
        m = ns.manifolds(pv, o, x=(-3, 3), v=(-3, 3))
        rows.append((value, int(m.sizes["crossing"]), float(o.multiplier_real[0])))
    return rows


def main():
    p = ns.preset("fig7")
    orbit = ns.periodic_orbit(p, x0=-1.5, v0=0.25)
    for name, values in (("omega", np.arange(1.10, 1.20, 0.01)),
                         ("omega", np.arange(1.10, 1.05, -0.01)),
                         ("F0", np.arange(0.125, 0.26, 0.025)),
                         ("xi", np.arange(0.05, 0.0, -0.01))):
        for value, n, mu in scan(p, orbit, name, values):
            print(f"{name} = {value:.3f}: " + (f"homoclinic crossings {n}, mu_u = {mu:.4g}"
                                               if n is not None else "saddle lost"))


if __name__ == "__main__":
    main()
