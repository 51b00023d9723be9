"""Chunked, resumable sweeps (nonsmooth.chunks): the store, resumption bit for bit, refusal of a
store of another run, and the two-parameter map against the bifurcation sweeps it generalises."""

import os

import numpy as np
import pytest

import nonsmooth as ns
from nonsmooth.chunks import ChunkStore, Plan, _from_bytes, _to_bytes, check_engine, execute
from nonsmooth.errors import OutputError, ParameterError

P3 = ns.preset("table3")
MAP = dict(x=("omega", 0.85, 0.95, 12), y=("F0", 0.25, 0.35, 5), transient=150, record=40,
           method="exact")


def _equal(a, b):
    assert set(a.data_vars) == set(b.data_vars)
    for v in a.data_vars:
        x, y = a[v].values, b[v].values
        assert x.dtype == y.dtype, v
        assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), v


def _square(spec, i, carry, workers=None, progress=None):
    c = 0 if carry is None else int(carry[0])
    return {"y": np.arange(spec["n"]) * i + c, "carry": np.array([c + i])}


def test_chunk_files_keep_every_bit_and_python_state():
    r = {"x": np.random.default_rng(1).random(50), "k": np.arange(5, dtype=np.int8),
         "b": np.ones(2, bool), "carry": {"found": [np.pi, 1e-300]}}
    back = _from_bytes(_to_bytes(r))
    for k in ("x", "k", "b"):
        assert back[k].dtype == r[k].dtype and np.array_equal(back[k], r[k])
    assert back["carry"] == r["carry"]


def test_store_resumes_a_chained_plan_and_refuses_another_run(tmp_path):
    plan = Plan("demo", {"n": 3}, 4, _square, {"n": 3}, chained=True)
    got = {}
    execute(plan, got.__setitem__, store=tmp_path / "s")
    assert sorted(got) == [0, 1, 2, 3] and list(got[3]["y"]) == [3, 6, 9]
    files = sorted((tmp_path / "s").glob("chunk-*.npz"))
    assert len(files) == 4
    stamp = files[0].stat().st_mtime_ns
    files[-1].unlink()  # as if killed during the last chunk
    again = {}
    execute(plan, again.__setitem__, store=tmp_path / "s")
    assert all(np.array_equal(again[i]["y"], got[i]["y"]) for i in got)
    assert files[0].stat().st_mtime_ns == stamp  # read, not recomputed
    other = Plan("demo", {"n": 4}, 4, _square, {"n": 4}, chained=True)
    with pytest.raises(ParameterError, match="holds a different run.*n: stored 3, now 4"):
        execute(other, lambda i, r: None, store=tmp_path / "s")
    assert len(list((tmp_path / "s").glob("chunk-*.npz"))) == 4  # nothing destroyed
    (tmp_path / "junk").mkdir()
    (tmp_path / "junk" / "x.txt").write_text("mine")
    with pytest.raises(OutputError, match="not a chunk store"):
        ChunkStore(tmp_path / "junk", plan)


def test_a_store_is_locked_while_used_and_a_corrupt_chunk_is_one_line(tmp_path):
    plan = Plan("demo", {"n": 3}, 2, _square, {"n": 3})
    first = ChunkStore(tmp_path / "s", plan)
    with pytest.raises(ParameterError, match="in use by another run"):
        ChunkStore(tmp_path / "s", plan)
    first.close()
    execute(plan, lambda i, r: None, store=tmp_path / "s")
    (tmp_path / "s" / "chunk-000001.npz").write_bytes(b"PK\x03\x04 truncated")
    with pytest.raises(OutputError, match="chunk-000001.npz.*unreadable.*delete it") as exc:
        execute(plan, lambda i, r: None, store=tmp_path / "s")
    assert "\n" not in str(exc.value)
    # a store with no finished chunk is simply replaced by another run
    other = Plan("demo", {"n": 5}, 2, _square, {"n": 5})
    for f in (tmp_path / "s").glob("chunk-*"):
        f.unlink()
    execute(other, lambda i, r: None, store=tmp_path / "s")


def test_a_resumed_map_is_bit_identical_and_recomputes_nothing_finished(tmp_path):
    ref = ns.parameter_map(P3, **MAP)
    store = tmp_path / "map.chunks"
    a = ns.parameter_map(P3, store=store, chunk=13, **MAP)
    _equal(a, ref)
    files = sorted(store.glob("chunk-*.npz"))
    assert len(files) == 5  # 60 points in chunks of 13
    for f in files[2:]:
        f.unlink()
    stamps = [f.stat().st_mtime_ns for f in files[:2]]
    b = ns.parameter_map(P3, store=store, chunk=13, **MAP)
    _equal(b, ref)
    assert [f.stat().st_mtime_ns for f in files[:2]] == stamps
    with pytest.raises(ParameterError, match="different run.*transient: stored 150, now 151"):
        ns.parameter_map(P3, store=store, chunk=13, **{**MAP, "transient": 151})
    with pytest.raises(ParameterError, match=r"params\.xi: stored 0\.05, now 0\.06"):
        ns.parameter_map(P3.replace(xi=0.06), store=store, chunk=13, **MAP)
    with pytest.raises(ParameterError, match=r"ys\[1\]: stored 0\.275, now 0\.2774"):
        ns.parameter_map(P3, store=store, chunk=13, **{**MAP, "y": ("F0", 0.25, 0.36, 5)})


@pytest.mark.parametrize("analysis", ["bifurcation", "basins", "eta_study", "resonance",
                                      "attractor_continuation"])
def test_every_sweep_resumes_bit_identically(analysis, tmp_path):
    calls = {
        "bifurcation": lambda **kw: ns.bifurcation_diagram(
            P3, "omega", np.linspace(0.85, 0.95, 60), transient=100, record=30,
            method="exact", **kw),
        "basins": lambda **kw: ns.basins(ns.preset("fig7"), grid=30, method="exact",
                                         max_periods=200, lyapunov=False, **kw),
        "eta_study": lambda **kw: ns.eta_study(ns.preset("fig4"), [1e-2, 1e-3], transient=50,
                                               record=20, orbit_periods=1, **kw),
        "resonance": lambda **kw: ns.resonance_curve(ns.preset("table1"),
                                                     np.linspace(0.6, 1.4, 60),
                                                     method="exact", transient=60, record=10,
                                                     **kw),
        "attractor_continuation": lambda **kw: ns.attractor_continuation(
            ns.preset("fig7"), "omega", [1.08, 1.12, 1.16], grid=12, method="exact", **kw),
    }
    ref = calls[analysis]()
    store = tmp_path / "s"
    first = calls[analysis](store=store)
    files = sorted(store.glob("chunk-*.npz"))
    assert len(files) >= 2
    files[-1].unlink()
    resumed = calls[analysis](store=store)
    for ds in (first, resumed):
        _equal(ds, ref)
        assert {k: str(v) for k, v in ds.attrs.items()} == {k: str(v) for k, v in ref.attrs.items()}


def test_map_rows_continued_along_x_are_the_up_sweeps():
    xs = ("omega", 0.88, 0.93, 9)
    m = ns.parameter_map(P3, x=xs, y=("F0", 0.28, 0.32, 3), transient=120, record=30,
                         method="exact", start="continued", lyapunov=False)
    for j, f0 in enumerate(m.F0.values):
        bd = ns.bifurcation_diagram(P3.replace(F0=float(f0)), "omega", np.linspace(*xs[1:]),
                                    sweep="up", transient=120, record=30, method="exact",
                                    lyapunov=False)
        for v in ("period", "max_X", "min_X", "contact", "status"):
            assert np.array_equal(m[v].values[j], bd[v].values[0].astype(m[v].dtype)), v


def test_map_fresh_points_are_the_fresh_sweep_with_floquet_lambda1_on_periodic_points():
    m = ns.parameter_map(P3, x=("omega", 0.9, 0.95, 6), y=("F0", 0.3, 0.3, 1), transient=150,
                         record=40, method="exact")
    bd = ns.bifurcation_diagram(P3.replace(F0=0.3), "omega", np.linspace(0.9, 0.95, 6),
                                sweep="fresh", transient=150, record=40, method="exact")
    for v in ("period", "max_X", "motion"):
        assert np.array_equal(m[v].values[0], bd[v].values[0].astype(m[v].dtype)), v
    per = m.period.values[0]
    assert (per > 0).any() and (per == 0).any()
    rest = per <= 0  # Benettin over `record` periods, as in the bifurcation diagram
    for v in ("lambda1", "lambda1_stderr"):
        assert np.array_equal(m[v].values[0][rest], bd[v].values[0][rest], equal_nan=True), v
    # periodic points: ln|mu_1| / (p T) of the leading Floquet multiplier, checked against the
    # multipliers of the orbit found independently by Newton shooting
    for i in np.flatnonzero(per > 0):
        w = float(m.omega[i])
        orb = ns.periodic_orbit(P3.replace(F0=0.3, omega=w), k=int(per[i]),
                                x0=float(bd.X[0, i, -1]), v0=float(bd.V[0, i, -1]),
                                method="exact")
        assert orb.attrs["status"] == "converged"
        mu = float(orb.multiplier_abs.max())
        expect = np.log(mu) / (per[i] * 2 * np.pi / w)
        assert float(m.lambda1[0, i]) == pytest.approx(expect, rel=1e-4, abs=1e-7)
        assert float(m.lambda1_stderr[0, i]) == 0.0
    assert m.attrs["x_param"] == "omega" and "param_omega" not in m.attrs
    assert "param_F0" not in m.attrs and m.attrs["param_xi"] == P3.xi


@pytest.mark.parametrize("kw, field", [
    (dict(x=("omega", 1.0, 0.8, 10)), "x: empty or reversed"),
    (dict(x=("omega", 0.9, 0.9, 3)), "x: empty or reversed"),
    (dict(y=("F0", 0.1, 0.2, 0)), "y n: must be"),
    (dict(x=("bogus", 0.1, 0.2, 3)), "bogus"),
    (dict(y=("omega", 0.1, 0.2, 3)), "y: the two axes"),
    (dict(x=("omega", 0.8, float("nan"), 3)), "x max"),
    (dict(start="sideways"), "start:"),
    (dict(engine="two words"), "dask:"),
    (dict(engine="local:0"), "dask: local:N"),
    (dict(chunk=0), "chunk:"),
])
def test_map_bad_input_is_one_line_naming_the_field(kw, field):
    with pytest.raises(ParameterError, match=field.replace("(", r"\(")) as exc:
        ns.parameter_map(P3, **{**dict(x=("omega", 0.8, 1.0, 3), y=("F0", 0.2, 0.3, 2)), **kw})
    assert "\n" not in str(exc.value)


def test_engine_names_are_checked_before_anything_starts():
    assert check_engine(None) is None and check_engine("embedded") is None
    assert check_engine("local:3") == "local:3"
    assert check_engine("tcp://10.0.0.1:8786") == "tcp://10.0.0.1:8786"
    with pytest.raises(ParameterError):
        check_engine(3.5)


def test_plots_of_a_map(tmp_path):
    from nonsmooth.analysis.parameter_map import regimes
    from nonsmooth.io import save_figure
    from nonsmooth.plot import plot_lambda1_map, plot_parameter_map
    m = ns.parameter_map(P3, **MAP)
    code, names = regimes(m)
    per = m.period.values
    assert np.all(code[per == 1] == names.index("period 1"))
    chaotic = (per == 0) & (m.motion.values == 3)
    assert np.all(code[chaotic] == names.index("chaotic"))
    fig = plot_parameter_map(m)
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any(t.startswith("period 1 (") for t in labels)
    shares = [t.rsplit("(", 1)[1].rstrip("%)") for t in labels]
    assert sum(float(x) for x in shares if not x.startswith("<")) == pytest.approx(100, abs=0.5)
    save_figure(fig, tmp_path / "m.png")
    save_figure(plot_lambda1_map(m), tmp_path / "l.png")
    assert os.path.getsize(tmp_path / "m.png") > 1000


def test_signals_during_a_compiled_call_are_delivered_after_it():
    import signal as sg
    from nonsmooth.sweep import deferred_interrupts
    inside = []
    # Python's own handler, as in the CLI (a run started as a background job inherits SIGINT
    # ignored: there is then nothing to hold or deliver)
    before = sg.signal(sg.SIGINT, sg.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            with deferred_interrupts():
                os.kill(os.getpid(), sg.SIGINT)
                inside.append("still running")  # held: the block ends normally first
        assert inside == ["still running"]
        assert sg.getsignal(sg.SIGINT) is sg.default_int_handler
    finally:
        sg.signal(sg.SIGINT, before)


def test_a_store_of_another_version_of_a_model_file_is_refused(tmp_path):
    """A sweep's chunks computed with a user's model file are not reused once the file has
    changed (its contents are part of the run's fingerprint; before, only its path was)."""
    from pathlib import Path
    src = Path(__file__).resolve().parents[1] / "examples" / "one_sided_duffing.py"
    path = tmp_path / "model.py"
    path.write_text(src.read_text())
    m = ns.model(f"{path}:MODEL")
    run = lambda: ns.bifurcation_diagram(m.params(), "omega", [0.9, 1.0, 1.1], method="exact",  # noqa: E731
                                         transient=5, record=5, lyapunov=False,
                                         store=tmp_path / "s")
    first = run()
    again = run()  # the same file: every chunk read back
    _equal(first, again)
    path.write_text(src.read_text() + "\n# edited\n")
    with pytest.raises(ParameterError, match=r"different run.*model_digest"):
        run()
