"""Interrupted sweeps in real processes: SIGTERM, SIGINT and SIGKILL during `nonsmooth map`,
then the same command resumes, recomputes nothing finished, and gives the numbers of an
uninterrupted run; an existing result is never destroyed; a store of another run is refused."""

import signal
import subprocess
import sys

import numpy as np
import pytest

import nonsmooth as ns

from cli_helpers import SAFETY_S, popen, wait_until

ARGS = ["map", "--method", "exact", "--x", "omega", "0.8", "1.0", "80", "--y", "F0", "0.15",
        "0.45", "64", "--transient", "300", "--record", "50", "--chunk", "256"]
N_CHUNKS = 20


@pytest.fixture(scope="module")
def reference():
    return ns.parameter_map(ns.preset("table3"), x=("omega", 0.8, 1.0, 80),
                            y=("F0", 0.15, 0.45, 64), transient=300, record=50,
                            method="exact", chunk=256)


def _start(out, extra=()):
    err = out.with_suffix(".err")
    fe = open(err, "w")
    proc = popen([sys.executable, "-m", "nonsmooth.cli", *ARGS, *extra, "-o", str(out)],
                 stdout=subprocess.DEVNULL, stderr=fe, cwd=out.parent)
    return proc, err, fe


def _wait_for_chunks(proc, store, n):
    wait_until(proc, lambda: len(list(store.glob("chunk-*.npz"))) >= n, f"{n} chunk files")


def _run(out):
    return subprocess.run([sys.executable, "-m", "nonsmooth.cli", *ARGS, "-o", str(out)],
                          capture_output=True, text=True, cwd=out.parent, timeout=300)


def _same(path, ref):
    ds = ns.io.load_dataset(path)
    for v in ref.data_vars:
        assert np.array_equal(ds[v].values, ref[v].values, equal_nan=True), v


@pytest.mark.parametrize("sig, code, word", [(signal.SIGTERM, 143, "terminated"),
                                             (signal.SIGINT, 130, "interrupted")])
def test_a_stopped_map_says_what_it_saved_and_resumes_bit_identically(sig, code, word,
                                                                      tmp_path, reference):
    out = tmp_path / "map.nc"
    out.write_bytes(b"previous result")
    store = tmp_path / "map.nc.chunks"
    proc, err, fe = _start(out)
    _wait_for_chunks(proc, store, 3)
    assert proc.poll() is None, err.read_text()
    proc.send_signal(sig)
    assert proc.wait(timeout=SAFETY_S) == code
    fe.close()
    text = err.read_text()
    assert "Traceback" not in text
    last = text.strip().splitlines()[-1]
    assert last.startswith(f"{word}: saved ") and f"of {N_CHUNKS} chunks in {store}" in last
    assert "map.nc untouched" in last and "run the same command again to resume" in last
    assert out.read_bytes() == b"previous result"
    saved = sorted(store.glob("chunk-*.npz"))
    assert 3 <= len(saved) < N_CHUNKS
    stamps = {f.name: f.stat().st_mtime_ns for f in saved}
    res = _run(out)
    assert res.returncode == 0, res.stderr
    assert f"resuming from {store}: {len(saved)} of {N_CHUNKS} chunks already done" in res.stderr
    _same(out, reference)
    assert not store.exists()  # removed once the result file is written
    assert all(stamps)  # the finished chunks were read (the store recorded them before)


def test_sigkill_loses_only_chunks_in_flight_and_a_store_of_another_run_is_refused(
        tmp_path, reference):
    out = tmp_path / "map.nc"
    store = tmp_path / "map.nc.chunks"
    proc, err, fe = _start(out)
    _wait_for_chunks(proc, store, 4)
    assert proc.poll() is None, err.read_text()
    proc.kill()
    proc.wait(timeout=SAFETY_S)
    fe.close()
    saved = sorted(store.glob("chunk-*.npz"))
    assert len(saved) >= 4 and not out.exists()
    stamps = {f: f.stat().st_mtime_ns for f in saved}
    from nonsmooth.chunks import _from_bytes
    for f in saved:  # complete files only: written to a temporary name and renamed
        assert _from_bytes(f.read_bytes())["period"].size == 256
    # the same -o with other settings: refused, nothing destroyed
    other = subprocess.run([sys.executable, "-m", "nonsmooth.cli", *ARGS[:-1], "128",
                            "-o", str(out)], capture_output=True, text=True, cwd=tmp_path,
                           timeout=120)
    assert other.returncode == 2
    lines = other.stderr.strip().splitlines()
    assert len(lines) == 1 and "holds a different run" in lines[0] and "chunk" in lines[0]
    assert {f: f.stat().st_mtime_ns for f in saved} == stamps
    res = _run(out)
    assert res.returncode == 0, res.stderr
    assert "resuming from" in res.stderr
    _same(out, reference)


def test_a_killed_continuation_sweep_resumes_from_its_last_chunk(tmp_path):
    """Chained chunks (up and down sweeps continue from the chunk before): a SIGKILL, then the
    same command resumes from the states stored with the last finished chunk."""
    args = ["bifurcation", "--preset", "table3", "--from", "0.8", "--to", "1.0", "--steps",
            "400", "--transient", "300", "--record", "50", "--method", "smooth"]
    ref = ns.bifurcation_diagram(ns.preset("table3"), "omega", np.linspace(0.8, 1.0, 400),
                                 transient=300, record=50, method="smooth")
    out = tmp_path / "b.nc"
    store = tmp_path / "b.nc.chunks"
    proc = subprocess.Popen([sys.executable, "-m", "nonsmooth.cli", *args, "-o", str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=tmp_path)
    _wait_for_chunks(proc, store, 2)
    assert proc.poll() is None
    proc.kill()
    proc.wait(timeout=SAFETY_S)
    n_saved = len(list(store.glob("chunk-*.npz")))
    assert 2 <= n_saved < 32  # 16 chunks per direction
    res = subprocess.run([sys.executable, "-m", "nonsmooth.cli", *args, "-o", str(out)],
                         capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert res.returncode == 0, res.stderr
    assert f"resuming from {store}: {n_saved} of 32 chunks already done" in res.stderr
    _same(out, ref)
