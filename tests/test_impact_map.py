"""Sections on a surface of forced systems (issue 23, items 3 and 4): the impact map, whose
section is a switching surface itself, recorded with the state before the reset and the
forcing phase, against closed forms; a section on a stick surface of a self-excited system."""

import math

import numpy as np
import pytest

import nonsmooth as ns

BALL = ns.model("bouncing_ball")


def period_one(p):
    """The bouncing ball's stable period-one orbit (g = 1, T = 1), in closed form: the impact
    phase phi (Gamma cos phi = pi (1 - r)/(1 + r), sin phi > 0), the velocity before impact
    relative to the table, -1/(1 + r), and the state (Z, V) at t = 0: the ball left the table at
    phi - omega with the absolute velocity g T / 2 = 1/2."""
    r, A, w = p.r, p.A, p.omega
    phi = math.acos(math.pi * (1 - r) / (1 + r) / (A * w**2))
    ti = phi / w
    z0 = A * math.sin(phi) + 0.5 * (1 - ti) - (1 - ti) ** 2 / 2
    return phi, -1 / (1 + r), (z0, 0.5 - (1 - ti) - A * w)


def test_the_bouncing_balls_impact_map_has_the_closed_form_period_one_orbit():
    p = BALL.preset("period_one")
    phi, v_impact, (z0, v0) = period_one(p)
    ds = ns.surface_section(p, "Z", crossings=6, transient=0, x0=z0, v0=v0)
    # every impact of the orbit: on the table, the closed form's phase and velocity (the
    # state before the reset: after it, V = -r V), once per forcing period
    assert np.allclose(ds.phase.values, phi, atol=1e-12, rtol=0)
    assert np.allclose(ds.V.values, v_impact, atol=1e-12, rtol=0)
    assert np.max(np.abs(ds.X.values)) < 1e-12
    assert np.allclose(ds.t.values, phi / p.omega + np.arange(6), atol=1e-12, rtol=0)
    assert int(ds.cycle_crossings) == 1 and float(ds.cycle_period) == pytest.approx(1.0,
                                                                                     abs=1e-12)
    assert ds.phase.attrs["units"] == "rad" and int(ds.at_equilibrium) == 0
    # from a start off the orbit the impacts converge onto it (a stable orbit)
    far = ns.surface_section(p, "Z", crossings=4, transient=200, x0=z0 + 0.01, v0=v0)
    assert np.allclose(far.phase.values, phi, atol=1e-9, rtol=0)
    assert np.allclose(far.V.values, v_impact, atol=1e-9, rtol=0)
    # the other way across the table's surface: none (an impact reverses V; the ball never
    # passes from Z < 0 to Z > 0), so the record runs out of time in one line
    with pytest.raises(ns.errors.IntegrationError, match="no crossing: 0 of 2 crossings"):
        ns.surface_section(p, ("Z", "increasing"), crossings=2, transient=0, x0=z0, v0=v0,
                           max_time=20)


def test_the_impact_map_along_the_table_amplitude_follows_the_closed_form():
    p = BALL.preset("period_one")
    amplitudes = np.array([1.2, 1.3, 1.45]) / p.omega**2  # Gamma below the period doubling
    _, _, (z0, v0) = period_one(p.replace(A=amplitudes[0]))
    ds = ns.surface_bifurcation_diagram(p, "A", amplitudes, "Z", crossings=3, transient=150,
                                        x0=z0, v0=v0)
    for i, A in enumerate(amplitudes):
        phi, v_impact, _ = period_one(p.replace(A=A))
        assert np.allclose(ds.phase.values[i], phi, atol=1e-9, rtol=0)
        assert np.allclose(ds.V.values[i], v_impact, atol=1e-9, rtol=0)
    assert list(ds.cycle_crossings.values) == [1, 1, 1] and list(ds.status.values) == [0, 0, 0]


def test_a_section_of_a_forced_linear_oscillator_at_its_closed_form_maxima():
    """A forced section off every switching surface: V = 0 decreasing, at the maxima of the
    steady state X = a cos(omega t - delta) of X'' + c X' + X = F0 cos(omega t), so at the
    phase delta with X = a."""
    m = ns.model_from_equations("forced_linear", states=("X", "V"),
                                parameters={"c": 0.1, "F0": 0.4, "omega": 0.7},
                                modes={"free": ["V", "-X - c*V + F0*cos(omega*t)"]},
                                forcing_amplitude="F0")
    p = m.params()
    a = p.F0 / math.hypot(1 - p.omega**2, p.c * p.omega)
    delta = math.atan2(p.c * p.omega, 1 - p.omega**2)
    ds = ns.surface_section(p, "V", crossings=3, transient=0, x0=a * math.cos(delta),
                            v0=a * p.omega * math.sin(delta))
    assert np.allclose(ds.phase.values, delta, atol=1e-9, rtol=0)
    assert np.allclose(ds.X.values, a, atol=1e-9, rtol=0)
    assert np.allclose(ds.return_time.values[1:], 2 * math.pi / p.omega, atol=1e-9, rtol=0)


def test_a_self_excited_section_on_the_stick_surface_counts_each_arrival():
    """Leine's belt-driven oscillator (stick_slip, F0 = 0) crosses V = v_belt only at the
    switching event into sticking: the section on that surface records each arrival (the
    state before the transition: the Coulomb cycle's X = (2 mu_k - mu_s)/omega0^2) once per
    cycle of the closed form's period."""
    p = ns.model("stick_slip").params()
    d = (p.mu_s - p.mu_k) / p.omega0**2
    period = 2 * d / p.v_belt + (math.pi + 2 * math.atan2(p.v_belt / p.omega0, d)) / p.omega0
    ds = ns.surface_section(p, ("V - v_belt", "increasing"), crossings=4, transient=2, v0=1.0)
    assert np.allclose(ds.X.values, (2 * p.mu_k - p.mu_s) / p.omega0**2, atol=1e-9, rtol=0)
    assert np.allclose(ds.V.values, p.v_belt, atol=1e-12, rtol=0)
    assert np.allclose(ds.return_time.values[1:], period, atol=1e-9, rtol=0)
    assert int(ds.cycle_crossings) == 1 and "phase" not in ds
    # the cycle on that surface by Newton: its map runs from one arrival's state (before the
    # switch into sticking, where the flow crosses the surface) to the next; sticking merges
    # the arrivals, so its multiplier is 0
    lc = ns.limit_cycle(p, ("V - v_belt", "increasing"), v0=1.0)
    assert lc.attrs["status"] == "converged"
    assert float(lc.period) == pytest.approx(period, abs=1e-9)
    assert float(lc.X_section) == pytest.approx((2 * p.mu_k - p.mu_s) / p.omega0**2, abs=1e-9)
    assert float(lc.multiplier_abs[0]) < 1e-9


def test_the_impact_map_on_the_cli_shows_the_phase(tmp_path, capsys):
    from cli_helpers import one_line, run_cli
    _, _, (z0, v0) = period_one(BALL.preset("period_one"))
    code, out, _ = run_cli(["surface-bifurcation", "--model", "bouncing_ball", "--preset",
                            "period_one", "--param", "A", "--from", "0.031", "--to", "0.034",
                            "--steps", "2", "--section", "Z", "--x0", str(z0), "--v0", str(v0),
                            "--transient", "50", "--crossings", "4", "--show", "phase",
                            "-o", str(tmp_path / "im.nc"), "--plot", str(tmp_path / "im.png")],
                           capsys)
    assert code == 0 and "2 cycles (1 crossing(s) per turn: 2)" in out
    assert (tmp_path / "im.png").stat().st_size > 0
    code, _, err = run_cli(["surface-bifurcation", "--param", "v_belt", "--from", "0.2",
                            "--to", "0.3", "--steps", "2", "--show", "phase"], capsys)
    assert code == 2
    one_line(err, "show: phase: only a forced system's crossings have a forcing phase")


def test_the_compliant_impact_oscillators_contacts_against_scipy():
    """The smooth ``impact`` model (a stiff spring-damper beyond X = 1, RKF45): its section on
    the contact surface X - 1 counts every onset (increasing) and every separation
    (decreasing) of an independent event-driven solution (scipy DOP853, 1e-12) once, at its
    time to 1e-8. The RKF45's located event may lie past the surface by about 1e-8, which
    must still count as the crossing (a review found 8 of 20 onsets at the default
    tolerance before)."""
    from scipy.integrate import solve_ivp
    from nonsmooth.models.impact import contact_damping
    p = ns.model("impact").params(F0=4.0, omega=2.0, r=0.7, xi=0.1, k_c=1e3)
    c = contact_damping(p.r, p.k_c)

    def f(t, u, contact):
        a = -p.omega0**2 * u[0] - p.xi * u[1] + p.F0 * math.cos(p.omega * t)
        return [u[1], a - (p.k_c * (u[0] - 1) + c * u[1] if contact else 0.0)]

    t, u, contact, ref = 0.0, np.array([0.0, 0.5]), False, {True: [], False: []}
    while True:
        def ev(t, u, *a):
            return u[0] - 1.0
        ev.terminal, ev.direction = True, (-1 if contact else 1)
        s = solve_ivp(f, (t, 25.0), u, args=(contact,), events=ev, method="DOP853",
                      rtol=1e-12, atol=1e-13)
        if not s.t_events[0].size:
            break
        t, u = s.t_events[0][0], s.y_events[0][0].copy()
        ref[not contact].append(t)
        contact = not contact
    for direction, times in (("increasing", ref[True]), ("decreasing", ref[False])):
        ds = ns.surface_section(p, ("X - 1", direction), crossings=len(times), transient=0,
                                x0=0.0, v0=0.5, method="smooth", max_time=25.0)
        assert len(times) == 8 and np.allclose(ds.t.values, times, atol=1e-8, rtol=0)
