"""
Fig. 5: from a soft to a stiff support
======================================

Table 2's response for ωs = 1, 3.16, 10, 31.6 and 100: the switch model integrates without
trouble as the support stiffens.
"""
import xarray as xr

import nonsmooth as ns

runs = []
for omega_s in (1.0, 3.16, 10.0, 31.6, 100.0):
    p = ns.preset("table2").replace(omega_s=omega_s)
    ds = ns.simulate(p, periods=3, transient=400, samples_per_period=200)
    runs.append(ds.expand_dims(omega_s=[omega_s]))
    print(f"omega_s = {omega_s:5.1f}: max X = {float(ds.X.max()):.4f}")
fig = ns.plot.plot_support_stiffness(xr.concat(runs, dim="omega_s", join="outer"))
