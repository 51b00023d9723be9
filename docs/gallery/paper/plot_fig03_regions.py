"""
Fig. 3: an orbit through the four regions
=========================================

Table 1 with η = 7.14e-3: the settled orbit passes Γ−, Σα, Γ+ and Σβ of the switch model
(eqs. 10-14), coloured by region.
"""
import nonsmooth as ns

p = ns.preset("table1")
ds = ns.simulate(p, periods=2, transient=10, samples_per_period=4000)
print("regions visited:", sorted({int(r) for r in ds.region.values}))
fig = ns.plot.plot_time_response(ds)
