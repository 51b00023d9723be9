"""Folds continued in two parameters as one extended system (``ns.fold_curve``, issue 21
item 4): on the cusp normal form X' = a + b X - X^3 (with a decoupled, forced V' = -V +
cos t, whose multiplier is e^(-T)) the time-T map
has its folds exactly where the equilibria fold, a = -2 X^3, b = 3 X^2; the curve runs through
the cusp at (0, 0), where the two folds meet, and the cusp is located there."""

import numpy as np
import pytest
import xarray as xr

import nonsmooth as ns
from nonsmooth.errors import ParameterError

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")


def cusp_model():
    """The cusp normal form with a forced V and a third component W' = (X - c) W (W = 0 on
    the orbits, its multiplier e^((X - c) T): far from 1 for c = 5)."""
    return ns.model_from_equations(
        "cusp_with_w", states=("X", "V", "W"),
        parameters={"a": 0.3, "b": 1.0, "c": 5.0, "omega": 1.0},
        modes={"free": ["a + b*X - X**3", "-V + cos(omega*t)", "(X - c)*W"]}, method="smooth",
        forcing_amplitude=None)


@pytest.fixture(scope="module")
def setup():
    p = cusp_model().params(a=0.3, b=1.0)
    br = ns.continuation(p, "a", x0=-0.8, bounds=(0.3, 0.5), method="smooth", step=0.02)
    return p, br


def test_the_fold_curve_of_the_cusp_normal_form_runs_through_the_cusp(setup):
    p, br = setup
    assert br.special_type.values.tolist() == [1]  # one fold, at 2 (1/3)^(3/2)
    assert float(br.special_a[0]) == pytest.approx(2 * 3 ** -1.5, abs=1e-8)
    fc = ns.fold_curve(p, "a", "b", start=br, direction="down", step=0.02,
                       bounds=(-1.0, 1.0), bounds2=(-0.5, 1.5))
    X, a, b = fc.X_section.values, fc.a.values, fc.b.values
    np.testing.assert_allclose(a, -2 * X ** 3, atol=1e-9)
    np.testing.assert_allclose(b, 3 * X ** 2, atol=1e-9)
    np.testing.assert_allclose(fc.V_section.values, 0.5, atol=1e-8)  # V = (cos t + sin t)/2
    # a multiplier 1 all along (the X direction), then e^(-T), then W's e^((X - 5) T)
    mu = np.sort(fc.multiplier_abs.values, axis=1)
    np.testing.assert_allclose(mu[:, 2], 1.0, atol=1e-7)
    np.testing.assert_allclose(mu[:, 1], np.exp(-2 * np.pi), rtol=1e-6)
    np.testing.assert_allclose(mu[:, 0], np.exp((X - 5) * 2 * np.pi), rtol=1e-3, atol=1e-12)
    # through the cusp onto the other fold: X from -1/sqrt(3) to positive, a changes sign
    assert X[0] == pytest.approx(-3 ** -0.5, abs=1e-8) and X[-1] > 0.5 and a[-1] < -0.3
    assert fc.attrs["status"] == "left the bounds of b"
    assert fc.sizes["cusp"] == 1
    assert abs(float(fc.cusp_a[0])) < 1e-4 and abs(float(fc.cusp_b[0])) < 2e-3
    assert fc.attrs["analysis"] == "fold_curve" and "param_a" not in fc.attrs
    assert fc.sizes["codim2"] == 0  # the other multipliers never cross the circle


def test_a_codimension_two_point_on_a_fold_curve_is_located_and_labelled():
    """With a third component W' = (X - c) W (W = 0 on the orbit, its multiplier
    e^((X - c) T)), the fold curve meets a second multiplier 1 where the fold's X is c: a 1:1
    resonance at (a, b) = (-2 c^3, 3 c^2), here c = 0.3: (-0.054, 0.27)."""
    p = cusp_model().params(c=0.3)
    br = ns.continuation(p, "a", x0=-0.8, bounds=(0.3, 0.5), method="smooth", step=0.02)
    fc = ns.fold_curve(p, "a", "b", start=br, direction="down", step=0.02,
                       bounds=(-1.0, 1.0), bounds2=(-0.5, 1.5))
    assert fc.X_section.values[-1] > 0.5  # through the cusp and past X = c
    assert fc.sizes["codim2"] == 1
    assert fc.codim2_type.attrs["flag_meanings"].split()[int(fc.codim2_type[0])] == \
        "one_to_one_resonance"
    # located by Illinois on the curve (linear interpolation of the test gave 1.1e-5 and
    # 2.5e-4 with these steps of 0.02); the fold's multiplier and the crossing one are both
    # within ~1e-6 of 1 there, which bounds what the test function resolves
    assert abs(float(fc.codim2_a[0]) + 0.054) < 1e-5  # measured 5.6e-7
    assert abs(float(fc.codim2_b[0]) - 0.27) < 1e-5  # measured 1.9e-6


def test_fold_curve_bad_input(setup):
    p, br = setup
    with pytest.raises(ParameterError, match="param2: must differ"):
        ns.fold_curve(p, "a", "a", start=br)
    with pytest.raises(ParameterError, match="start:"):
        ns.fold_curve(p, "a", "b", start=xr.Dataset())
    with pytest.raises(ParameterError, match="special:"):
        ns.fold_curve(p, "a", "b", start=br, special=3)
    with pytest.raises(ParameterError, match="start:"):
        ns.fold_curve(p, "b", "a", start=br)  # a branch in a, not in b


def test_fold_and_period_doubling_curves_of_the_bouncing_ball_are_its_closed_forms():
    """The bouncing ball's period-one orbit folds at Gamma = A omega^2 / g = pi (1 - r)/(1 + r)
    and flips at Gamma = hypot(pi (1 - r)/(1 + r), 2 (1 + r^2)/(1 + r)^2): both curves in
    (A, r), continued both ways from r = 0.5 on the extended systems (section at phase pi: at
    phase 0 the fold's impact falls on the section)."""
    import math
    m = ns.model("bouncing_ball")
    W, R, psi = 2 * math.pi, 0.5, math.pi

    def g_fold(r):
        return math.pi * (1 - r) / (1 + r)

    def g_flip(r):
        return math.hypot(g_fold(r), 2 * (1 + r * r) / (1 + r) ** 2)

    def on_orbit(gamma):
        A, phi = gamma / W**2, math.acos(g_fold(R) / gamma)
        s = (psi - phi) / W % 1.0
        z0 = 0.5 * s - 0.5 * s * s + A * math.sin(phi) - A * math.sin(psi)
        return m.params(A=A, r=R), z0, 0.5 - s - A * W * math.cos(psi)

    for curve, gamma, direction, law, mu in (
            (ns.fold_curve, 1.3, "down", g_fold, 1.0),
            (ns.period_doubling_curve, 1.2, "up", g_flip, -1.0)):
        p, z0, v0 = on_orbit(gamma)
        lo, hi = 0.5 * g_fold(R) / W**2, (g_flip(R) + 0.2) / W**2
        br = ns.continuation(p, "A", x0=z0, v0=v0, direction=direction, bounds=(lo, hi),
                             section_phase=psi)
        for way in ("up", "down"):
            c = curve(p, "A", "r", start=br, direction=way, step=0.02, bounds2=(0.3, 0.7))
            assert c.attrs["status"] == "left the bounds of r" and c.sizes["cusp"] == 0
            r = c.r.values
            assert (r.max() > 0.69) if way == "up" else (r.min() < 0.31)
            err = [abs(a * W**2 - law(rr)) for a, rr in zip(c.A.values, r)]
            assert max(err) < (1e-12 if mu > 0 else 1e-8)  # measured 1e-15, 1.2e-9
            assert np.max(np.abs(c.multiplier_real.values[:, 0] - mu)) < 1e-7
            assert c.attrs["section_phase"] == psi
    with pytest.raises(ParameterError, match="no period doubling"):
        ns.period_doubling_curve(p, "A", "r", start=ns.continuation(
            p, "A", x0=z0, v0=v0, bounds=(1.2 / W**2, 1.3 / W**2), section_phase=psi))


def test_cli_continues_the_fig6a_fold_as_an_extended_system(tmp_path, capsys):
    """``nonsmooth continue --two-param omega_s --extended up``: Fig. 6a's upper fold omega_c
    rises with the support's stiffness; at omega_s = 5 it is where ``two_parameter_curve``
    re-locates it (1.264323)."""
    from cli_helpers import one_line, run_cli
    from nonsmooth.io import load_dataset
    nc, png = tmp_path / "f.nc", tmp_path / "f.png"
    args = ["continue", "--param", "omega", "--set", "omega=0.5", "--bounds", "0.5", "1.6",
            "--two-param", "omega_s", "--step", "0.02"]
    code, out, err = run_cli(args + ["--extended", "up", "--bounds2", "1", "5.5", "-o", str(nc),
                                     "--plot", str(png)], capsys)
    assert code == 0, err
    ds = load_dataset(nc)
    assert ds.attrs["analysis"] == "fold_curve" and ds.attrs["status"] == \
        "left the bounds of omega_s"
    assert "fold of the period-1 branch at omega = 1.1930415" in out
    w, ws = ds.omega.values, ds.omega_s.values
    assert np.all(np.diff(ws) > 0)
    assert abs(np.interp(5.0, ws, w) - 1.264323) < 2e-4  # linear interpolation, steps 0.02
    assert np.max(np.abs(ds.multiplier_real.values[:, 0] - 1.0)) < 1e-7
    assert png.read_bytes()[:4] == b"\x89PNG"
    for extra, needle in ((["--extended", "sideways"], "extended"),
                          (["--extended", "up", "--special", "nope"], "special")):
        code, out, err = run_cli(args + extra + ["-o", str(nc)], capsys)
        assert code == 2
        one_line(err, needle)
    code, out, err = run_cli(args[:-4] + ["--extended", "up", "-o", str(nc)], capsys)
    assert code == 2
    one_line(err, "--two-param")
    code, out, err = run_cli(args + ["--bounds2", "1", "5", "-o", str(nc)], capsys)
    assert code == 2
    one_line(err, "bounds2: only with --extended")


def test_the_grazing_curve_of_the_contact_free_orbit_is_its_closed_form():
    """Fig. 6a's contact-free orbit X'' + xi X' + X = F0 cos(omega t) grazes the support
    (X = 1) where its amplitude is 1: F0 = sqrt((1 - omega^2)^2 + (xi omega)^2). The grazing
    that continuation locates at omega_a = 0.9403, continued both ways in (omega, F0)."""
    p = ns.preset("fig6a").replace(omega=0.5)
    br = ns.continuation(p, "omega", bounds=(0.5, 1.6), method="exact")
    assert br.special_type.values[0] == 4  # grazing first
    for way in ("up", "down"):
        c = ns.grazing_curve(p, "omega", "F0", start=br, direction=way, step=0.02,
                             bounds2=(0.05, 0.5), bounds=(0.3, 1.6))
        assert c.attrs["status"] == "left the bounds of F0"
        assert c.attrs["analysis"] == "grazing_curve" and c.sizes["point"] > 10
        w, F = c.omega.values, c.F0.values
        assert np.max(np.abs(F - np.sqrt((1 - w**2) ** 2 + (p.xi * w) ** 2))) < 1e-10
        assert np.max(np.abs(c.max_X.values - 1.0)) < 1e-10
        assert (F.max() > 0.5) if way == "up" else (F.min() < 0.05)
    q = cusp_model().params()  # a model without a contact level
    fake = br.copy()
    fake.attrs.update(model="cusp_with_w", method="smooth")
    with pytest.raises(ParameterError, match="declares no contact level"):
        ns.grazing_curve(q, "omega", "a", start=fake)
