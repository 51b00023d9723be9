"""
Fig. 12: period 4, chaos, period 2
==================================

Table 4 at F0 = 0.225 (period 4), 0.35 (chaotic) and 0.40 (period 2).
"""
import nonsmooth as ns

for F0 in (0.225, 0.35, 0.40):
    p = ns.preset("table4").replace(F0=F0)
    sec = ns.poincare(p, record=200, transient=500, orbit_samples=1000)
    print(f"F0 = {F0}: period {int(sec.period)}, {sec.motion.item()}")
    fig = ns.plot.plot_section_panel(sec, title=f"Fig. 12: F0 = {F0}")
