"""
impact_2dof: two masses, one stop
=================================

State (X, V, Y, W): the primary mass hits a rigid stop. Floquet multipliers act on the whole
state; figures show any two components.
"""
import nonsmooth as ns

p = ns.model("impact_2dof").preset("period_one")
ds = ns.simulate(p, periods=4, transient=200, method="exact", u0={"X": 0.1, "Y": 0.3})
fig = ns.plot.plot_time_response(ds, show=("X", "Y"))
orb = ns.periodic_orbit(p, transient=300, method="exact")
print(orb.attrs["verdict"], "|mu| =", orb.multiplier_abs.values.round(5))
