"""
Fig. 9: bifurcation diagram in ω
================================

Table 3, ω from 0.8 to 1.0, swept up and down (each value starts from the previous state):
the motion turns chaotic right after grazing. The λ1 panel is the evidence of each
classification.
"""
import numpy as np

import nonsmooth as ns

bif = ns.bifurcation_diagram(ns.preset("table3"), "omega", np.linspace(0.8, 1.0, 81),
                             transient=500, record=60)
fig = ns.plot.plot_bifurcation(bif)
