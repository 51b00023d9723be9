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


#: Why a model without forcing (or with its amplitude at 0) has no orbit diagram.
NO_SECTION = ("no orbit diagram: without forcing there is no stroboscopic section "
              "(nonsmooth surface-bifurcation draws one on a section surface)")

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
    lambda1_pending: bool = False   # drawn before its lambda1 (the second stage) is known

    def summary(self) -> str:
        """One line for the page: period, lambda1 and the verdict."""
        if self.status != "ok":
            return self.status
        if self.period is None:
            return f"no stroboscopic section ({self.motion or 'no forcing'})"
        per = {0: "no period", -1: "not settled"}.get(self.period, f"period {self.period}")
        if self.lambda1_pending:
            return f"{per}, λ1: computing ..."
        lam = ("" if not math.isfinite(self.lambda1) else
               f", λ1 = {self.lambda1:.4g} ± {self.lambda1_stderr:.2g}")
        return f"{per}{lam}{', ' + self.motion if self.motion else ''}"


def first_line(exc) -> str:
    """An exception's message in one line (its type where it has none)."""
    return str(exc).splitlines()[0] if str(exc) else type(exc).__name__


def _failed(names, exc) -> Orbit:
    empty = np.zeros(0)
    return Orbit(t=empty, u={n: empty for n in names}, mode=np.zeros(0, np.int8),
                 section={n: empty for n in names}, status=f"failed: {first_line(exc)}")


def current_orbit(params, method: str, u0, *, transient: int = VIEW_TRANSIENT,
                  record: int = VIEW_RECORD, periods: int = VIEW_PERIODS,
                  samples: int = VIEW_SAMPLES, lyapunov: bool = True) -> Orbit:
    """The orbit from ``u0`` after ``transient`` periods: ``periods`` periods drawn at
    ``samples`` per period with their modes, ``record`` section points, the period found on the
    section and (``lyapunov``) lambda1 with its standard error and the verdict
    (``ns.poincare``). A model without forcing (or with its forcing amplitude at 0) has no
    stroboscopic section: its time response only (``ns.simulate``). A failure is an Orbit with
    ``status`` saying why (never raised)."""
    from ..analysis.poincare import poincare
    from ..simulate import simulate

    from ..io import component_names

    names = tuple(params.model.state_names)
    var = dict(zip(names, component_names(names)))   # results name u[0], u[1] X and V
    t0 = time.perf_counter()
    try:
        if has_section(params):
            ds = poincare(params, record=record, transient=transient, method=method,
                          u0=list(u0), orbit_periods=periods, orbit_samples=samples,
                          lyapunov=lyapunov)
            orb = Orbit(t=ds["orbit_t"].values,
                        u={n: ds[f"orbit_{var[n]}"].values for n in names},
                        mode=ds["orbit_region"].values.astype(np.int8),
                        section={n: ds[var[n]].values for n in names},
                        period=int(ds["period"]),
                        lambda1=float(ds["lambda1"]) if "lambda1" in ds else math.nan,
                        lambda1_stderr=(float(ds["lambda1_stderr"]) if "lambda1_stderr" in ds
                                        else math.nan),
                        motion=MOTION_TEXT.get(int(ds["motion"]), "") if "motion" in ds else "",
                        lambda1_pending=not lyapunov)
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


def orbit_stages(params, method: str, u0, **kw):
    """The current orbit in two stages: drawn first without lambda1 (the fast part), then
    with it (Benettin's run over the record for a non-periodic orbit, the dear part). A
    superseded request stops between the stages (``LatestWorker``)."""
    first = current_orbit(params, method, u0, lyapunov=False, **kw)
    yield first
    if first.status == "ok" and first.period is not None:
        yield current_orbit(params, method, u0, lyapunov=True, **kw)


def has_section(params) -> bool:
    """Does the model have a stroboscopic section at these parameters (a forcing whose
    amplitude is not 0)?"""
    m = params.model
    if m.autonomous:
        return False
    amp = m.forcing_amplitude
    return amp is None or getattr(params, amp) != 0.0


class Cancelled(Exception):
    """Raised inside a slice whose request was superseded."""


def orbit_slice(params, method: str, param: str, values, u0, *, transient: int = SLICE_TRANSIENT,
                record: int = SLICE_RECORD, chunk: int = SLICE_CHUNK, alive=lambda: True,
                component: int = 0):
    """An orbit-diagram slice over ``param`` = ``values`` (increasing), swept up from ``u0``
    as ``bifurcation_diagram`` sweeps it (each value starts from the previous value's state,
    every component of it), in chunks of ``chunk`` values: yields (values, section points of
    u[``component``] (0 or 1), period) per chunk, and stops (raises Cancelled) between chunks
    once ``alive()`` is false. Failed values carry NaN points; the sweep goes on from the last
    good state. A model without forcing (or with its amplitude at 0) has no stroboscopic
    section: one ParameterError."""
    from ..analysis.bifurcation import check_values, run_branches
    from ..integrate.contract import ST_EXTRA
    from ..kernels import Solver

    if not has_section(params):
        raise ParameterError(NO_SECTION)
    values = np.asarray(values, dtype=float)
    if values.size == 0:
        raise ParameterError("slice: empty range of values")
    if component not in (0, 1):
        raise ParameterError(f"component: the section holds u[0] and u[1], got u[{component}]")
    n = len(params.model.state_names)
    solver = Solver(model=params.model, method=method)
    state = [float(x) for x in u0]
    for i in range(0, values.size, chunk):
        if not alive():
            raise Cancelled()
        part = check_values(param, values[i:i + chunk])
        out = run_branches(params, param, part, solver, directions=["up"],
                           transient=transient, record=record, x0=state[0], v0=state[1],
                           extra=state[2:], settle=True, workers=1)
        pts = np.where((out["status"][0] == 0)[:, None], out["X" if component == 0 else "V"][0],
                       np.nan)
        end = out["state"][0]
        last = [float(end[0]), float(end[1]), *map(float, end[ST_EXTRA:ST_EXTRA + n - 2])]
        if out["status"][0][-1] == 0 and all(map(math.isfinite, last)):
            state = last
        yield part, pts, out["period"][0]


#: One computation at a time: numba's parallel regions must not be entered from two threads.
COMPUTE_LOCK = threading.Lock()


class LatestWorker:
    """A background thread that computes only the newest request.

    ``submit(*args)`` replaces any request still waiting; the request being computed is
    abandoned at its next check of ``alive()`` (a slice, between chunks) or, if it cannot be
    interrupted, its result is dropped. ``fn(*args, alive=...)`` returns a value or yields
    values; each is passed to ``deliver(value)`` while its request is still the newest.
    """

    def __init__(self, fn, deliver, name: str = "nonsmooth-explore", defer_to=None):
        self._fn, self._deliver = fn, deliver
        self._defer_to = defer_to           # a worker whose requests go first (the view)
        self.idle = threading.Event()
        self.idle.set()
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
            self.idle.clear()
            self._cond.notify()
            return self._gen

    def cancel(self) -> None:
        """Abandon the request waiting or running (a refused request supersedes it)."""
        with self._cond:
            self._gen += 1
            self._pending = None

    def alive(self, gen: int) -> bool:
        """Is request ``gen`` still the newest?"""
        return gen == self._gen and not self._stopped

    def stop(self) -> None:
        with self._cond:
            self._stopped = True
            self.idle.set()
            self._cond.notify()

    def _run(self) -> None:
        while True:
            with self._cond:
                while self._pending is None and not self._stopped:
                    self.idle.set()
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
                        if self._defer_to is not None:   # let the view go first
                            self._defer_to.idle.wait()
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
