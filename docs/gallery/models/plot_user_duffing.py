"""
A user model: Duffing oscillator with a one-sided support
=========================================================

``examples/one_sided_duffing.py``, written by hand (see the tutorial), loaded from its file:
a bifurcation diagram in F0 with the exact method.
"""
from pathlib import Path

import numpy as np

import nonsmooth as ns

# the repository's examples/ folder (the gallery runs in its own folder, below it)
path = next(d / "examples" / "one_sided_duffing.py" for d in (Path.cwd(), *Path.cwd().parents)
            if (d / "examples" / "one_sided_duffing.py").is_file())
m = ns.model(f"{path}:MODEL")
p = m.params(k_s=50.0)
bif = ns.bifurcation_diagram(p, "F0", np.linspace(0.5, 2.0, 60), transient=200, record=40,
                             method="exact")
fig = ns.plot.plot_bifurcation(bif)
