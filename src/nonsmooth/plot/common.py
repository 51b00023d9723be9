"""Pieces shared by several figures.

Every figure reads what it draws about the system from the model named in the dataset
(:func:`model_of`): the mode colours and legend labels (``Model.mode_names``), the lines of X to
draw (``Model.plot_lines``), the parameter symbols (``Param.symbol``) and the parameters of the
title (``Model.param_names``). Files written before the model interface have no ``model``
attribute: they are the ``support`` model.
"""

from __future__ import annotations

import numpy as np

from .._builtin import DEFAULT_MODEL
from . import MODE_COLORS

#: Label prefix of the secondary lines of ``Model.plot_lines`` (band edges of the smooth
#: method), drawn thinner and grey, with one legend entry.
BAND_EDGE = "band edge"


def new_figure(nrows: int = 1, ncols: int = 1, *, figsize=None, **subplots_kw):
    """``(fig, axes)`` like ``plt.subplots`` but without pyplot: a ``matplotlib.figure.Figure``
    that no backend or pyplot state knows about (saved by ``nonsmooth.io.save_figure``, shown
    in a notebook by displaying ``fig``). ``subplots_kw`` go to ``Figure.subplots``."""
    from matplotlib.figure import Figure
    fig = Figure(figsize=figsize)
    return fig, fig.subplots(nrows, ncols, **subplots_kw)


# ---- the model of a dataset ------------------------------------------------------------------
def model_name(ds) -> str:
    """The model name of a result (``model`` attribute; the paper's model, the default, when
    missing: files written before the model interface)."""
    attrs = getattr(ds, "attrs", ds)
    return str(attrs.get("model", DEFAULT_MODEL))


def model_of(ds):
    """The :class:`~nonsmooth.models.base.Model` named in the dataset (``support`` for files
    without a ``model`` attribute): a built-in model, else a user's model that this process
    used (``models.used``), else one loaded from the file its ``model_source`` attribute names;
    None when it cannot be found (e.g. a user model whose file is gone): figures then fall
    back to generic mode labels and draw no model lines."""
    from ..models import BUILTIN, model, used
    name = model_name(ds)
    if name not in BUILTIN and used(name) is not None:
        return used(name)
    source = getattr(ds, "attrs", ds).get("model_source")
    for spec in (name, source) if source else (name,):
        try:
            m = model(spec)
        except Exception:  # noqa: BLE001 - a missing or broken file: no model, generic labels
            continue
        if m.name == name:
            return m
    return None


def mode_colors(m, n=None) -> tuple:
    """One colour per mode code of model ``m`` (``MODE_COLORS``; the support model keeps the
    paper's four region colours)."""
    k = len(m.mode_names) if m is not None else (n or len(MODE_COLORS))
    return tuple(MODE_COLORS[i % len(MODE_COLORS)] for i in range(k))


def mode_labels(m, n=None) -> tuple:
    """Legend label per mode code of model ``m``: its ``mode_labels`` (mathtext, e.g. the
    support model's Gamma-/Sigma labels), else its ``mode_names``."""
    if m is None:
        return tuple(f"mode {i}" for i in range(n or len(MODE_COLORS)))
    return tuple(m.mode_labels or m.mode_names)


def state_labels(ds) -> tuple:
    """Axis labels (mathtext) of the state components of the dataset's model: its
    ``axis_labels``, else its ``state_names``; (X, V) when the model cannot be loaded."""
    m = model_of(ds)
    if m is None:
        return ("$X$", "$V$")
    return tuple(m.axis_labels) or tuple(f"${n}$" for n in m.state_names)


def check_show(show, names, field: str = "show") -> tuple | None:
    """``show`` (None, "X,Y" or a pair of component names) as a pair of names among ``names``
    (``simulate.component_pair``)."""
    from ..checks import component_pair
    return component_pair(show, names, field)


def shown_components(ds, show, prefix: str = "", suffix: str = ""):
    """The two state components a figure shows: ``show`` (None: the first two), as
    (index a, index b, label a, label b, values of a, values of b) from the dataset's
    component variables (``<prefix>X<suffix>``, ``<prefix>V<suffix>``, then one per further
    component, see ``io.components``); indices into the model's states."""
    from ..io import component_names
    labels = state_labels(ds)
    names = str(ds.attrs.get("state_names", "X V")).split()
    pair = check_show(show, names) or tuple(names[:2])
    a, b = names.index(pair[0]), names.index(pair[1])
    var = [f"{prefix}{nm}{suffix}" for nm in component_names(names)]
    la = labels[a] if a < len(labels) else f"${names[a]}$"
    lb = labels[b] if b < len(labels) else f"${names[b]}$"
    return a, b, la, lb, ds[var[a]].values, ds[var[b]].values


def param_symbol(m, name: str) -> str:
    """The plot symbol (mathtext) of parameter ``name`` of model ``m`` (the name if none)."""
    if m is not None:
        try:
            return m.param(name).symbol or name
        except Exception:  # noqa: BLE001 - not a parameter of this model: show the name
            pass
    return name


def params_of(ds, **point):
    """The model's parameters of a result from its ``param_<name>`` attributes (swept ones
    given in ``point``), or None when they are incomplete or invalid."""
    m = model_of(ds)
    if m is None:
        return None
    point = {k: float(v) for k, v in point.items() if k in m.param_names}
    try:
        return m.params_from_attrs(getattr(ds, "attrs", ds), **point)
    except Exception:  # noqa: BLE001 - an old or partial file: no params, no lines
        return None


def model_lines(ds, method=None, *, band_edges: bool = True, **point) -> list:
    """``[(X value, label), ...]`` of the dataset's model (``Model.plot_lines``) at its
    parameters (``point``: values of swept parameters) for ``method`` (default: the dataset's
    ``method`` attribute). ``band_edges=False`` leaves out the band-edge lines. Labels are
    the model's (mathtext where its ``line_labels`` has one)."""
    m = model_of(ds)
    if m is None:
        return []
    method = method or str(getattr(ds, "attrs", {}).get("method", "smooth"))
    try:  # parameters None: the lines that do not depend on them
        lines = m.plot_lines(params_of(ds, **point), method)
    except Exception:  # noqa: BLE001 - a model's lines must not break a figure
        lines = []
    tex = m.line_labels
    return [(float(x), tex.get(lab, lab)) for x, lab in lines
            if band_edges or not str(lab).startswith(BAND_EDGE)]


def draw_model_lines(ax, ds, orient: str = "v", *, label: bool = True, band_edges: bool = True,
                     method=None, style=None, **point) -> list:
    """Draw the model's lines of X (:func:`model_lines`) on ``ax``: vertical (``orient="v"``,
    phase planes) or horizontal (``"h"``, X over time or over a parameter). Main lines black
    dashed (``style`` overrides), band edges thin grey with one legend entry. Returns the
    lines drawn."""
    main = dict(color="k", lw=0.6, ls="--")
    main.update(style or {})
    draw = ax.axvline if orient == "v" else ax.axhline
    seen = set()
    lines = model_lines(ds, method, band_edges=band_edges, **point)
    for x, lab in lines:
        band = str(lab).startswith(BAND_EDGE)
        kw = dict(color="0.3", lw=0.6, ls="--") if band else dict(main)
        text = "band edges" if band else lab
        draw(x, label=text if label and text not in seen else None, **kw)
        seen.add(text)
    return lines


def scatter_by_region(ax, x, y, region, s=2.0, legend=True, model=DEFAULT_MODEL, **kw):
    """Scatter (x, y) coloured by mode (region) code; only the modes present get a legend
    entry. ``model``: a Model, a model name or a dataset naming one (colours and labels per
    mode code; default the support model's four regions); None: generic ``mode k`` labels."""
    if isinstance(model, str):
        model = model_of({"model": model})
    elif model is not None and not hasattr(model, "mode_names"):
        model = model_of(model)
    region = np.asarray(region)
    n = int(region.max()) + 1 if region.size else 0
    colors, labels = mode_colors(model, n), mode_labels(model, n)
    for code in range(max(len(colors), n)):
        sel = region == code
        if np.any(sel):
            ax.scatter(np.asarray(x)[sel], np.asarray(y)[sel], s=s,
                       color=MODE_COLORS[code % len(MODE_COLORS)],
                       label=(labels[code] if code < len(labels) else f"mode {code}")
                       if legend else None, linewidths=0, **kw)


def draw_band_edges(ax, eta, omega_s, xi_s, vlim=None, label=True):
    """Support model, smooth method: draw h_alpha = +-eta (X = 1 +- eta) and h_beta = +-eta
    (eq. 7) in the phase plane."""
    kw = dict(color="0.3", lw=0.6, ls="--")
    ax.axvline(1 - eta, **kw, label=r"band edges ($h=\pm\eta$)" if label else None)
    ax.axvline(1 + eta, **kw)
    if omega_s > 0 and xi_s > 0:
        r = xi_s / omega_s**2
        lo, hi = vlim if vlim is not None else ax.get_ylim()
        v = np.linspace(lo, hi, 2)
        for sgn in (-1, 1):
            ax.plot(1 - r * v - sgn * eta, v, color="0.5", lw=0.6, ls=":")
        ax.set_ylim(lo, hi)


def has_support_bands(ds, method=None) -> bool:
    """True for the support model's smooth method (the bands h_alpha, h_beta = +-eta)."""
    method = method or getattr(ds, "attrs", {}).get("method", "smooth")
    return model_name(ds) == DEFAULT_MODEL and method != "exact"


def draw_phase_lines(ax, ds, *, label: bool = True, eta=None, vlim=None, **point) -> None:
    """The model's lines in a phase plane: for the support model's smooth method the band
    edges h_alpha = +-eta and h_beta = +-eta (:func:`draw_band_edges`), for any other model or
    method the vertical lines of ``Model.plot_lines`` (labelled if ``label``)."""
    if has_support_bands(ds):
        a = ds.attrs
        eta = float(a["param_eta"]) if eta is None else float(eta)
        draw_band_edges(ax, eta, float(a.get("param_omega_s", 0.0)),
                        float(a.get("param_xi_s", 0.0)), vlim=vlim, label=label)
    else:
        if eta is not None:
            point = {"eta": eta, **point}
        draw_model_lines(ax, ds, "v", label=label, **point)


def title_keys(ds, exclude=()) -> tuple:
    """The parameter names of the dataset's model (in its order), less ``exclude`` and less
    those its method does not read (``Method.unused``: the exact method's eta, k_c)."""
    m = model_of(ds)
    names = m.param_names if m is not None else tuple(
        k[6:] for k in getattr(ds, "attrs", {}) if k.startswith("param_"))
    method = getattr(ds, "attrs", {}).get("method")
    if m is not None and method in m.methods:
        exclude = (*exclude, *m.methods[method].unused)
    return tuple(k for k in names if k not in exclude)


def param_title(ds, keys=None, exclude=()) -> str:
    """``name=value, ...`` of the parameters in the dataset's attributes; ``keys`` default to
    the model's parameter names (less ``exclude``)."""
    if keys is None:
        keys = title_keys(ds, exclude)
    parts = []
    for k in keys:
        a = f"param_{k}"
        if a in ds.attrs:
            parts.append(f"{k}={ds.attrs[a]:.4g}")
    return ", ".join(parts)
