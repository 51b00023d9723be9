"""Figures of two-parameter maps (:func:`nonsmooth.analysis.parameter_map.parameter_map`): the
periodicity map (one colour per regime, with a legend giving each regime's share of the grid)
and the lambda1 map."""

from __future__ import annotations

import numpy as np

from .common import model_of, new_figure, param_symbol, param_title

#: Colours of the regimes of ``analysis.parameter_map.regimes`` (periods 1 ... 8, longer
#: periods, quasi-periodic, chaotic, non-periodic, not settled, failed).
REGIME_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#bcbd22",
                 "#17becf", "#aec7e8", "#ffbb78", "#d62728", "#7f7f7f", "#c7c7c7", "#000000")


def _axes_labels(ax, ds):
    m = model_of(ds)
    xn, yn = ds.attrs["x_param"], ds.attrs["y_param"]
    ax.set_xlabel(param_symbol(m, xn) if m is not None else xn)
    ax.set_ylabel(param_symbol(m, yn) if m is not None else yn)
    ax.set_title(f"{param_title(ds, exclude=(xn, yn))}\n{ds.attrs.get('method', '')} method, "
                 f"{ds.attrs.get('start', 'fresh')} start", fontsize=8)


def _extent(ds):
    xs, ys = ds[ds.attrs["x_param"]].values, ds[ds.attrs["y_param"]].values

    def edges(v):
        if v.size == 1:
            return v[0] - 0.5, v[0] + 0.5
        h = 0.5 * (v[1] - v[0])
        return v[0] - h, v[-1] + h
    return (*edges(xs), *edges(ys))


def plot_parameter_map(ds, ax=None):
    """Categorical map of the regimes (period 1, 2, ..., chaotic, quasi-periodic, not settled,
    failed); the legend lists the regimes present with their share of the grid."""
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch
    from ..analysis.parameter_map import regimes
    code, names = regimes(ds)
    own = ax is None
    if own:
        fig, ax = new_figure(figsize=(7.5, 5.0))
    cmap = ListedColormap(REGIME_COLORS[:len(names)])
    ax.imshow(code, origin="lower", aspect="auto", extent=_extent(ds), cmap=cmap,
              vmin=-0.5, vmax=len(names) - 0.5, interpolation="nearest")
    counts = np.bincount(code.ravel(), minlength=len(names))
    def share(c):
        pct = 100.0 * c / code.size
        return f"{pct:.1f}%" if pct >= 0.05 else "<0.1%"
    handles = [Patch(color=REGIME_COLORS[k], label=f"{names[k]} ({share(counts[k])})")
               for k in range(len(names)) if counts[k]]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8,
              frameon=False)
    _axes_labels(ax, ds)
    if own:
        fig.tight_layout()
    return ax.figure


def plot_lambda1_map(ds, ax=None):
    """lambda1 over the grid (diverging colours centred on 0: red = chaos); grey where it was
    not computed or the point failed."""
    from matplotlib.colors import TwoSlopeNorm
    if "lambda1" not in ds:
        from ..errors import ParameterError
        raise ParameterError("lambda-plot: the map has no lambda1 (computed with lyapunov=False "
                             "or for a model without tangent dynamics)")
    lam = np.ma.masked_invalid(ds.lambda1.values)
    own = ax is None
    if own:
        fig, ax = new_figure(figsize=(6.5, 5.0))
    lo = float(lam.min()) if lam.count() else -1.0
    hi = float(lam.max()) if lam.count() else 1.0
    lo, hi = min(lo, -1e-6), max(hi, 1e-6)
    import matplotlib
    cmap = matplotlib.colormaps["RdBu_r"].with_extremes(bad="#bbbbbb")
    im = ax.imshow(lam, origin="lower", aspect="auto", extent=_extent(ds), cmap=cmap,
                   norm=TwoSlopeNorm(0.0, lo, hi), interpolation="nearest")
    ax.figure.colorbar(im, ax=ax, label=r"$\lambda_1$ (1/s)")
    _axes_labels(ax, ds)
    if own:
        fig.tight_layout()
    return ax.figure
