"""What the explore page computes, without any page: the current orbit (time response, phase
portrait, section points, period and lambda1) and an orbit-diagram slice in chunks that a newer
request abandons. Plain data in, plain arrays out; the page (``page.py``) only draws them.
"""

from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import NonsmoothError, ParameterError

#: Settings of the current orbit: periods discarded, section points recorded, periods drawn
#: and samples per period of the drawn orbit.
VIEW_TRANSIENT = 200
VIEW_RECORD = 100
VIEW_PERIODS = 3
VIEW_SAMPLES = 150
#: Settings of the orbit-diagram slice (per parameter value) and its chunk size in values.
SLICE_TRANSIENT = 200
SLICE_RECORD = 40
SLICE_CHUNK = 20
#: The time unit of a model without forcing is 2 pi; its orbit is drawn over this many units.
AUTONOMOUS_TIME = 40


MOTION_TEXT = {1: "periodic", 2: "quasi-periodic", 3: "chaotic", 4: "not settled"}


@dataclass
class Orbit:
    """The current orbit: drawn samples, section points and what they say."""

    t: np.ndarray
    u: dict                    # component name -> samples
    mode: np.ndarray
    section: dict              # component name -> section points
    period: int | None = None  # 0: none found, -1: not settled, None: no section
    lambda1: float = math.nan
    lambda1_stderr: float = math.nan
    motion: str = ""
    status: str = "ok"
    seconds: float = 0.0

    def summary(self) -> str:
        """One line for the page: period, lambda1 and the verdict."""
        if self.status != "ok":
            return self.status
        if self.period is None:
            return f"no stroboscopic section ({self.motion or 'no forcing'})"
        per = {0: "no period", -1: "not settled"}.get(self.period, f"period {self.period}")
        lam = ("" if not math.isfinite(self.lambda1) else
               f", λ1 = {self.lambda1:.4g} ± {self.lambda1_stderr:.2g}")
        return f"{per}{lam}{', ' + self.motion if self.motion else ''}"


def _failed(names, exc) -> Orbit:
    empty = np.zeros(0)
    msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    return Orbit(t=empty, u={n: empty for n in names}, mode=np.zeros(0, np.int8),
                 section={n: empty for n in names}, status=f"failed: {msg}")


def current_orbit(params, method: str, u0, *, transient: int = VIEW_TRANSIENT,
                  record: int = VIEW_RECORD, periods: int = VIEW_PERIODS,
                  samples: int = VIEW_SAMPLES) -> Orbit:
    """The orbit from ``u0`` after ``transient`` periods: ``periods`` periods drawn at
    ``samples`` per period with their modes, ``record`` section points, the period found on the
    section and lambda1 with its standard error (``ns.poincare``). A model without forcing (or
    with its forcing amplitude at 0) has no stroboscopic section: its time response only
    (``ns.simulate``). A failure is an Orbit with ``status`` saying why (never raised)."""
    from ..analysis.poincare import poincare
    from ..simulate import simulate

    from ..io import component_names

    names = tuple(params.model.state_names)
    var = dict(zip(names, component_names(names)))   # results name u[0], u[1] X and V
    t0 = time.perf_counter()
    try:
        if _has_section(params):
            ds = poincare(params, record=record, transient=transient, method=method,
                          u0=list(u0), orbit_periods=periods, orbit_samples=samples)
            orb = Orbit(t=ds["orbit_t"].values,
                        u={n: ds[f"orbit_{var[n]}"].values for n in names},
                        mode=ds["orbit_region"].values.astype(np.int8),
                        section={n: ds[var[n]].values for n in names},
                        period=int(ds["period"]),
                        lambda1=float(ds["lambda1"]) if "lambda1" in ds else math.nan,
                        lambda1_stderr=(float(ds["lambda1_stderr"]) if "lambda1_stderr" in ds
                                        else math.nan),
                        motion=MOTION_TEXT.get(int(ds["motion"]), "") if "motion" in ds else "")
        else:
            n_per = periods if params.model.omega or params.model.period else AUTONOMOUS_TIME
            ds = simulate(params, periods=n_per, transient=transient, method=method,
                          u0=list(u0), samples_per_period=samples)
            orb = Orbit(t=ds["t"].values, u={n: ds[var[n]].values for n in names},
                        mode=ds["region"].values.astype(np.int8),
                        section={n: np.zeros(0) for n in names},
                        motion="no forcing" if params.model.autonomous else "F0 = 0")
    except (NonsmoothError, FloatingPointError, ValueError) as exc:
        orb = _failed(names, exc)
    orb.seconds = time.perf_counter() - t0
    return orb


def _has_section(params) -> bool:
    m = params.model
    if m.autonomous:
        return False
    amp = m.forcing_amplitude
    return amp is None or getattr(params, amp) != 0.0


class Cancelled(Exception):
    """Raised inside a slice whose request was superseded."""


@dataclass
class Generation:
    """A counter of requests: work started for generation g stops once a newer one exists."""

    value: int = 0
    lock: threading.Lock = field(default_factory=threading.Lock)

    def next(self) -> int:
        with self.lock:
            self.value += 1
            return self.value

    def current(self, g: int) -> bool:
        return g == self.value


def orbit_slice(params, method: str, param: str, values, u0, *, transient: int = SLICE_TRANSIENT,
                record: int = SLICE_RECORD, chunk: int = SLICE_CHUNK, alive=lambda: True,
                component: str | None = None):
    """An orbit-diagram slice over ``param`` = ``values`` (increasing), swept up from ``u0``
    as ``bifurcation_diagram`` sweeps (each value starts from the previous value's state), in
    chunks of ``chunk`` values: yields (values, section points of ``component``, period) per
    chunk, and stops (raises Cancelled) between chunks once ``alive()`` is false. Failed
    values carry NaN points (the sweep goes on from the last good state)."""
    from ..analysis.bifurcation import bifurcation_diagram
    from ..io import component_names

    values = np.asarray(values, dtype=float)
    if values.size == 0:
        raise ParameterError("slice: empty range of values")
    names = tuple(params.model.state_names)
    var = dict(zip(names, component_names(names)))   # results name u[0], u[1] X and V
    comp = var[component or names[0]]
    state = [float(x) for x in u0]
    for i in range(0, values.size, chunk):
        if not alive():
            raise Cancelled()
        part = values[i:i + chunk]
        ds = bifurcation_diagram(params, param, part, sweep="up", transient=transient,
                                 record=record, method=method, u0=state, lyapunov=False,
                                 workers=1)
        pts = ds[comp].isel(sweep=0).values
        last = {n: ds[var[n]].isel(sweep=0).values if var[n] in ds else None for n in names}
        good = np.flatnonzero(np.isfinite(pts).all(axis=1))
        if good.size and all(v is not None for v in last.values()):
            j = int(good[-1])
            state = [float(last[n][j, -1]) for n in names]
        yield part, pts, ds["period"].isel(sweep=0).values


#: One computation at a time: numba's parallel regions must not be entered from two threads.
COMPUTE_LOCK = threading.Lock()


class LatestWorker:
    """A background thread that computes only the newest request.

    ``submit(*args)`` replaces any request still waiting; the request being computed is
    abandoned at its next check of ``alive()`` (a slice, between chunks) or, if it cannot be
    interrupted, its result is dropped. ``fn(*args, alive=...)`` returns a value or yields
    values; each is passed to ``deliver(value)`` while its request is still the newest.
    """

    def __init__(self, fn, deliver, name: str = "nonsmooth-explore"):
        self._fn, self._deliver = fn, deliver
        self._cond = threading.Condition()
        self._gen = 0
        self._pending = None
        self._stopped = False
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    def submit(self, *args) -> int:
        """Queue a request (superseding the others); its generation number."""
        with self._cond:
            self._gen += 1
            self._pending = (self._gen, args)
            self._cond.notify()
            return self._gen

    def alive(self, gen: int) -> bool:
        """Is request ``gen`` still the newest?"""
        return gen == self._gen and not self._stopped

    def stop(self) -> None:
        with self._cond:
            self._stopped = True
            self._cond.notify()

    def _run(self) -> None:
        while True:
            with self._cond:
                while self._pending is None and not self._stopped:
                    self._cond.wait()
                if self._stopped:
                    return
                gen, args = self._pending
                self._pending = None
            alive = lambda g=gen: self.alive(g)  # noqa: E731
            try:
                out = self._fn(*args, alive=alive)
                if hasattr(out, "__next__"):
                    while True:
                        with COMPUTE_LOCK:
                            if not alive():
                                break
                            try:
                                value = next(out)
                            except StopIteration:
                                break
                        self._deliver(gen, value)
                elif alive():
                    self._deliver(gen, out)
            except Cancelled:
                continue
            except Exception as exc:  # noqa: BLE001 - shown in the page, the page keeps working
                if alive():
                    self._deliver(gen, exc)
