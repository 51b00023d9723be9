"""Figures: Dataset in, matplotlib Figure out. Plots never integrate."""

import matplotlib

matplotlib.use("Agg")

#: Region colours used by every figure (codes of models.switch).
REGION_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728")
REGION_LABELS = (r"$\Gamma_-$", r"$\Sigma_\alpha$", r"$\Sigma_\beta$", r"$\Gamma_+$")
