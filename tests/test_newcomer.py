"""What a newcomer trips over (issue 24): sizes typed too large are refused in one line with the
largest size that fits, ``progress`` takes True/False/None/a callable everywhere, and
``--set eta=0`` is accepted with ``--method exact`` (the exact model has no band)."""

import numpy as np
import pytest

import nonsmooth as ns
from nonsmooth.errors import ParameterError

from cli_helpers import one_line, run_cli

HUGE = "100000000000"


@pytest.mark.parametrize("argv,field", [
    (["bifurcation", "--preset", "table3", "--param", "omega", "--from", "0.8", "--to", "1.0",
      "--steps", HUGE, "-o", "{out}"], "steps"),
    (["resonance", "--preset", "fig6a", "--from", "0.5", "--to", "1.6", "--steps", HUGE,
      "-o", "{out}"], "steps"),
    (["simulate", "--preset", "table1", "--periods", HUGE, "-o", "{out}"], "periods"),
    (["poincare", "--preset", "table3", "--record", HUGE, "-o", "{out}"], "record"),
    (["basins", "--preset", "fig7", "--grid", "10000000", "-o", "{out}"], "grid"),
    (["map", "--x", "omega", "0.8", "1.0", "1000000", "--y", "F0", "0.1", "0.4", "1000000",
      "-o", "{out}"], "x n"),
    (["lyapunov", "--preset", "table3", "--periods", HUGE, "-o", "{out}"], "periods"),
    (["orbit", "--preset", "fig7", "--k", HUGE, "-o", "{out}"], "k"),
    (["eta-study", "--preset", "fig4", "--eta", "0.01", "--record", HUGE, "-o", "{out}"],
     "record"),
])
def test_sizes_that_do_not_fit_are_refused_in_one_line_with_the_largest_that_fits(
        argv, field, capsys, tmp_path):
    out = tmp_path / "r.nc"
    code, _, err = run_cli([a.format(out=out) for a in argv], capsys)
    assert code == 2
    one_line(err, f"{field}:")
    assert "of memory" in err and "available" in err
    if field != "record" or argv[0] != "eta-study":
        assert "at most" in err and "fits" in err
    assert not out.exists()


def test_python_api_sizes_are_checked_too():
    with pytest.raises(ParameterError, match=r"^samples_per_period: .* at most samples_per_"):
        ns.periodic_orbit(ns.preset("fig7"), samples_per_period=10**11)
    with pytest.raises(ParameterError, match=r"^periods: .* at most periods = "):
        ns.lyapunov(ns.preset("table3"), periods=10**12)


def test_the_largest_size_named_fits(monkeypatch):
    """The size the line names is accepted by the same check (with the same memory available:
    other processes, the suite's own workers among them, change it between two reads)."""
    from nonsmooth import io
    from nonsmooth.analysis.bifurcation import check_sweep_memory
    monkeypatch.setattr(io, "available_memory", lambda: 16 * 2**30)
    with pytest.raises(ParameterError) as exc:
        check_sweep_memory(10**11, 2, 200, "steps")
    largest = int(str(exc.value).split("at most steps = ")[1].split(" ")[0].replace(",", ""))
    assert 1000 < largest < 10**11
    check_sweep_memory(largest, 2, 200, "steps")


@pytest.mark.parametrize("progress", [False, None, True])
def test_progress_accepts_booleans_and_none(progress):
    p = ns.preset("table3")
    bif = ns.bifurcation_diagram(p, "omega", np.linspace(0.9, 0.92, 3), transient=10, record=4,
                                 method="exact", progress=progress, lyapunov=False)
    assert bif.sizes["omega"] == 3
    ds = ns.simulate(p, periods=2, method="exact", progress=progress)
    assert ds.sizes["t"] > 2


def test_progress_callable_is_called_and_a_wrong_type_is_one_line():
    calls = []
    ns.simulate(ns.preset("table3"), periods=3, method="exact",
                progress=lambda d, t: calls.append((d, t)))
    assert calls and calls[-1][0] == calls[-1][1]
    for f in (lambda: ns.simulate(ns.preset("table3"), periods=2, progress="yes"),
              lambda: ns.poincare(ns.preset("table3"), record=2, transient=0, progress=3),
              lambda: ns.parameter_map(ns.preset("table3"), x=("omega", 0.9, 0.92, 2),
                                       y=("F0", 0.3, 0.31, 2), progress=1.5)):
        with pytest.raises(ParameterError, match=r"^progress: expected True, False, None or a "):
            f()


def test_eta_zero_is_accepted_for_the_exact_method(capsys, tmp_path):
    out = tmp_path / "ex.nc"
    code, stdout, err = run_cli(["simulate", "--preset", "table3", "--set", "eta=0",
                                 "--set", "omega=0.92", "--method", "exact", "--periods", "2",
                                 "-o", str(out)], capsys)
    assert code == 0, err
    ds = ns.io.load_dataset(out)
    ref = ns.simulate(ns.preset("table3").replace(omega=0.92), periods=2, method="exact")
    assert np.array_equal(ds.X.values, ref.X.values)
    # the file says that the eta it carries (the preset's) is not read by the exact method
    assert ds.attrs["unused_parameters"] == "eta"
    assert "unused_parameters" not in ns.simulate(ns.preset("table3"), periods=1).attrs
    # and that its rtol, atol (recorded as asked) are not read either: its closed form is
    # exact to round-off, event times located to 2e-14 max(1, T)
    assert "rtol and atol are not used" in ds.attrs["integrator"]
    assert "not used" not in ns.simulate(ns.preset("table3"), periods=1).attrs["integrator"]
    # still refused for the smoothed model, and not a number is still an error
    code, _, err = run_cli(["simulate", "--preset", "table3", "--set", "eta=0", "--periods", "2",
                            "-o", str(tmp_path / "s.nc")], capsys)
    assert code == 2
    one_line(err, "eta:")
    code, _, err = run_cli(["simulate", "--preset", "table3", "--set", "eta=x", "--method",
                            "exact", "--periods", "2", "-o", str(tmp_path / "s.nc")], capsys)
    assert code == 2
    one_line(err, "eta: expected a number")
    code, stdout, err = run_cli(["simulate", "--help"], capsys)
    assert "ignored" in " ".join(stdout.split())


def _in_a_fresh_process(cases, cwd):
    """[exit code, nonsmooth.kernels imported by then, stderr] of ``nonsmooth ARGV`` for each
    argv of ``cases``, run one after the other in one fresh Python process."""
    import json
    import subprocess
    import sys
    code = ("import sys, json, io, contextlib\nfrom nonsmooth.cli import main\nout = []\n"
            f"for argv in {list(cases)!r}:\n"
            "    err = io.StringIO()\n"
            "    with contextlib.redirect_stderr(err):\n"
            "        try:\n            main(argv)\n            c = 0\n"
            "        except SystemExit as e:\n            c = e.code\n"
            "    out.append([c, 'nonsmooth.kernels' in sys.modules, err.getvalue()])\n"
            "print(json.dumps(out))\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=cwd,
                       timeout=300)
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_bad_options_are_refused_before_the_kernels_load(tmp_path):
    """A newcomer on a fresh machine waited 4-9 minutes (the kernels' first compile) for the
    one line refusing `--periods -5`, an unwritable `-o`, a reversed range, ...: the commands
    imported their analysis, and with it the kernels, before checking their own options. Now
    those are checked first: none of these imports ``nonsmooth.kernels`` (one fresh process)."""
    bad = tmp_path / "missing" / "x.nc"
    cases = [
        ["simulate", "--periods", "-5", "-o", "a.nc"],
        ["simulate", "-o", "x.png"],
        ["simulate"],
        ["simulate", "--method", "rk4", "-o", "a.nc"],
        ["simulate", "--plot", str(tmp_path / "missing" / "p.png")],
        ["poincare", "--record", "0", "-o", "a.nc"],
        ["poincare", "-o", str(bad)],
        ["bifurcation", "--from", "1.0", "--to", "0.9", "-o", "a.nc"],
        ["bifurcation", "--steps", "0", "-o", "a.nc"],
        ["bifurcation", "--sweep", "sideways", "-o", "a.nc"],
        ["resonance", "--from", "1.0", "--to", "0.9", "-o", "a.nc"],
        ["basins", "-o", str(bad)],
        ["attractors", "--from", "1.2", "--to", "1.1", "-o", "a.nc"],
        ["map", "-o", str(bad)],
    ]
    got = _in_a_fresh_process(cases, tmp_path)
    assert [c for c, _, _ in got] == [2] * len(cases), got
    assert [ln for ln in got[0][2].splitlines() if ln.strip()][0].startswith("error: periods:")
    assert not got[-1][1], "a command imported the kernels before refusing a bad option"


def test_every_command_refuses_bad_options_before_the_kernels_load(tmp_path):
    """The same for the commands the first fix left: lyapunov, orbit, continue (its two-
    parameter and extended forms), manifolds, eta-study, limit-cycle, equilibria and
    surface-bifurcation; the grids, windows, axes and map axes of basins, attractors and map;
    and the tolerances and section phase of every command (checked by ``kernels.Solver``
    before, now by the light ``checks.check_solver_options`` it calls)."""
    bad = str(tmp_path / "missing" / "x.nc")
    sb = ["surface-bifurcation", "--param", "v_belt", "--from", "0.1", "--to", "0.2"]
    cases = [
        (["lyapunov", "--blocks", "1"], "blocks: must be >= 2"),
        (["lyapunov", "--rtol", "2"], "rtol: must satisfy 0 < rtol < 1"),
        (["orbit", "--tol", "-1"], "tol: must be > 0"),
        (["orbit", "--show", "X,Q"], "show: unknown component 'Q'"),
        (["orbit", "--atol", "0"], "atol: must satisfy"),
        (["continue", "--param", "omega", "--step", "-1"], "step: must be > 0"),
        (["continue", "--param", "omega", "-o", bad], "output: cannot write"),
        (["continue", "--param", "omega", "--two-param", "F0", "--values", "0.1", "0.2", "1"],
         "values: N must be >= 2"),
        (["continue", "--param", "omega", "--two-param", "F0", "--extended", "sideways"],
         "extended: expected 'up' or 'down'"),
        (["continue", "--model", "stick_slip", "--param", "v_belt", "--section", "V +"],
         "section: cannot read 'V +'"),
        (["manifolds", "--point", "1"], "point: a period-1 orbit has section points 0 ... 0"),
        (["manifolds", "--axes", "X,X"], "axes: two different components"),
        (["manifolds", "--x", "1", "0"], "x: expected finite low < high"),
        (["eta-study", "--eta", "0.7", "-o", "a.nc"], "eta: every value must satisfy"),
        (["eta-study", "--eta", "0.1", "--record", "0", "-o", "a.nc"], "record: must be >= 2"),
        (["limit-cycle", "--transient", "0"], "transient: must be >= 1"),
        (["limit-cycle", "--direction", "sideways"], "section: direction must be one of"),
        (["limit-cycle", "--section", "Q + 1"], "section: unknown name(s) Q"),
        (["limit-cycle", "--set", "F0=0.5"], "limit_cycle: the system is forced"),
        (["equilibria", "-o", bad], "output: cannot write"),
        (["equilibria", "--param", "v_belt", "--from", "1", "--to", "1"], "from/to: empty"),
        (sb + ["--crossings", "0"], "crossings: must be >= 2"),
        (sb + ["--section", "X +* 1"], "section: cannot read"),
        (["simulate", "--rtol", "0", "-o", "a.nc"], "rtol: must satisfy"),
        (["poincare", "--section-phase", "7", "-o", "a.nc"], "section_phase: must satisfy"),
        (["map", "--atol", "2", "-o", "a.nc"], "atol: must satisfy"),
        # a newcomer's fresh machine: these waited for the compile (basins --grid 1: 360 s),
        # and attractors left its a.nc.chunks behind
        (["basins", "--grid", "1", "-o", "a.nc"], "grid: must be >= 2"),
        (["basins", "--x", "3", "-3", "-o", "a.nc"], "x: empty or reversed range"),
        (["basins", "--axes", "X,Q", "-o", "a.nc"], "axes: unknown component 'Q'"),
        (["map", "--x", "omega", "1.0", "0.8", "10", "-o", "a.nc"], "x: empty or reversed"),
        (["map", "--x", "omega", "0.8", "1.0", "0", "-o", "a.nc"], "x n: must be >= 1"),
        (["map", "--start", "sideways", "-o", "a.nc"], "start: expected one of"),
        (["attractors", "--grid", "0", "-o", "a.nc"], "grid: must be >= 2"),
        (["attractors", "--v", "1", "1", "-o", "a.nc"], "v: empty or reversed range"),
        # a newcomer: the error named --from / --to, which this command does not have
        (["continue", "--param", "omega", "--two-param", "omega_s", "--values", "7", "3", "5",
          "--special", "fold"], "values: empty or reversed omega_s values: FROM 7 must be < TO 3"),
        (["bifurcation", "--workers", "-3", "-o", "a.nc"],
         "workers: must be a positive integer (0: all cores), got -3"),
    ]
    got = _in_a_fresh_process([argv for argv, _ in cases], tmp_path)
    for (argv, msg), (c, loaded, err) in zip(cases, got):
        lines = [ln for ln in err.splitlines() if ln.strip()]
        assert c == 2 and len(lines) == 1 and lines[0].startswith("error: ") and msg in lines[0], \
            (argv, c, err)
        assert not loaded, f"{argv} imported the kernels before refusing a bad option"
    assert not (tmp_path / "a.nc.chunks").exists()


def test_a_sweep_refused_inside_its_chunks_leaves_no_store(tmp_path, capsys, monkeypatch):
    """A newcomer's refused ``attractors --grid 0 -o a.nc`` left ``a.nc.chunks/`` (a lock and
    a manifest) behind: its basins refused the grid inside the sweep's first chunk. The CLI
    now checks the grid first; and a refusal that still comes from inside a chunk removes a
    store with no finished chunk."""
    import nonsmooth.analysis.basins as basins_module

    def refuse(*args, **kwargs):
        raise ParameterError("grid: refused inside the chunk")

    monkeypatch.setattr(basins_module, "basins", refuse)
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(["attractors", "--steps", "2", "--grid", "2", "--workers", "1",
                              "-o", "a.nc"], capsys)
    assert code == 2
    one_line(err, "grid: refused inside the chunk")
    assert sorted(p.name for p in tmp_path.iterdir()) == []
