"""Figures read the model named in the dataset: mode colours and labels, lines of X, parameter
symbols and title parameters (support keeps the paper's labels and its X = 1 line)."""

import numpy as np
import pytest
from matplotlib.figure import Figure

import nonsmooth as ns
from nonsmooth.analysis.bifurcation import bifurcation_diagram
from nonsmooth.analysis.poincare import poincare
from nonsmooth.plot import REGION_LABELS
from nonsmooth.plot.bifurcation import plot_bifurcation
from nonsmooth.plot.common import mode_labels, model_lines, model_of, param_title
from nonsmooth.plot.poincare import plot_poincare
from nonsmooth.plot.time_response import plot_time_response

MODELS = {
    "stick_slip": lambda: ns.model("stick_slip").params(),  # default stick-slip cycle
    "support": lambda: ns.preset("table3"),
}
CASES = [(m, k) for m in MODELS for k in ("smooth", "exact")]


@pytest.fixture(scope="module")
def results():
    out = {}
    for name, make in MODELS.items():
        p = make()
        for method in ("smooth", "exact"):
            out[name, method] = dict(
                simulate=ns.simulate(p, periods=3, method=method, samples_per_period=50),
                poincare=poincare(p, record=3, transient=3, method=method, orbit_samples=50,
                                  orbit_periods=3),
                bifurcation=bifurcation_diagram(p, "omega", [0.85, 0.9, 0.95], method=method,
                                                transient=2, record=3, settle=False,
                                                sweep="up"),
            )
    return out


def _legend_texts(fig):
    return [t.get_text() for ax in fig.axes if ax.get_legend() is not None
            for t in ax.get_legend().get_texts()]


def _vlines_at(ax, x):
    return [ln for ln in ax.lines if np.allclose(ln.get_xdata(), x)]


def _hlines_at(ax, y):
    return [ln for ln in ax.lines if np.allclose(ln.get_ydata(), y)]


def _labels_of(name):
    return REGION_LABELS if name == "support" else ns.model(name).mode_names


@pytest.mark.parametrize("name,method", CASES)
def test_time_response_uses_the_model(results, name, method):
    ds = results[name, method]["simulate"]
    assert ds.attrs["model"] == name
    fig = plot_time_response(ds)
    assert isinstance(fig, Figure)
    texts = _legend_texts(fig)
    labels = _labels_of(name)
    visited = sorted(set(np.asarray(ds.region.values).tolist()))
    assert all(labels[c] in texts for c in visited)
    other = set(REGION_LABELS) if name != "support" else set(ns.model("stick_slip").mode_names)
    assert not other & set(texts)
    if name == "support":
        assert _hlines_at(fig.axes[0], 1.0)  # X = 1 on the time response


@pytest.mark.parametrize("name,method", CASES)
def test_poincare_uses_the_model(results, name, method):
    ds = results[name, method]["poincare"]
    fig = plot_poincare(ds)
    assert isinstance(fig, Figure)
    texts = _legend_texts(fig)
    labels = _labels_of(name)
    visited = sorted(set(np.asarray(ds.orbit_region.values).tolist()))
    assert all(labels[c] in texts for c in visited)
    assert bool(_vlines_at(fig.axes[0], 1.0)) == (name == "support")
    m = ns.model(name)
    title = fig._suptitle.get_text()
    # every parameter the method reads, none it does not (the exact method's eta, k_c)
    unused = m.methods[method].unused
    assert all(f"{k}=" in title for k in m.param_names if k not in unused)
    assert not any(f"{k}=" in title for k in unused)


@pytest.mark.parametrize("name,method", CASES)
def test_bifurcation_uses_the_model(results, name, method):
    ds = results[name, method]["bifurcation"]
    fig = plot_bifurcation(ds)
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    assert ns.model(name).param("omega").symbol in ax.get_xlabel()
    texts = _legend_texts(fig)
    if name == "support":
        assert _hlines_at(ax, 1.0) and r"support $X = 1$" in texts
    else:
        assert not _hlines_at(ax, 1.0)
        assert "v_belt=" in fig._suptitle.get_text() and "omega=" not in fig._suptitle.get_text()


def test_model_helpers():
    assert model_of({}).name == "support"  # files written before the model attribute
    assert mode_labels(ns.model("support")) == REGION_LABELS == ns.model("support").mode_labels
    assert mode_labels(ns.model("stick_slip")) == ns.model("stick_slip").mode_names
    p = ns.model("stick_slip").params()
    attrs = p.attrs()
    assert model_lines(attrs, "exact") == []
    assert "v_belt=0.2" in param_title(type("D", (), {"attrs": attrs})())
    sup = ns.preset("table3").attrs()
    assert model_lines(sup, "exact") == [(1.0, r"support $X = 1$")]
    assert len(model_lines(sup, "smooth")) == 3
    assert model_lines(sup, "smooth", band_edges=False) == [(1.0, r"support $X = 1$")]


def test_a_user_models_figures_find_the_model_in_the_process_and_from_its_file(monkeypatch,
                                                                               tmp_path):
    """A result names its model by name only; a user's model is not built in, so figures drew
    it with generic mode labels and without its lines (a newcomer's finding). In the process
    that used it they now take that model (``models.used``); in another, the model loaded
    from the file the result's ``model_source`` names; with that file gone, generic labels."""
    from pathlib import Path

    from nonsmooth import models
    path = Path(__file__).resolve().parents[1] / "examples" / "one_sided_duffing.py"
    m = ns.model(f"{path}:MODEL")
    ds = ns.simulate(m.params(), periods=2, method="exact")
    assert ds.attrs["model_source"] == f"{path}:MODEL"
    assert model_of(ds) is m and mode_labels(model_of(ds)) == ("free", "contact")
    assert model_lines(ds) == [(1.0, "support (X = gap)")]
    monkeypatch.setattr(models, "_USED", {})  # as in a new process: from the file
    assert model_of(ds).name == "one_sided_duffing"
    assert model_lines(ds) == [(1.0, "support (X = gap)")]
    monkeypatch.setattr(models, "_USED", {})
    ds.attrs["model_source"] = f"{tmp_path / 'gone.py'}:MODEL"
    assert model_of(ds) is None and model_lines(ds) == []


def test_section_axes_name_the_model_s_own_components():
    # the bouncing ball's first component is Z: the Poincaré map and the bifurcation diagram
    # label it Z(kT), not X(kT) (support's labels stay X(kT), V(kT), as before)
    ball = ns.model("bouncing_ball")
    p = ball.preset("period_one")
    ds = poincare(p, record=2, transient=2, method="exact", orbit_samples=20, orbit_periods=1)
    ax = plot_poincare(ds).axes[1]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("$Z(kT)$", "$V(kT)$")
    bd = bifurcation_diagram(p, "A", np.array([1.2, 1.3]) / (4 * np.pi**2), method="exact",
                             transient=2, record=2, settle=False, sweep="up")
    assert plot_bifurcation(bd).axes[0].get_ylabel() == "$Z(kT)$"
    assert plot_bifurcation(bd, var="V").axes[0].get_ylabel() == r"$\dot Z(kT)$"


@pytest.mark.parametrize("name,method", CASES)
def test_x_v_models_keep_their_section_labels(results, name, method):
    # support and stick_slip (components X, V): the labels as before
    ax = plot_poincare(results[name, method]["poincare"]).axes[1]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("$X(kT)$", "$V(kT)$")
    assert plot_bifurcation(results[name, method]["bifurcation"]).axes[0].get_ylabel() \
        == "$X(kT)$"
