"""The CLI framework: exit codes, Ctrl-C / SIGTERM with one line on what was saved and lost,
figure paths checked before computing, the first-run compilation notice. Real subprocesses,
real signals."""

import os
import signal
import subprocess
import sys
import textwrap

import xarray as xr

from nonsmooth import io

from cli_helpers import SAFETY_S, popen

# Runs the CLI with one step of the work replaced by a stand-in that reports "ready" on stdout
# and waits, so that a signal arrives in the middle of it: the trajectory ("simulate") or the
# figure ("plot", after the netCDF file was written).
DRIVER = """
import sys, time
import nonsmooth.simulate, nonsmooth.plot.time_response

def wait(*args, **kwargs):
    print("ready", flush=True)
    while True:
        time.sleep(1)

if "{stage}" == "simulate":
    sys.modules["nonsmooth.simulate"].simulate = wait
else:
    sys.modules["nonsmooth.plot.time_response"].plot_time_response = wait
from nonsmooth.cli import main
main({argv!r})
"""


def _interrupt(tmp_path, stage, sig, argv):
    proc = popen([sys.executable, "-c", DRIVER.format(stage=stage, argv=argv)],
                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    try:
        assert proc.stdout.readline().strip() == "ready"
        proc.send_signal(sig)
        out, err = proc.communicate(timeout=SAFETY_S)
    finally:
        proc.kill()
    return proc.returncode, out, err


def test_ctrl_c_says_what_was_saved_and_what_was_lost(tmp_path):
    # interrupted while drawing the figure: the netCDF file is saved, the figure is not
    code, out, err = _interrupt(tmp_path, "plot", signal.SIGINT,
                                ["simulate", "--periods", "1", "--samples-per-period", "10",
                                 "-o", "r.nc", "--plot", "r.png"])
    assert code == 130  # before the fix: 130 and nothing on stderr (typer's silent exit)
    assert err.splitlines() == ["interrupted: saved r.nc; lost the computation in progress; "
                                "no partial result written; r.png not written"]
    assert io.load_dataset(tmp_path / "r.nc").sizes["t"] == 11
    assert not (tmp_path / "r.png").exists()


def test_sigterm_takes_the_same_path_and_leaves_the_old_file(tmp_path):
    io.save_dataset(xr.Dataset(attrs={"run": "old"}), tmp_path / "r.nc")
    code, out, err = _interrupt(tmp_path, "simulate", signal.SIGTERM,
                                ["simulate", "-o", "r.nc", "--plot", "noext"])
    assert code == 143
    assert err.splitlines() == ["terminated: saved nothing; lost the computation in progress; "
                                "no partial result written; r.nc untouched, noext.png not written"]
    assert io.load_dataset(tmp_path / "r.nc").attrs["run"] == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.nc"]


def test_a_second_sigterm_while_the_first_unwinds_changes_nothing(tmp_path):
    """A newcomer's ``timeout 30`` (with its harness) sent SIGTERM twice: the second one, raised
    while the first was being reported, ended in a traceback. Now it is ignored: one line,
    exit 143."""
    driver = DRIVER.format(stage="simulate", argv=["simulate", "-o", "r.nc"]).replace(
        "from nonsmooth.cli import main\n",
        "import nonsmooth.cli as cli\nslow = cli.interrupted_message\n"
        "def report(code):\n    print('unwinding', flush=True)\n    sys.stdin.readline()\n"
        "    return slow(code)\ncli.interrupted_message = report\nmain = cli.main\n")
    proc = popen([sys.executable, "-c", driver], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                 stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    try:
        assert proc.stdout.readline().strip() == "ready"
        proc.send_signal(signal.SIGTERM)
        assert proc.stdout.readline().strip() == "unwinding"
        proc.send_signal(signal.SIGTERM)  # while the report waits for its go on stdin
        out, err = proc.communicate(input="go\n", timeout=SAFETY_S)
    finally:
        proc.kill()
    assert proc.returncode == 143, err
    assert err.splitlines() == ["terminated: saved nothing; lost the computation in progress; "
                                "no partial result written; r.nc not written"]


def _cli(*args, cwd=None, **env):
    return subprocess.run([sys.executable, "-m", "nonsmooth.cli", *args], capture_output=True,
                          text=True, cwd=cwd, timeout=300, env={**os.environ, **env})


def test_numerical_failure_has_its_own_exit_code(tmp_path):
    # the exact solver at the undamped resonance: exit 3 (not the usage error's 2), and the
    # message says what happened and what to do (before: "event location failed", exit 2)
    r = _cli("simulate", "--method", "exact", "--set", "xi=0", "--set", "omega=4.5",
             "--periods", "1", "-o", "r.nc", cwd=tmp_path)
    assert r.returncode == 3, r.stderr
    lines = r.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: simulate:")
    assert "resonance" in lines[0] and 'method="smooth"' in lines[0]
    assert not (tmp_path / "r.nc").exists()


def test_unknown_figure_format_fails_before_computing(tmp_path):
    r = _cli("simulate", "--periods", "1", "-o", "r.nc", "--plot", "a.xyz", cwd=tmp_path)
    assert r.returncode == 2
    lines = r.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: plot: unknown figure format 'xyz'")
    assert list(tmp_path.iterdir()) == []  # before the fix: r.nc was computed and written


def test_plot_without_suffix_prints_the_file_written(tmp_path):
    r = _cli("simulate", "--periods", "1", "--samples-per-period", "10", "--plot", "noext",
             cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[-1] == "wrote noext.png"  # before: "wrote noext"
    assert (tmp_path / "noext.png").read_bytes()[:4] == b"\x89PNG"


NOTICE = "compiling numba kernels (first run only, three to five minutes)..."


def test_first_run_compilation_is_announced_once(tmp_path):
    import nonsmooth.kernels  # noqa: F401  (today's kernels are in the user's cache)
    code = ("from nonsmooth import _numba_cache, cli\n"
            "_numba_cache.compile_notice = cli._compile_notice\n"
            "import nonsmooth.integrate, nonsmooth.models, nonsmooth.analysis")
    run = lambda **env: subprocess.run(  # noqa: E731
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
        env={**os.environ, **env})
    cold = dict(NUMBA_CACHE_DIR=str(tmp_path / "numba"), XDG_CACHE_HOME=str(tmp_path / "xdg"))
    assert run(NONSMOOTH_PROGRESS="1", **cold).stderr.splitlines() == [NOTICE]
    assert run(NONSMOOTH_PROGRESS="1").stderr == ""  # warm cache: nothing
    assert run(NONSMOOTH_PROGRESS="0", **cold).stderr == ""  # not a terminal: nothing
