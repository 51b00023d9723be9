"""
stick_slip: a belt-driven friction oscillator
=============================================

Leine's oscillator with Stribeck friction, forced (preset ``stribeck``); without forcing it is
self-excited: its stick-slip limit cycle on the section V = 0.
"""
import nonsmooth as ns

m = ns.model("stick_slip")
p = m.preset("stribeck")
fig = ns.plot.plot_time_response(ns.simulate(p, periods=4, transient=100, method="exact"))
sec = ns.poincare(p, record=200, transient=300, method="exact")
print(f"forced: period {int(sec.period)}, {sec.motion.item()}")

lc = ns.limit_cycle(m.params(), "V", v0=1.0)
print(f"self-excited: limit cycle of period {float(lc.period):.9f}")
