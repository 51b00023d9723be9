"""
jeffcott_rotor: rubbing on a circular stator
============================================

A curved switching surface X² + Y² = δ²; the chaotic rub seen in the rotor's plane.
"""
import nonsmooth as ns

p = ns.model("jeffcott_rotor").preset("chaotic_rub")
sec = ns.poincare(p, record=300, transient=200, method="exact")
print(f"{sec.motion.item()}, lambda1 = {float(sec.lambda1):.4f}")
fig = ns.plot.plot_poincare(sec, show=("X", "Y"))
