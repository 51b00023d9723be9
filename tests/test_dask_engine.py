"""The Dask engine: a LocalCluster of worker processes gives the embedded engine's numbers bit
for bit, survives a worker killed mid-run, and an unreachable scheduler is one line."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import nonsmooth as ns
from cli_helpers import SAFETY_S, one_line, run_cli

distributed = pytest.importorskip("distributed")

P3 = ns.preset("table3")


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def _equal(a, b):
    for v in a.data_vars:
        assert np.array_equal(a[v].values, b[v].values, equal_nan=True), v


@pytest.mark.parametrize("analysis", ["map", "bifurcation", "basins", "attractors"])
def test_dask_results_are_the_embedded_results(analysis, client):
    call = {
        "map": lambda **kw: ns.parameter_map(P3, x=("omega", 0.85, 0.95, 10),
                                             y=("F0", 0.25, 0.35, 6), transient=150,
                                             record=40, method="exact", chunk=9, **kw),
        "bifurcation": lambda **kw: ns.bifurcation_diagram(
            P3, "omega", np.linspace(0.85, 0.95, 60), transient=100, record=30,
            method="exact", **kw),
        "basins": lambda **kw: ns.basins(ns.preset("fig7"), grid=30, method="exact",
                                         max_periods=200, **kw),
        "attractors": lambda **kw: ns.attractor_continuation(
            ns.preset("fig7"), "omega", np.linspace(1.04, 1.2, 4), grid=16, method="exact",
            **kw),
    }[analysis]
    _equal(call(engine=client), call())


def test_a_worker_killed_mid_run_has_its_chunks_retried(client, tmp_path):
    kw = dict(x=("omega", 0.8, 1.0, 40), y=("F0", 0.15, 0.45, 30), transient=300, record=50,
              method="exact", chunk=40)
    ref = ns.parameter_map(P3, **kw)
    store = tmp_path / "s"
    pids = list(client.run(os.getpid).values())
    killed = []

    def killer():
        t_end = time.monotonic() + SAFETY_S
        while time.monotonic() < t_end:
            if len(list(store.glob("chunk-*.npz"))) >= 3:
                os.kill(pids[0], signal.SIGKILL)
                killed.append(pids[0])
                return
            time.sleep(0.01)
    th = threading.Thread(target=killer)
    th.start()
    got = ns.parameter_map(P3, engine=client, store=store, **kw)
    th.join()
    assert killed, "the run ended before a worker could be killed"
    _equal(got, ref)
    assert len(list(store.glob("chunk-*.npz"))) == 30


def test_an_unreachable_scheduler_is_one_line(capsys, tmp_path):
    out = tmp_path / "m.nc"
    code, _, err = run_cli(["map", "--method", "exact", "--x", "omega", "0.8", "1.0", "3",
                            "--y", "F0", "0.2", "0.3", "2", "--dask", "tcp://127.0.0.1:1",
                            "-o", str(out)], capsys)
    assert code == 2
    one_line(err, "dask: cannot reach the scheduler at tcp://127.0.0.1:1")
    assert not out.exists() and not (tmp_path / "m.nc.chunks").exists()


def test_cli_dask_local_gives_the_embedded_file(capsys, tmp_path):
    args = ["map", "--method", "exact", "--x", "omega", "0.88", "0.92", "5", "--y", "F0", "0.28",
            "0.3", "3", "--transient", "100", "--record", "30"]
    code, _, err = run_cli(args + ["--dask", "local:2", "-o", str(tmp_path / "d.nc")], capsys)
    assert code == 0, err
    code, _, err = run_cli(args + ["-o", str(tmp_path / "e.nc")], capsys)
    assert code == 0, err
    _equal(ns.io.load_dataset(tmp_path / "d.nc"), ns.io.load_dataset(tmp_path / "e.nc"))
