"""
support: the paper's oscillator
===============================

The paper's model, smoothed (eq. 13) and exact side by side at Table 3, ω = 0.92: the
smoothed section lies on the exact chaotic attractor.
"""
import nonsmooth as ns

p = ns.model("support").preset("table3").replace(omega=0.92)
fig = ns.plot.plot_time_response(ns.simulate(p, periods=3, transient=200))
for method in ("smooth", "exact"):
    sec = ns.poincare(p, record=500, transient=300, method=method)
    print(f"{method}: {sec.motion.item()}, lambda1 = {float(sec.lambda1):.4f}")
    fig = ns.plot.plot_poincare(sec)
