"""The built-in ``bouncing_ball`` (written as equations) against its closed forms: the
period-one orbit, its Floquet multipliers, its period doubling and its fold (located by
continuation, which moves the section off the impact), the smooth method converging to the exact
one, chatter ending in sticking."""

import math

import numpy as np
import pytest

import nonsmooth as ns

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")

M = ns.model("bouncing_ball")
W, R = 2 * math.pi, 0.5  # omega = 2 pi, g = 1: T = 1
G1 = math.pi * (1 - R) / (1 + R)  # the fold: Gamma cos(phi) = pi (1 - r)/(1 + r)
G_PD = math.hypot(G1, 2 * (1 + R * R) / (1 + R) ** 2)


def on_orbit(gamma, psi=0.0):
    """Parameters and the period-one orbit's state at the section of phase psi: the ball left
    the table at the phase phi with absolute velocity g T / 2 = 1/2."""
    A, phi = gamma / W**2, math.acos(G1 / gamma)
    s = (psi - phi) / W % 1.0  # flight time from the impact to the section
    z0 = 0.5 * s - 0.5 * s * s + A * math.sin(phi) - A * math.sin(psi)
    return M.params(A=A, r=R), z0, 0.5 - s - A * W * math.cos(psi)


def test_period_one_orbit_its_multipliers_and_its_period_doubling():
    ex = M.methods["exact"]  # flight (no stiffness) in closed form, no RKF45 left to tighten
    assert ex.closed_form and ex.rtol is None
    for gamma, crossed in ((1.2, False), (G_PD - 1e-3, False), (G_PD + 1e-3, True)):
        p, z0, v0 = on_orbit(gamma)
        ds = ns.simulate(p, periods=2, x0=z0, v0=v0, method="exact", samples_per_period=1)
        assert np.max(np.abs(ds.X.values - z0)) < 1e-9  # the closed-form orbit is periodic
        orb = ns.periodic_orbit(p, x0=z0, v0=v0, transient=0, method="exact")
        assert int(orb.converged) == 1 and abs(float(orb.X_section[0]) - z0) < 1e-9
        mu = orb.multiplier_real.values + 1j * orb.multiplier_imag.values
        trace = 1 + R * R - (1 + R) ** 2 * gamma * math.sin(math.acos(G1 / gamma))
        assert mu.sum().real == pytest.approx(trace, abs=1e-7)
        assert abs(np.prod(mu)) == pytest.approx(R * R, rel=1e-7)
        assert (np.min(mu.real) < -1.0) == crossed


def test_continuation_passes_the_fold_where_the_impact_falls_on_the_section():
    """At the fold the impact falls on t = kT: at phase 0 the period map is not smooth there
    and the corrector fails, so continuation moves the section a quarter period on (carrying
    the branch point and its tangent with the flow) and goes on; with the section at phase pi
    from the start it never needs to. Both locate the fold at Gamma = pi (1 - r)/(1 + r)."""
    for psi in (0.0, math.pi):
        p, z0, v0 = on_orbit(1.3, psi)
        br = ns.continuation(p, "A", x0=z0, v0=v0, direction="down",
                             bounds=(0.5 * G1 / W**2, 1.45 / W**2), section_phase=psi)
        assert list(br.special_type.values) == [1] and "bounds" in br.attrs["status"]
        assert br["special_A"].values[0] * W**2 == pytest.approx(G1, abs=1e-9)
        if psi == 0.0:
            assert "to 1.5708 rad" in br.attrs["section_moved"]
            ph = br.section_phase.values
            assert ph[0] == 0.0 and ph[-1] == pytest.approx(math.pi / 2)
        else:
            assert "section_moved" not in br.attrs


def test_smooth_table_converges_to_the_impact_law():
    """The compliant table restitutes r per contact; its period-one orbit tends to the exact
    one as k_c grows, like the contact time, k_c^(-1/2)."""
    p, z0, v0 = on_orbit(1.3)
    errs = []
    for kc in (1e5, 1e6, 1e7):
        sec = ns.poincare(p.replace(k_c=kc), record=20, transient=200, method="smooth", x0=z0,
                          v0=v0)
        assert int(sec.period) == 1
        errs.append(abs(float(sec.X[-1]) - z0) + abs(float(sec.V[-1]) - v0))
    assert errs[2] < 3e-4 and errs[0] / errs[1] > 2.5 and errs[1] / errs[2] > 2.5


def test_chatter_ends_in_sticking_not_zeno():
    ds = ns.simulate(M.preset("period_one"), periods=50, method="exact")  # from rest
    assert int(ds.regions_visited) & 0b10  # stuck on the table at some time
    assert float(ds.min_X) >= -1e-12  # never below the table
    assert float(ds.max_X) > 1e-3  # and launched again


def test_a_start_on_the_table_moving_into_it_bounces_at_once():
    """From Z = 0 with V = -0.3 (far faster than the sticking threshold) the exact method
    applies the impact at t = 0 (V -> 0.15) and flies: Z = 0.15 t - g t^2 / 2 + A omega t -
    A sin(omega t). It used to classify the start as riding on the table, keeping V = -0.3 (a
    review's finding)."""
    import math
    p = ns.model("bouncing_ball").preset("period_one")
    ds = ns.simulate(p, periods=1, method="exact", x0=0.0, v0=-0.3, samples_per_period=200)
    g, w, A = 1.0, 2 * math.pi, 1.3 / (4 * math.pi ** 2)
    t = ds.t.values[1:20]
    Z = 0.15 * t - g * t ** 2 / 2 + A * w * t - A * np.sin(w * t)
    V = 0.15 - g * t + A * w * (1 - np.cos(w * t))
    assert np.max(np.abs(ds.X.values[1:20] - Z)) < 1e-12
    assert np.max(np.abs(ds.V.values[1:20] - V)) < 1e-12


def test_results_describe_the_height_z_not_the_papers_x():
    """The result files' long names use the ball's own component names (Z, dZ/dt, its modes),
    not the paper's model's (displacement X, region of eq. 14); the units are its own."""
    import re
    p = M.preset("period_one")
    for ds in (ns.simulate(p, periods=2, method="exact"),
               ns.poincare(p, record=8, transient=2, method="exact")):
        for name in list(ds.data_vars) + list(ds.coords):
            long = str(ds[name].attrs.get("long_name", ""))
            assert not re.search(r"\bX\b|dX/dt|eq\. 14", long), (name, long)
        assert "Z" in ds.max_X.attrs["long_name"] and ds.max_X.attrs["units"] == "m"
    assert ds.V.attrs["units"] == "m/s"
    sim = ns.simulate(p, periods=1, method="exact")
    assert sim.X.attrs["long_name"] == M.state_long_names[0]
    assert sim.region.attrs["long_name"] == "mode at t"
