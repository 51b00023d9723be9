"""lambda1 evidence in the reproduction report and the lambda1 panel of bifurcation plots."""

import numpy as np
import pytest
import xarray as xr

from nonsmooth.reproduction.core import lyapunov_text


def test_lyapunov_text_chaotic():
    t = lyapunov_text((0.058, 0.006, 3, 0))
    assert t.startswith("not periodic (period 0), lambda1 = 0.0580 ± 0.0060 /s > 0")
    assert t.endswith(": chaotic")


def test_lyapunov_text_within_error_is_not_called_chaotic():
    t = lyapunov_text((0.036, 0.014, 2, 0))
    assert "within 3 errors of 0" in t and "quasi-periodic or a long transient" in t
    assert "chaotic" not in t.split(":")[-1].replace("chaos is not shown", "")


def test_lyapunov_text_negative_and_missing():
    assert "< 0" in lyapunov_text((-0.025, 0.0045, 4, 0))
    assert "not chaos" in lyapunov_text((-0.025, 0.0045, 4, 0))
    assert lyapunov_text((-0.028, 0.004, 1, 3)).endswith(": periodic")
    assert "not computed" in lyapunov_text((float("nan"), float("nan"), 0, 0))
    assert lyapunov_text((0.05, 0.005), with_period=False).startswith("lambda1 = 0.0500")


def test_lyapunov_text_from_a_sweep_dataset():
    ds = xr.Dataset({"lambda1": (("sweep", "omega"), [[0.06, -0.03], [0.05, 0.001]]),
                     "lambda1_stderr": (("sweep", "omega"), [[0.005, 0.004], [0.004, 0.01]]),
                     "motion": (("sweep", "omega"), np.array([[3, 1], [3, 2]], np.int8)),
                     "period": (("sweep", "omega"), [[0, 3], [0, 0]])},
                    coords={"omega": [0.92, 0.93]})
    assert lyapunov_text(ds, sweep=0, omega=0.92).endswith("chaotic")
    assert lyapunov_text(ds, sweep=0, omega=0.93).startswith("period 3, lambda1 = -0.0300")
    assert "within 3 errors" in lyapunov_text(ds, sweep=1, omega=0.9301)


def test_poincare_chaos_text_exact():
    import nonsmooth as ns
    d = ns.poincare(ns.preset("table3").replace(omega=0.92), transient=300, record=200,
                    method="exact")
    t = lyapunov_text(d)
    assert t.startswith("not periodic (period 0), lambda1 = 0.0") and t.endswith("chaotic")


@pytest.fixture(scope="module")
def small_diagram():
    import nonsmooth as ns
    return ns.bifurcation_diagram(ns.preset("table3"), "omega", [0.91, 0.92, 0.93],
                                  transient=100, record=40, method="exact")


def test_bifurcation_plot_lambda1_panel(small_diagram):
    from nonsmooth.plot.bifurcation import plot_bifurcation
    assert "lambda1" in small_diagram
    fig = plot_bifurcation(small_diagram)
    assert len(fig.axes) == 2
    top, low = fig.axes
    assert low.get_shared_x_axes().joined(top, low)
    assert "lambda_1" in low.get_ylabel()
    assert any(np.allclose(line.get_ydata(), 0) for line in low.get_lines())
    assert len(low.containers) == 2  # one errorbar series per sweep direction
    assert len(plot_bifurcation(small_diagram, lyapunov=False).axes) == 1
    assert len(plot_bifurcation(small_diagram.drop_vars(
        ["lambda1", "lambda1_stderr", "motion"])).axes) == 1
    with pytest.raises(Exception, match="lambda1"):
        plot_bifurcation(small_diagram.drop_vars(["lambda1"]), lyapunov=True)
