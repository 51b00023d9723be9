"""Issue 8 item 2: a period label is never reported from a section that has not settled.

Oracles: the paper's points and an independent check of the settled section (plain numpy on
the section after a 10000-period transient), not the package's period detection."""

import numpy as np
import pytest

import nonsmooth as ns
from nonsmooth.analysis.bifurcation import bifurcation_diagram
from nonsmooth.analysis.periodicity import NOT_SETTLED
from nonsmooth.analysis.poincare import poincare

P4 = ns.preset("table4")


def test_slow_period_2_is_not_labelled_0_or_4():
    # F0 = 0.3675: period 2 with a Floquet multiplier -0.989; after 500 periods the
    # section repeated with period 4 or not at all (labels 0 / 4 before the fix)
    p = P4.replace(F0=0.3675)
    ref = poincare(p, record=40, transient=10000, method="exact")  # no early end
    X = ref.X.values
    assert np.abs(X[2:] - X[:-2]).max() < 1e-8 and np.abs(X[1:] - X[:-1]).min() > 0.1
    ds = poincare(p, record=200, transient=500, method="exact")
    assert int(ds.period) == 2 and int(ds.transient_used) > 500
    b = bifurcation_diagram(P4, "F0", [0.35, 0.3675], sweep="fresh", transient=500,
                            record=200, method="exact")
    assert list(b.period.values[0]) == [0, 2]


def test_too_short_a_budget_says_not_settled():
    # 50 + 60 periods, extended at most 20 x 60: still converging -> -1, not period 4
    ds = poincare(P4.replace(F0=0.3675), record=60, transient=50, method="exact")
    assert int(ds.period) == NOT_SETTLED == -1
    assert "-1 = not" in ds.period.attrs["long_name"]


@pytest.mark.parametrize("name, change", [("table3", dict(omega=0.92)),
                                          ("table4", dict(F0=0.35))])
@pytest.mark.parametrize("method", ["exact", "smooth"])
def test_chaos_stays_period_0_and_is_not_extended(name, change, method):
    ds = poincare(ns.preset(name).replace(**change), record=200, transient=500, method=method)
    assert int(ds.period) == 0 and int(ds.transient_used) == 500
