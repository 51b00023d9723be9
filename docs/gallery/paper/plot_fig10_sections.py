"""
Fig. 10: period 3 and chaos
===========================

Table 3 at ω = 0.91 (a period-3 orbit) and ω = 0.92 (chaotic): phase portrait coloured by
region with the Poincaré section points, the exact model's section in grey.
"""
import nonsmooth as ns

for omega in (0.91, 0.92):
    p = ns.preset("table3").replace(omega=omega)
    sec = ns.poincare(p, record=200, transient=500, orbit_samples=1000)
    exact = ns.poincare(p, record=200, transient=500, method="exact", lyapunov=False)
    print(f"omega = {omega}: period {int(sec.period)}, {sec.motion.item()}, "
          f"lambda1 = {float(sec.lambda1):.4f} +- {float(sec.lambda1_stderr):.4f}")
    fig = ns.plot.plot_section_panel(sec, title=f"Fig. 10: omega = {omega}", exact=exact)
