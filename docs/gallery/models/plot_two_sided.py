"""
two_sided: a gap on both sides
==============================

The oscillator between two spring-damper supports.
"""
import nonsmooth as ns

p = ns.model("two_sided").preset("table3")
fig = ns.plot.plot_time_response(ns.simulate(p, periods=3, transient=200, method="exact"))
sec = ns.poincare(p, record=300, transient=300, method="exact")
print(f"period {int(sec.period)}, {sec.motion.item()}")
fig = ns.plot.plot_poincare(sec)
