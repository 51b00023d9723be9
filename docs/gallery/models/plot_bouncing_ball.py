"""
bouncing_ball: a ball on a vibrating table
==========================================

Written as equations (``model_from_equations``); the exact method has restitution and chatter
ending in sticking.
"""
import nonsmooth as ns

p = ns.model("bouncing_ball").preset("chaotic")
fig = ns.plot.plot_time_response(ns.simulate(p, periods=4, transient=50, method="exact"))
sec = ns.poincare(p, record=400, transient=100, method="exact")
print(f"{sec.motion.item()}, lambda1 = {float(sec.lambda1):.4f}")
fig = ns.plot.plot_poincare(sec)
