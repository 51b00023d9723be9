"""Parameters, presets, result files and the `simulate` / `presets` commands."""

import math
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import nonsmooth as ns
from nonsmooth.io import load_dataset, save_dataset
from nonsmooth.models.support import from_dimensional

VALID = dict(omega0=1.0, omega_s=3.0, xi=0.05, xi_s=0.3, F0=0.1, omega=0.9, eta=1e-5)


# ---------------------------------------------------------------- the support model's parameters
@pytest.mark.parametrize("field, value", [
    ("omega0", 0.0), ("omega0", -1.0), ("omega_s", -1.0), ("xi", -0.1), ("xi_s", -0.1),
    ("omega", 0.0), ("eta", 0.0), ("eta", -1.0), ("eta", 0.5), ("F0", math.nan),
    ("omega", math.inf), ("xi", "abc"),
])
def test_invalid_parameter_names_the_field(field, value):
    with pytest.raises(ns.ParameterError) as exc:
        ns.model("support").params(**{**VALID, field: value})
    msg = str(exc.value)
    assert msg.startswith(f"{field}:") and "\n" not in msg


def test_replace_validates_and_rejects_unknown_names():
    p = ns.model("support").params(**VALID)
    assert p.replace(omega=1.2).omega == 1.2 and p.omega == 0.9  # immutable
    with pytest.raises(ns.ParameterError, match="^nope: not a parameter of model 'support'"):
        p.replace(nope=1)
    with pytest.raises(ns.ParameterError, match="^eta:"):
        p.replace(eta=-1)
    with pytest.raises(AttributeError):
        p.omega = 2.0


def test_support_without_stiffness_needs_no_damping():
    ns.model("support").params(**{**VALID, "omega_s": 0.0, "xi_s": 0.0})
    with pytest.raises(ns.ParameterError, match="^omega_s:"):
        ns.model("support").params(**{**VALID, "omega_s": 0.0})


def test_from_dimensional_follows_eq3():
    m, k, c, ks, cs, f0, g = 2.0, 8.0, 0.4, 50.0, 1.0, 3.0, 0.01
    p = from_dimensional(m=m, k=k, c=c, k_s=ks, c_s=cs, f0=f0, g=g, omega=1.5,
                                   eta_hat=1e-5)
    assert p.omega0 == pytest.approx(2.0) and p.omega_s == pytest.approx(5.0)
    assert p.xi == pytest.approx(0.2) and p.xi_s == pytest.approx(0.5)
    assert p.F0 == pytest.approx(f0 / (m * g)) and p.eta == pytest.approx(1e-3)
    with pytest.raises(ns.ParameterError, match="^g:"):
        from_dimensional(m=m, k=k, c=c, k_s=ks, c_s=cs, f0=f0, g=0.0, omega=1.0)


@settings(max_examples=60, deadline=None)
@given(st.floats(1e-3, 1e3), st.floats(0, 1e3), st.floats(0, 10), st.floats(0, 10),
       st.floats(-1e3, 1e3), st.floats(1e-3, 1e2), st.floats(1e-9, 0.49))
def test_valid_parameters_round_trip_through_pack_and_attrs(w0, ws, xi, xis, F0, om, eta):
    if ws == 0.0:
        xis = 0.0
    p = ns.model("support").params(omega0=w0, omega_s=ws, xi=xi, xi_s=xis, F0=F0, omega=om, eta=eta)
    packed = p.pack()
    assert packed.dtype == np.float64 and list(packed) == [getattr(p, n) for n in ns.PARAM_NAMES]
    assert ns.model("support").params_from_attrs(p.attrs()) == p


def test_presets_match_the_paper_tables():
    t1 = ns.preset("table1")
    assert (t1.omega0, t1.omega_s, t1.xi, t1.xi_s, t1.F0, t1.omega, t1.eta) == (
        4.5, 38.0, 1.04, 0.72, 144.9, 5.0, 7.14e-3)
    assert ns.preset("fig4").F0 == 76.24 and ns.preset("fig4").omega == 9.55
    assert ns.preset("table2").eta == 2.5e-6
    assert ns.preset("fig6a").omega_s == 3.16 and ns.preset("fig6b").omega_s == 7.07
    assert ns.preset("fig7").omega == 1.10 and ns.preset("fig7").omega_s == 3.16
    t3 = ns.preset("table3")
    assert (t3.omega_s, t3.xi_s, t3.F0, t3.omega, t3.eta) == (17.32, 0.6, 0.3125, 0.91, 6.25e-6)
    t4 = ns.preset("table4")
    assert (t4.omega_s, t4.xi_s, t4.F0, t4.omega, t4.eta) == (31.6, 0.6, 0.225, 0.9, 5e-6)
    with pytest.raises(ns.ParameterError, match="^preset: unknown preset 'missing'"):
        ns.preset("missing")


# ---------------------------------------------------------------- simulate
def test_simulate_dataset_layout_and_provenance(tmp_path):
    p = ns.preset("table1")
    ds = ns.simulate(p, periods=2, transient=3, samples_per_period=50)
    T = p.period
    assert ds.sizes["t"] == 101
    np.testing.assert_allclose(ds.t.values, 3 * T + np.arange(101) * T / 50, rtol=1e-14)
    assert ds.region.dtype == np.int8 and "flag_meanings" in ds.region.attrs
    assert ds.attrs["nonsmooth_version"] == ns.__version__
    assert ds.attrs["method"] == "smooth" and ds.attrs["rtol"] == 1e-8
    assert ns.model("support").params_from_attrs(ds.attrs) == p
    back = load_dataset(save_dataset(ds, tmp_path / "s.nc"))
    np.testing.assert_array_equal(back.X.values, ds.X.values)
    assert ns.model("support").params_from_attrs(back.attrs) == p


def test_simulate_rejects_bad_arguments():
    p = ns.preset("table1")
    for kw, field in ((dict(periods=0), "periods"), (dict(periods=1, transient=-1), "transient"),
                      (dict(periods=1, samples_per_period=0), "samples_per_period"),
                      (dict(periods=1, x0=math.nan), "x0"), (dict(periods=1, method="rk4"), "method"),
                      (dict(periods=1, rtol=0.0), "rtol")):
        with pytest.raises(ns.ParameterError, match=f"^{field}:"):
            ns.simulate(p, **kw)


def test_simulate_is_identical_when_split_into_calls():
    """The kernel state carries everything (incl. the step size and the Sigma_alpha memory):
    a transient of 7 periods then 3 recorded equals 10 periods straight through."""
    p = ns.preset("table3").replace(omega=0.92)
    a = ns.simulate(p, periods=3, transient=7, samples_per_period=1)
    b = ns.simulate(p, periods=10, samples_per_period=1)
    np.testing.assert_array_equal(a.X.values, b.X.values[7:])


# ---------------------------------------------------------------- CLI
def _cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "nonsmooth.cli", *args], capture_output=True,
                          text=True, cwd=cwd, timeout=300)


@pytest.mark.parametrize("args, needle", [
    (["--set", "eta=-1"], "eta:"),
    (["--set", "omega=nan"], "omega:"),
    (["--set", "nope=1"], "nope: not a parameter of model 'support'"),
    (["--set", "omega"], "expected NAME=VALUE"),
    (["--preset", "missing"], "preset: unknown preset"),
    (["--periods", "0"], "periods:"),
    (["-o", "/nonexistent-dir/x.nc"], "output: cannot write"),
    (["--plot", "/nonexistent-dir/x.png"], "plot: cannot write"),
    (["-o", "x.png"], "a result is a netCDF file, give a name ending in .nc (a figure: --plot)"),
    (["-o", "x.txt"], "'x.txt': a result is a netCDF file"),  # (it wrote netCDF in x.txt)
    (["--nope"], "No such option: --nope"),  # click's usage errors: one line too (a newcomer
    (["--periods", "abc"], "Invalid value for '--periods'"),  # saw typer's 5-line box)
])
def test_simulate_bad_input_one_line_nonzero_no_traceback(args, needle, tmp_path):
    argv = ["simulate", *args]
    if "-o" not in args and "--plot" not in args:
        argv += ["-o", str(tmp_path / "x.nc")]
    r = _cli(*argv)
    assert r.returncode != 0
    assert "Traceback" not in r.stderr + r.stdout
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: ") and needle in lines[0]
    assert not (tmp_path / "x.nc").exists()


def test_eq12_is_a_method_of_the_support_model(tmp_path):
    """The eq. 12 variant is ``--method smooth_eq12`` (it was ``--transition eq12``): the same
    numbers from the CLI and from the library, and different ones from eq. 13."""
    r = _cli("simulate", "--preset", "table1", "--method", "smooth_eq12", "--periods", "2",
             "--transient", "5", "-o", str(tmp_path / "t.nc"))
    assert r.returncode == 0, r.stderr
    ds = load_dataset(tmp_path / "t.nc")
    assert ds.attrs["method"] == "smooth_eq12"
    p = ns.preset("table1")
    lib = ns.simulate(p, periods=2, transient=5, method="smooth_eq12")
    np.testing.assert_array_equal(ds.X.values, lib.X.values)
    eq13 = ns.simulate(p, periods=2, transient=5)
    assert np.max(np.abs(eq13.X.values - lib.X.values)) > 1e-6
    r = _cli("simulate", "--transition", "eq12", "-o", str(tmp_path / "u.nc"))
    assert r.returncode == 2 and "Traceback" not in r.stderr + r.stdout
    assert r.stderr.strip().splitlines() == ["error: transition: the option is gone; eq. 12 is "
                                             "the support model's method: --method smooth_eq12 "
                                             "(eq. 13 is --method smooth)"]


def test_simulate_command_writes_netcdf_and_png(tmp_path):
    r = _cli("simulate", "--preset", "table1", "--set", "omega=5.2", "--periods", "2",
             "--transient", "5", "--samples-per-period", "100", "-o", str(tmp_path / "t.nc"),
             "--plot", str(tmp_path / "t.png"))
    assert r.returncode == 0, r.stderr
    ds = load_dataset(tmp_path / "t.nc")
    assert ds.attrs["param_omega"] == 5.2 and ds.attrs["preset"] == "table1"
    # the summary line and the file say what --set changed in the preset (a newcomer's report:
    # "table1" alone read as the preset's own omega)
    assert ds.attrs["preset_changes"] == "omega=5.2"
    assert r.stdout.startswith("table1 with omega=5.2: 2 periods after 5")
    assert ds.sizes["t"] == 201
    assert (tmp_path / "t.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_presets_command_lists_every_preset():
    r = _cli("presets")
    assert r.returncode == 0
    for name in ns.PRESETS:
        assert name in r.stdout


def test_version_option():
    r = _cli("--version")
    assert r.returncode == 0 and r.stdout.strip() == f"nonsmooth {ns.__version__}"
