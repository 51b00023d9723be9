"""`nonsmooth models` and the `--model` option of the commands (real subprocesses: exit codes
and one-line errors as a user sees them)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

import nonsmooth as ns
from nonsmooth.io import load_dataset

EXAMPLE = str(Path(__file__).resolve().parents[1] / "examples" / "one_sided_duffing.py")


def _cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "nonsmooth.cli", *args], capture_output=True,
                          text=True, cwd=cwd, timeout=300, env=os.environ.copy())


def _one_error_line(r, needle):
    assert r.returncode == 2, (r.returncode, r.stderr)
    assert "Traceback" not in r.stderr + r.stdout
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: ") and needle in lines[0], lines


def test_models_lists_every_builtin_with_its_parameters():
    r = _cli("models")
    assert r.returncode == 0, r.stderr
    for name in ns.models():
        m = ns.model(name)
        assert f"{name}: {m.description}" in r.stdout
        for p in m.parameters:
            assert f"{p.name}={p.default:g} ({p.range_text})" in r.stdout


def test_models_name_shows_one_model_in_detail():
    r = _cli("models", "stick_slip")
    assert r.returncode == 0, r.stderr
    out = r.stdout
    for needle in ("parameters:", "static friction force / m", "0 < eta", "[1/s^2]",
                   "modes: 0 slip_forward, 1 slip_backward, 2 stick, 3 transition",
                   "methods:", "smooth", "exact", "presets (--preset NAME):", "coulomb:",
                   "stribeck:", "references:", "Leine"):
        assert needle in out, needle
    _one_error_line(_cli("models", "nosuch"), "model: unknown model 'nosuch'")


def test_simulate_another_builtin_model(tmp_path):
    r = _cli("simulate", "--model", "stick_slip", "--set", "v_belt=0.3", "--periods", "2",
             "--samples-per-period", "20", "-o", "s.nc", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("stick_slip (defaults) with v_belt=0.3: 2 periods")
    ds = load_dataset(tmp_path / "s.nc")
    assert ds.attrs["model"] == "stick_slip" and ds.attrs["param_v_belt"] == 0.3
    assert ds.sizes["t"] == 41
    r = _cli("simulate", "--model", "stick_slip", "--preset", "coulomb", "--method", "exact",
             "--periods", "1", "-o", "c.nc", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert load_dataset(tmp_path / "c.nc").attrs["preset"] == "stick_slip/coulomb"
    # the summary names the model's first component (the ball's height Z, not X) and gives
    # the dataset's max_X / min_X
    r = _cli("simulate", "--model", "bouncing_ball", "--preset", "period_one", "--method",
             "exact", "--periods", "2", "-o", "b.nc", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    ds = load_dataset(tmp_path / "b.nc")
    assert f"max Z = {float(ds.max_X):.6g}, min Z = {float(ds.min_X):.6g}" in r.stdout
    assert "max X" not in r.stdout


@pytest.mark.parametrize("args, needle", [
    (["--model", "support", "--set", "mu_s=1"], "mu_s: not a parameter of model 'support' (a parameter of stick_slip)"),
    (["--model", "stick_slip", "--set", "omega_s=1"], "omega_s: not a parameter of model "
                                                      "'stick_slip'"),
    (["--model", "nosuch"], "model: unknown model 'nosuch'"),
    (["--model", "stick_slip", "--preset", "table1"], "preset: unknown preset 'table1' of "
                                                      "model 'stick_slip'"),
    (["--model", "stick_slip", "--method", "rk4"], "method: model 'stick_slip' has no method"),
    (["--model", "nofile.py:MODEL"], "model: no such file"),
])
def test_model_errors_are_one_line_exit_2(args, needle, tmp_path):
    r = _cli("simulate", *args, "--periods", "1", "-o", "x.nc", cwd=tmp_path)
    _one_error_line(r, needle)
    assert not (tmp_path / "x.nc").exists()


def test_support_parameter_of_another_model_names_it(tmp_path):
    r = _cli("simulate", "--set", "mu_s=1", "--periods", "1", "-o", "x.nc", cwd=tmp_path)
    _one_error_line(r, "mu_s: not a parameter of model 'support' (a parameter of stick_slip)")
    assert "stick_slip" in r.stderr


def test_user_model_script_on_the_cli(tmp_path):
    model = f"{EXAMPLE}:MODEL"
    r = _cli("simulate", "--model", model, "--method", "exact", "--set", "k_s=50",
             "--periods", "2", "--transient", "5", "--samples-per-period", "20", "-o", "u.nc",
             "--plot", "u.png", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    ds = load_dataset(tmp_path / "u.nc")
    assert ds.attrs["model"] == "one_sided_duffing" and ds.attrs["param_k_s"] == 50.0
    assert (tmp_path / "u.png").read_bytes()[:4] == b"\x89PNG"
    r = _cli("poincare", "--model", model, "--method", "exact", "--record", "5",
             "--transient", "50", "-o", "p.nc", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "period 1, contact 1" in r.stdout
    r = _cli("bifurcation", "--model", model, "--param", "omega_s", "--from", "1", "--to", "2",
             "--steps", "2", "-o", "b.nc", cwd=tmp_path)
    _one_error_line(r, "omega_s: not a parameter of model 'one_sided_duffing'")
    r = _cli("models", model)
    assert r.returncode == 0 and "k_s" in r.stdout and "soft:" in r.stdout
