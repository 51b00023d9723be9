"""Bifurcation diagram: section X versus the swept parameter (Figs. 9 and 11)."""

from __future__ import annotations

import numpy as np

from .common import model_lines, model_of, new_figure, param_symbol, param_title

SWEEP_STYLE = {
    "up": dict(color="#1f77b4", marker=".", label="sweep up"),
    "down": dict(color="#d62728", marker="x", label="sweep down"),
    "fresh": dict(color="k", marker=".", label="fresh start each value"),
}



def sweep_names(ds) -> list[str]:
    """The direction names ("up", "down", "fresh") of the integer ``sweep`` coordinate of a
    bifurcation or resonance Dataset, from its CF flag_values / flag_meanings."""
    sw = ds["sweep"]
    meanings = dict(zip(np.asarray(sw.attrs["flag_values"]).tolist(),
                        sw.attrs["flag_meanings"].split()))
    return [meanings[int(c)] for c in np.atleast_1d(sw.values)]


def plot_bifurcation(ds, var: str = "X", lyapunov=None):
    """Section ``var`` (X or V) of every recorded period versus the swept parameter; up and
    down sweeps in different colours and markers, small dots; failed points are left out.

    ``lyapunov``: None (default) adds a panel below the diagram, sharing its x axis, with the
    largest Lyapunov exponent ``lambda1`` of every value per sweep (error bars: its standard
    error ``lambda1_stderr``) and the zero line, when the Dataset has ``lambda1``; False never
    draws it; True requires ``lambda1``."""
    param = ds.attrs["swept_param"]
    has = "lambda1" in ds.data_vars
    if lyapunov and not has:
        from ..errors import ParameterError
        raise ParameterError("lyapunov: the Dataset has no lambda1 (compute it with "
                             "lyapunov=True)")
    panel = has if lyapunov is None else bool(lyapunov)
    if panel:
        fig, (ax, lax) = new_figure(2, 1, figsize=(10, 7.5), sharex=True,
                                    gridspec_kw=dict(height_ratios=(3, 1.3)))
    else:
        fig, ax = new_figure(figsize=(10, 5.5))
    vals = ds[param].values
    nsw = ds.sizes["sweep"]
    npts = vals.size * ds.sizes["n"]
    size = 0.6 if npts > 20000 else 2.0
    for j, name in enumerate(sweep_names(ds)):
        y = ds[var].values[j]  # (value, n)
        x = np.broadcast_to(vals[:, None], y.shape)
        ok = np.isfinite(y)
        style = dict(SWEEP_STYLE.get(str(name), dict(color="0.3", marker=".", label=str(name))))
        marker = style.pop("marker")
        ax.scatter(x[ok], y[ok], s=size * 1.6 if marker == "." else size, marker=marker,
                   linewidths=0.4 if marker == "x" else 0, alpha=0.7 if nsw > 1 else 1.0,
                   zorder=3 if str(name) == "up" else 2, rasterized=True, **style)
    if var == "X":
        draw_lines_over(ax, ds, param, vals)
    failed = int(np.count_nonzero(ds.status.values))
    unit = ds[param].attrs.get("units", "")
    sym = param_symbol(model_of(ds), param)
    ax.set_xlabel(f"{sym} [{unit}]" if unit else sym)
    if panel:  # the label goes below the lambda1 panel (kept, hidden, on the diagram's axes)
        draw_lambda1(lax, ds, param, vals)
        lax.set_xlabel(ax.get_xlabel())
        ax.xaxis.label.set_visible(False)
    x = str(ds.attrs.get("state_names", "X")).split()[0]  # (the model's own: the ball's Z)
    ax.set_ylabel(f"${x}(kT)$" if var == "X" else rf"$\dot {x}(kT)$")
    ax.set_xlim(vals[0], vals[-1])
    ttl = f"bifurcation diagram, {ds.sizes['n']} section points per value"
    if failed:
        ttl += f" ({failed} failed points omitted)"
    ax.set_title(ttl, fontsize=10)
    ax.legend(loc="best", fontsize=8, markerscale=4)
    ax.grid(True, lw=0.3, alpha=0.5)
    fig.suptitle(f"{ds.attrs.get('method', '')}: {param_title(ds, exclude=(param,))}",
                 fontsize=9)
    fig.tight_layout()
    return fig


def draw_lines_over(ax, ds, param, vals, style=None):
    """The model's main lines of X (``Model.plot_lines`` without band edges) over the swept
    parameter: horizontal where they do not depend on it, else a curve through the values."""
    style = {**dict(color="k", lw=0.6, ls="--"), **(style or {})}
    per_value = [model_lines(ds, band_edges=False, **{param: float(v)}) for v in vals]
    n = min((len(li) for li in per_value), default=0)
    for k in range(n):
        ys = np.array([li[k][0] for li in per_value])
        lab = per_value[0][k][1]
        if np.all(ys == ys[0]):
            ax.axhline(ys[0], label=lab, **style)
        else:
            ax.plot(vals, ys, label=lab, **style)



def draw_lambda1(ax, ds, param, vals):
    """lambda1 (per unit time) versus the swept parameter, one series per sweep direction, with
    its standard error as error bars, and the zero line (chaos: above it beyond the errors)."""
    sw = "sweep" in ds["lambda1"].dims
    order = ("sweep", param) if sw else (param,)
    lam = np.asarray(ds["lambda1"].transpose(*order).values, dtype=float)
    err = (np.asarray(ds["lambda1_stderr"].transpose(*order).values, dtype=float)
           if "lambda1_stderr" in ds else np.full_like(lam, np.nan))
    names = sweep_names(ds) if sw else [""]
    lam, err = lam.reshape(len(names), -1), err.reshape(len(names), -1)
    for j, name in enumerate(names):
        style = dict(SWEEP_STYLE.get(str(name), dict(color="0.3", marker=".", label=str(name))))
        ok = np.isfinite(lam[j])
        e = np.where(np.isfinite(err[j]), err[j], 0.0)[ok]
        ax.errorbar(vals[ok], lam[j][ok], yerr=e, fmt=style.pop("marker"), ms=3, lw=0.6,
                    elinewidth=0.6, capsize=0, alpha=0.8, **style)
    ax.axhline(0.0, color="k", lw=0.7)
    unit = ds["lambda1"].attrs.get("units", "1/s")
    ax.set_ylabel(rf"$\lambda_1$ [{unit}]")
    ax.grid(True, lw=0.3, alpha=0.5)
    if len(names) > 1:
        ax.legend(loc="best", fontsize=7, markerscale=2)
