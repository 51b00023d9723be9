"""
Figs. 7 and 8: coexisting attractors and their basins
=====================================================

At ω = 1.10 and 1.18 (Fig. 7) two period-1 attractors coexist, one with contact and one
without; the basins over (x0, v0), and the two orbits (Fig. 8). The saddle between them and
its stable manifold, the basin boundary, are in the user guide.
"""
import nonsmooth as ns

for omega in (1.10, 1.18):
    bas = ns.basins(ns.preset("fig7").replace(omega=omega), x=(-3, 3), v=(-3, 3), grid=60)
    print(f"omega = {omega}: basin fractions {bas.fraction.values.round(3)}, "
          f"contact {bas.contact.values}")
    fig = ns.plot.plot_basins(bas)

# %%
# The attractors at ω = 1.10, each started from inside its basin:
fig = ns.plot.plot_attractors(bas)
