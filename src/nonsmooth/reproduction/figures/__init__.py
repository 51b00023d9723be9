"""One entry per figure of the paper (Figs. 3-12), one module per figure family.

Every entry calls the library's analyses (``simulate``, ``poincare``, ``eta_study``,
``resonance_curve``, ``basins``, ``bifurcation_diagram``), saves the Dataset(s) and a PNG, and
records the paper's claims beside the measured values with verdicts computed from the data.
Entries never integrate on their own beyond calling these public functions. Importing this
package registers the figures (:data:`..core.FIGURES`, kept in paper order).
"""

from . import (fig03_regions, fig04_eta, fig05_stiffness, fig06_resonance,  # noqa: F401
               fig07_08_basins, fig09_11_bifurcation, fig10_12_sections)
