"""
Fig. 6: resonance curves with jumps
===================================

Amplitude over the forcing frequency, swept up and down, for ωs = 3.16 (Fig. 6a) and 7.07
(Fig. 6b): the first contact at ω_a and the jumps at ω_b, ω_c (hysteresis between them).
"""
import numpy as np

import nonsmooth as ns

for name in ("fig6a", "fig6b"):
    res = ns.resonance_curve(ns.preset(name), np.linspace(0.5, 1.6, 111), transient=200,
                             record=30)
    a, b, c = (res.attrs[k] for k in ("omega_a", "omega_b", "omega_c"))
    print(f"{name}: omega_a = {a:.4f}, omega_b = {b:.4f}, omega_c = {c:.4f}")
    fig = ns.plot.plot_resonance(res)
