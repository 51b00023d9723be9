"""
Fig. 4: the band width η against the exact model
================================================

The chaotic case of Fig. 4 for η = 0.28 ... 2.8e-4, each smoothed section compared with the
exact non-smooth model (η = 0) on the same section; ``recommended_eta`` is the largest η
whose section agrees.
"""
import nonsmooth as ns

eta = ns.eta_study(ns.preset("fig4"), [0.28, 0.028, 0.0028, 0.00028], transient=500,
                   record=400)
print("recommended eta:", float(eta.recommended_eta))
fig = ns.plot.plot_eta_study(eta)
