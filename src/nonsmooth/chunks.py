"""Chunked, resumable runs (importing this module is cheap: numpy is loaded on first use): a sweep is cut into chunks that are computed by an engine (the
embedded one: numba threads on all local cores; or a Dask distributed cluster) and written, as
each finishes, to a chunk store on disk; the final result is assembled from the chunks.

* **Plan** (what to compute): ``task(spec, i, carry, workers=None, progress=None)`` computes
  chunk ``i`` and returns a dict of numpy arrays (and, for a *chained* plan, a ``"carry"``
  entry handed to chunk ``i + 1``: the state a continuation sweep goes on from). ``task`` is a
  module-level function and ``spec`` plain data, so that both travel to Dask workers; a chunk
  depends only on ``spec``, ``i`` and ``carry``, never on the engine, the number of threads or
  of workers, so every engine gives the same bits.
* **Store** (:class:`ChunkStore`): a directory with ``manifest.json`` (the analysis and the
  fingerprint of its inputs, including the package version and the chunk layout) and one
  ``.npz`` file (numpy's format) per finished chunk, each written to a temporary name and
  renamed (``io.write_file``), so that a
  chunk file is complete or absent: a SIGKILL loses at most the chunks in flight. Opening a
  store of a different run is refused with one line; running the same plan again computes
  only the chunks that are missing, and the resumed result is bit-identical to an
  uninterrupted one (the files keep every bit of the arrays).
* **Engines** (:func:`execute`): ``engine=None`` or ``"embedded"``; ``"local"`` /
  ``"local:N"`` (a Dask LocalCluster of N worker processes, one thread each, started and
  stopped here); a scheduler address (``tcp://host:8786``); or a ``dask.distributed.Client``.
  On Dask every chunk is a task (``retries`` if its worker dies); the client writes the chunk
  files as results arrive, with at most a few chunks in flight per worker thread.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import pickle
import shutil
import threading
import uuid
from pathlib import Path
from typing import Any, Callable

from ._version import __version__
from .errors import NonsmoothError, OutputError, ParameterError

#: Seconds to wait for a Dask scheduler before giving up with one line.
CONNECT_TIMEOUT = 5.0
#: Chunks in flight per Dask worker thread (more hides latency, fewer bounds memory).
IN_FLIGHT_PER_THREAD = 2
#: Times a Dask task that raised is retried. A task whose worker dies is rescheduled by the
#: scheduler itself (up to its ``distributed.scheduler.allowed-failures``, 3 by default);
#: beyond that the run stops with one line saying which chunks are saved.
RETRIES = 3


@dataclasses.dataclass
class Plan:
    """A chunked computation. ``fingerprint``: JSON-able inputs that determine the result
    (a store of another fingerprint is refused); ``weights``: work per chunk (progress).

    ``chained`` (all chunks one chain) or ``chains`` (a chain id per chunk, None for an
    independent chunk): a chunk of a chain starts from the ``carry`` of the chain's previous
    chunk (in index order). Chains are independent of each other: Dask runs them side by
    side. ``stream(spec, todo, carries, emit, workers=None, progress=None)``, optional, runs
    on the embedded engine all the pending chunks of all chains at once (``todo``: chain ->
    chunk indices, ``carries``: chain -> carry) and calls ``emit(i, result)`` as each chunk
    is finished: the chains then never wait for each other at chunk boundaries (each chunk
    must equal what ``task`` gives)."""

    analysis: str
    fingerprint: dict
    n_chunks: int
    task: Callable
    spec: Any
    chained: bool = False
    weights: list | None = None
    chains: list | None = None
    stream: Callable | None = None

    def __post_init__(self):
        if self.chains is None and self.chained:
            self.chains = [0] * self.n_chunks
        self.chained = self.chains is not None and any(c is not None for c in self.chains)

    def chain_of(self, i: int):
        return None if self.chains is None else self.chains[i]

    def manifest(self) -> dict:
        return {"analysis": self.analysis, "nonsmooth_version": __version__,
                "n_chunks": int(self.n_chunks),
                "chains": None if self.chains is None else [
                    None if c is None else int(c) for c in self.chains],
                "fingerprint": _jsonable(self.fingerprint)}


def _jsonable(obj):
    """Plain JSON types; floats as repr strings so that every bit counts in comparisons."""
    import numpy as np
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [_jsonable(v) for v in (obj.tolist() if isinstance(obj, np.ndarray) else obj)]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return repr(float(obj) + 0.0)  # -0.0 and 0.0 are the same input
    return None if obj is None else str(obj)


# ---- the store ----------------------------------------------------------------------------------
class ChunkStore:
    """Finished chunks of one plan in a directory (see the module docstring); a chained plan's
    chunk file also holds its ``carry`` (the state the next chunk goes on from; kept small:
    basins, e.g., carries its attractors, not its per-point data). The store is locked while a
    run uses it: a second run with the same store is refused."""

    def __init__(self, path, plan: Plan):
        self.path = Path(path)
        self.plan = plan
        manifest = plan.manifest()
        mfile = self.path / "manifest.json"
        if self.path.exists() and not self.path.is_dir():
            raise OutputError(f"store: {str(self.path)!r} exists and is not a chunk store")
        old = None
        if mfile.is_file():
            try:
                old = json.loads(mfile.read_text())
            except (OSError, ValueError) as exc:
                raise OutputError(f"store: cannot read {str(mfile)!r}: {exc}") from None
        elif self.path.exists() and any(not p.name.startswith(".") and p.name != "lock"
                                        for p in self.path.iterdir()):
            raise OutputError(f"store: {str(self.path)!r} is not empty and has no "
                              f"manifest.json; not a chunk store of nonsmooth")
        try:
            self.path.mkdir(parents=False, exist_ok=True)
            self._lock = open(self.path / "lock", "w")
        except OSError as exc:
            raise OutputError(f"store: cannot write {str(self.path)!r}: "
                              f"{exc.strerror or exc}") from None
        try:
            import fcntl
            fcntl.flock(self._lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except ImportError:  # not on POSIX: no lock
            pass
        except OSError:
            self._lock.close()
            raise ParameterError(f"store: {str(self.path)!r} is in use by another run "
                                 f"(the same output file); wait for it or use another -o")
        if old is not None and old != manifest:
            if self.done():
                self._lock.close()
                raise ParameterError(f"store: {str(self.path)!r} holds a different run "
                                     f"({_difference(old, manifest)}); use another output "
                                     f"file or store, or delete that directory to start "
                                     f"afresh")
            old = None  # nothing finished there: nothing to lose
        if old is None:
            _atomic_write(mfile, json.dumps(manifest, indent=1, sort_keys=True).encode())

    def chunk_file(self, i: int) -> Path:
        return self.path / f"chunk-{i:06d}.npz"

    def done(self) -> set:
        """Indices of the finished chunks."""
        out = set()
        for p in self.path.glob("chunk-*.npz"):
            with contextlib.suppress(ValueError):
                out.add(int(p.stem.split("-")[1]))
        return {i for i in out if 0 <= i < self.plan.n_chunks}

    def write(self, i: int, result: dict) -> None:
        _atomic_write(self.chunk_file(i), _to_bytes(result))

    def read(self, i: int) -> dict:
        try:
            return _from_bytes(self.chunk_file(i).read_bytes())
        except Exception as exc:  # truncated or foreign file
            raise OutputError(f"store: chunk file {str(self.chunk_file(i))!r} is unreadable "
                              f"({type(exc).__name__}); delete it to recompute that "
                              f"chunk") from None

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self._lock.close()


def _difference(old: dict, new: dict) -> str:
    if old.get("analysis") != new.get("analysis"):
        return f"analysis {old.get('analysis')!r}, this run {new.get('analysis')!r}"
    if old.get("nonsmooth_version") != new.get("nonsmooth_version"):
        return f"written by nonsmooth {old.get('nonsmooth_version')}, this is {__version__}"
    a, b = _flat(old.get("fingerprint", {})), _flat(new.get("fingerprint", {}))
    keys = [k for k in list(a) + [k for k in b if k not in a] if a.get(k) != b.get(k)]
    if keys:
        shown = ", ".join(f"{k}: stored {_show(a.get(k))}, now {_show(b.get(k))}"
                          for k in keys[:3])
        return shown + (f" and {len(keys) - 3} more" if len(keys) > 3 else "")
    return f"chunks: stored {old.get('n_chunks')}, now {new.get('n_chunks')}"


def _flat(obj, prefix: str = "") -> dict:
    """A fingerprint as {dotted.key[index]: leaf}: a message can name the value that differs
    (lists of different lengths are one leaf: their lengths differ)."""
    out = {}
    if isinstance(obj, dict):
        for k, v in obj.items():
            out.update(_flat(v, f"{prefix}.{k}" if prefix else str(k)))
    elif isinstance(obj, list) and obj and all(not isinstance(v, (list, dict)) for v in obj):
        out[f"{prefix}#"] = f"{len(obj)} values"
        for i, v in enumerate(obj):
            out[f"{prefix}[{i}]"] = v
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            out.update(_flat(v, f"{prefix}[{i}]"))
        out[f"{prefix}#"] = f"{len(obj)} values"
    else:
        out[prefix] = obj
    return out


def _show(v) -> str:
    return "(none)" if v is None else str(v).strip("'")


def _atomic_write(path: Path, data: bytes) -> None:
    """A store file, complete or absent (``io.write_file``, not listed as a result file)."""
    from .io import write_file
    write_file(path, data, "store", record=False)


def _to_bytes(result: dict) -> bytes:
    """A chunk result as numpy's ``.npz`` (arrays as they are; other values, e.g. a carried
    Python state, pickled into a uint8 array). About 100 times faster to write than a netCDF
    file per chunk; the final result is one netCDF file."""
    import io
    import numpy as np
    data = {}
    for name, value in result.items():
        if isinstance(value, np.ndarray) and value.dtype != object:
            data[f"a_{name}"] = value
        else:
            data[f"p_{name}"] = np.frombuffer(pickle.dumps(value, protocol=5), np.uint8)
    buf = io.BytesIO()
    np.savez(buf, **data)
    return buf.getvalue()


def _from_bytes(blob: bytes) -> dict:
    import io
    import numpy as np
    out = {}
    with np.load(io.BytesIO(blob), allow_pickle=False) as z:
        for name in z.files:
            arr = z[name]
            out[name[2:]] = arr if name.startswith("a_") else pickle.loads(arr.tobytes())
    return out


# ---- engines -------------------------------------------------------------------------------------
_ENGINE_HINT = "embedded, local, local:N, a scheduler address (tcp://host:8786) or a Client"


def check_engine(engine):
    """Validate ``engine`` without starting anything: None, "embedded", "local[:N]", an
    address, or a dask.distributed.Client. Returns it normalised (None for embedded)."""
    if engine is None or engine == "embedded":
        return None
    if isinstance(engine, str):
        e = engine.strip()
        if e == "local" or e.startswith("local:"):
            n = e.partition(":")[2]
            if n and (not n.isdigit() or int(n) < 1):
                raise ParameterError(f"dask: local:N needs N >= 1 workers, got {engine!r}")
            return e
        if not e or any(c.isspace() for c in e):
            raise ParameterError(f"dask: expected {_ENGINE_HINT}, got {engine!r}")
        return e
    if type(engine).__name__ == "Client" and hasattr(engine, "submit"):
        return engine
    raise ParameterError(f"engine: expected {_ENGINE_HINT}, got {engine!r}")


@contextlib.contextmanager
def dask_client(engine):
    """A connected ``Client`` for a normalised Dask ``engine`` (closed on exit where opened
    here); one line when Dask is missing or the scheduler cannot be reached."""
    if not isinstance(engine, str):
        yield engine
        return
    try:
        import distributed
    except ImportError:
        raise ParameterError('dask: Dask is not installed; pip install "nonsmooth[dask]"') from None
    import logging
    for name in ("distributed", "tornado"):  # connection noise would hide our one line
        logging.getLogger(name).setLevel(logging.CRITICAL)
    if engine.startswith("local"):
        n = int(engine.partition(":")[2] or (os.cpu_count() or 1))
        import warnings
        with warnings.catch_warnings():  # "port 8787 in use" and the like
            warnings.simplefilter("ignore")
            cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1,
                                               processes=True, dashboard_address=None,
                                               silence_logs=logging.CRITICAL)
        client = distributed.Client(cluster)
        try:
            yield client
        finally:
            with contextlib.suppress(Exception):
                client.close()
                cluster.close()
        return
    address = engine if "://" in engine else f"tcp://{engine}"
    try:
        client = distributed.Client(address, timeout=CONNECT_TIMEOUT)
    except ValueError as exc:
        raise ParameterError(f"dask: invalid scheduler address {engine!r} "
                             f"({str(exc).splitlines()[0][:120] if str(exc) else 'ValueError'})"
                             ) from None
    except (OSError, TimeoutError) as exc:
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ParameterError(f"dask: cannot reach the scheduler at {address} within "
                             f"{CONNECT_TIMEOUT:g} s ({reason[:120]})") from None
    try:
        yield client
    finally:
        with contextlib.suppress(Exception):
            client.close()


_kernel_lock = threading.Lock()


def _dask_task(task, spec, i, carry):
    """Run one chunk on a Dask worker: one chunk at a time per worker process (numba's
    default threading layer must not be entered by two threads at once), with as many numba
    threads as the worker has threads."""
    import numba as nb
    try:
        from distributed import get_worker
        n = int(get_worker().state.nthreads)
    except Exception:  # not on a worker (a synchronous test client)
        n = 1
    n = max(1, min(n, nb.config.NUMBA_NUM_THREADS))
    with _kernel_lock:
        return task(spec, i, carry, workers=n)


# ---- running a plan ------------------------------------------------------------------------------
#: Called as ``on_resume(path, chunks_done, chunks_total)`` when a run finds finished chunks in
#: its store (the CLI prints one line); None: silent.
on_resume = None

#: Stores used by the runs of this process: (path, chunks in all). The CLI's message for an
#: interrupted run says what they hold and how to resume.
active_stores: list = []


def saved_chunks(path) -> int:
    """Finished chunk files in a store directory (0 when it is gone)."""
    return len(list(Path(path).glob("chunk-*.npz"))) if Path(path).is_dir() else 0


def execute(plan: Plan, collect: Callable[[int, dict], None], *, store=None, engine=None,
            workers=None, progress=None) -> None:
    """Compute every chunk of ``plan`` and hand each result to ``collect(i, result)`` (in
    chunk order within a chain, otherwise in order of completion: ``collect`` must put each
    chunk in its place). With ``store`` (a directory, see :class:`ChunkStore`) the
    finished chunks are written there and the chunks already there are read instead of
    computed. ``progress(done, total)`` counts ``plan.weights``. A Dask engine is connected
    before the store is opened, so an unreachable scheduler leaves nothing behind; a run
    refused or failed with a :class:`NonsmoothError` (an analysis refusing its input inside
    a chunk) removes a store that holds no finished chunk (one with finished chunks stays, to
    resume from)."""
    engine = check_engine(engine)
    with contextlib.ExitStack() as stack:
        client = stack.enter_context(dask_client(engine)) if engine is not None else None
        st = ChunkStore(store, plan) if store is not None else None
        if st is not None:
            stack.callback(st.close)
            active_stores.append((st.path, plan.n_chunks))
        try:
            _execute(plan, collect, st, client, workers, progress)
        except NonsmoothError:
            if st is not None and saved_chunks(st.path) == 0:
                stack.close()  # (its lock released first)
                remove_store(st.path)
            raise


def _execute(plan, collect, st, client, workers, progress):
    done = st.done() if st is not None else set()
    weights = [float(w) for w in (plan.weights or [1.0] * plan.n_chunks)]
    total = sum(weights) or 1.0
    finished = [0.0]

    def report(extra=0.0):
        if progress is not None:
            progress(int(round(finished[0] + extra)), int(round(total)))

    def finish(i, res, write=True, quiet=False):
        if write and st is not None:
            st.write(i, res)
        collect(i, res)
        finished[0] += weights[i]
        if not quiet:
            report()

    # finished chunks: independent ones all; of a chain, the prefix of finished chunks
    members: dict = {}
    for i in range(plan.n_chunks):
        members.setdefault(plan.chain_of(i), []).append(i)
    carries, todo, reuse = {}, {}, []
    for c, idx in members.items():
        if c is None:
            reuse += [i for i in idx if i in done]
            todo[None] = [i for i in idx if i not in done]
            continue
        k = next((q for q, i in enumerate(idx) if i not in done), len(idx))
        reuse += idx[:k]
        carries[c] = None
        if idx[k:]:
            todo[c] = idx[k:]
    if reuse and on_resume is not None:
        on_resume(st.path, len(reuse), plan.n_chunks)
    for i in sorted(reuse):
        res = st.read(i)
        if plan.chain_of(i) is not None:
            carries[plan.chain_of(i)] = res.get("carry")
        finish(i, res, write=False)
    todo = {c: v for c, v in todo.items() if v}
    if client is not None:
        try:
            _run_dask(client, plan, todo, carries, finish)
        except (KeyboardInterrupt, NonsmoothError):
            raise
        except Exception as exc:  # a killed worker beyond the scheduler's allowed failures,
            # a lost connection, a cancelled task: one line, and what is saved
            saved = (f"; {saved_chunks(st.path)} of {plan.n_chunks} chunks saved in "
                     f"{st.path}, run again to resume") if st is not None else ""
            reason = str(exc).splitlines()[0][:160] if str(exc) else ""
            raise NonsmoothError(f"dask: the cluster failed ({type(exc).__name__}: {reason})"
                                 f"{saved}") from None
        return
    chained = {c: v for c, v in todo.items() if c is not None}
    if chained and plan.stream is not None:
        base, left = finished[0], sum(weights[i] for v in chained.values() for i in v)

        def inner(d, t):
            if progress is not None:
                progress(int(round(base + left * d / t if t else base)), int(round(total)))
        plan.stream(plan.spec, chained, {c: carries[c] for c in chained},
                    lambda i, res: finish(i, res, quiet=True), workers=workers,
                    progress=inner if progress is not None else None)
        chained = {}
    for c, idx in list(chained.items()) + ([(None, todo[None])] if None in todo else []):
        carry = carries.get(c)
        for i in idx:
            w = weights[i]

            def inner(d, t, _w=w):
                report(_w * d / t if t else 0.0)
            res = plan.task(plan.spec, i, carry, workers=workers,
                            progress=inner if progress is not None else None)
            carry = res.get("carry")
            finish(i, res)


def _submit(client, plan, spec, i, carry):
    return client.submit(_dask_task, plan.task, spec, i, carry, pure=False, retries=RETRIES,
                         key=f"nonsmooth-{plan.analysis}-{i}-{uuid.uuid4().hex[:8]}")


def _run_dask(client, plan, todo, carries, finish):
    """Every chain's chunks one after the other (each from its predecessor's carry), chains
    and independent chunks side by side, at most a window of independent chunks in flight."""
    from distributed import as_completed
    if not todo:
        return
    futures = []
    try:
        nthreads = sum(client.nthreads().values()) or 1
        window = max(2, IN_FLIGHT_PER_THREAD * nthreads)
        spec = plan.spec
        if _big(spec):  # one copy per worker, not one per task (a list: scattered whole)
            [spec] = client.scatter([plan.spec], broadcast=True, hash=False)
        queues = {c: list(v) for c, v in todo.items()}
        index = {}

        def submit(c, carry=None):
            i = queues[c].pop(0)
            fut = _submit(client, plan, spec, i, carry)
            index[fut.key] = (i, c)
            futures.append(fut)
            return fut

        first = [submit(c, carries.get(c)) for c in queues if c is not None]
        free = queues.get(None, [])
        first += [submit(None) for _ in range(min(window, len(free)))]
        ac = as_completed(first)
        for fut in ac:
            res = fut.result()
            i, c = index.pop(fut.key)
            fut.release()
            futures.remove(fut)
            if queues.get(c):
                ac.add(submit(c, res.get("carry") if c is not None else None))
            finish(i, res)
    finally:  # an interruption or a failure: nothing of this run stays on the cluster
        if futures:
            with contextlib.suppress(Exception):
                client.cancel(futures)


def _big(spec) -> bool:
    with contextlib.suppress(Exception):
        return len(pickle.dumps(spec)) > 1_000_000
    return False


def chunk_bounds(n: int, size: int) -> list:
    """[(start, stop), ...] of ``n`` items in chunks of ``size`` (the last may be shorter)."""
    size = max(1, int(size))
    return [(a, min(n, a + size)) for a in range(0, n, size)] or [(0, 0)]


def store_for(out) -> Path | None:
    """The chunk store of a run whose result goes to ``out``: ``<out>.chunks`` next to it."""
    return None if out is None else Path(str(out) + ".chunks")


def remove_store(path) -> None:
    """Delete a chunk store (a directory with a ``manifest.json``; anything else is left)."""
    if path is not None and (Path(path) / "manifest.json").is_file():
        shutil.rmtree(path, ignore_errors=True)


def solver_spec(solver) -> dict:
    """A Solver as plain data that Dask workers can rebuild (:func:`solver_from_spec`); a
    model defined only in this process (not built in, not loaded from a file) cannot travel."""
    m = solver.model
    ref = m.name if m.source == "built-in" else m.source
    out = {"model": ref, "method": solver.method, "rtol": solver.rtol, "atol": solver.atol,
           "max_steps": solver.max_steps, "section_phase": solver.section_phase,
           "defined_in_process": m.source == "built-in" and _not_builtin(m)}
    from .models import file_digest
    digest = file_digest(ref) if m.source != "built-in" else None
    if digest is not None:  # a model from a file: a store of another version of it is refused
        out["model_digest"] = digest
    return out


def _not_builtin(m) -> bool:
    from .models import BUILTIN
    return m.name not in BUILTIN


_models_here: dict = {}


def remember_model(model) -> None:
    """Models defined in this process, so that embedded tasks can find them by name."""
    _models_here[model.name] = model


def solver_from_spec(spec: dict):
    from .kernels import Solver
    from .models import model as get_model
    if spec.get("defined_in_process"):
        m = _models_here.get(spec["model"])
        if m is None:
            raise ParameterError(f"model: {spec['model']!r} is defined in the client process "
                                 f"only; Dask workers need it in a file (path/to/file.py:NAME)")
    else:
        from .models import file_digest
        m = get_model(spec["model"])
        digest = spec.get("model_digest")
        if digest is not None and file_digest(spec["model"]) != digest:
            raise ParameterError(f"model: {spec['model']} here is not the file the run started "
                                 f"with (its contents differ)")
    return Solver(model=m, method=spec["method"], rtol=spec["rtol"], atol=spec["atol"],
                  max_steps=spec["max_steps"], section_phase=spec.get("section_phase", 0.0))


def plan_solver(solver, engine) -> dict:
    """``solver_spec`` for a plan run on ``engine``; refuses, before anything starts, a model
    that Dask workers could not rebuild."""
    spec = solver_spec(solver)
    if spec["defined_in_process"]:
        if check_engine(engine) is not None:
            raise ParameterError(f"engine: model {solver.model.name!r} is defined in this "
                                 f"process only; for Dask put it in a file and use "
                                 f"path/to/file.py:NAME")
        remember_model(solver.model)
    return spec
