"""
impact: a rigid stop with restitution
=====================================

Newton's law V+ = -r V- at the stop; the exact method propagates the free flight in closed
form and locates each impact to round-off.
"""
import nonsmooth as ns

p = ns.model("impact").params(r=0.8)
fig = ns.plot.plot_time_response(ns.simulate(p, periods=4, transient=200, method="exact"))
orb = ns.periodic_orbit(p, transient=200, method="exact")
print(orb.attrs["verdict"], "multipliers |mu| =", orb.multiplier_abs.values.round(5))
fig = ns.plot.plot_orbit(orb)
