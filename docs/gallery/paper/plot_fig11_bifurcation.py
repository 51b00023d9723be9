"""
Fig. 11: bifurcation diagram in F0
==================================

Table 4, F0 from 0.1 to 0.45: periodic motion, grazing, then chaotic windows.
"""
import numpy as np

import nonsmooth as ns

bif = ns.bifurcation_diagram(ns.preset("table4"), "F0", np.linspace(0.1, 0.45, 71),
                             transient=500, record=60)
fig = ns.plot.plot_bifurcation(bif)
