"""The reproduction framework: a registry of figures, checks with computed verdicts, and a runner
that times every figure and records its failure instead of stopping.

A figure entry is a function ``entry(ctx, rec)`` registered with :func:`figure`. It computes its
Dataset(s) by calling the library's analyses, saves them with ``ctx.save`` / ``ctx.savefig``, and
records what it measured with ``rec.check(...)``. Verdicts are computed by the helpers below from
the measured numbers, never written in by hand.
"""

from __future__ import annotations

import math
import re
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

AGREES = "agrees"
DIFFERS = "differs"
NOT_STATED = "not stated"
VERDICTS = (AGREES, DIFFERS, NOT_STATED)


@dataclass
class Check:
    """One claim of the paper (or a measured fact the paper does not state) beside our result."""

    claim: str
    measured: str
    verdict: str
    evidence: str = ""

    def __post_init__(self):
        if self.verdict not in VERDICTS:
            raise ValueError(f"verdict: must be one of {VERDICTS}, got {self.verdict!r}")


#: FigureRecord fields stored in ``summary.json`` (paths as names inside the output folder)
_STORED = ("id", "title", "params", "method", "settings", "notes", "seconds", "error",
           "traceback", "gaps", "run")


@dataclass
class FigureRecord:
    """Everything the report says about one figure."""

    id: str
    title: str
    params: dict = field(default_factory=dict)
    method: str = ""
    settings: dict = field(default_factory=dict)
    checks: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    files: list = field(default_factory=list)
    seconds: float = 0.0
    error: str = ""
    traceback: str = ""
    #: evidence for the report's section on the paper's gaps: [topic, text] pairs
    gaps: list = field(default_factory=list)
    #: the run that computed this figure (command, mode, date, ...), see ``reproduce``
    run: dict = field(default_factory=dict)

    # -- recording helpers -------------------------------------------------------------
    def check(self, claim: str, measured: str, verdict: str, evidence: str = "") -> Check:
        c = Check(claim, measured, verdict, evidence)
        self.checks.append(c)
        return c

    def note(self, text: str) -> None:
        self.notes.append(text)

    def use_params(self, params, **labels) -> None:
        """Record the parameter set (``labels`` add e.g. preset names or swept ranges)."""
        self.params = {k: f"{v:.6g}" for k, v in params.as_dict().items()}
        self.params.update({k: str(v) for k, v in labels.items()})

    @property
    def ok(self) -> bool:
        return not self.error

    def counts(self) -> dict:
        out = {v: 0 for v in VERDICTS}
        for c in self.checks:
            out[c.verdict] += 1
        return out

    # -- summary.json ------------------------------------------------------------------
    def to_dict(self) -> dict:
        d = {k: getattr(self, k) for k in _STORED}
        d["checks"] = [c.__dict__ for c in self.checks]
        d["files"] = [Path(f).name for f in self.files]
        return d

    @classmethod
    def from_dict(cls, d: dict, out: Path) -> "FigureRecord":
        rec = cls(**{k: d[k] for k in _STORED})
        rec.checks = [Check(**c) for c in d["checks"]]
        rec.files = [Path(out) / f for f in d["files"]]
        return rec


@dataclass(frozen=True)
class FigureSpec:
    id: str
    title: str
    claim: str  # the paper's headline claim for this figure, one line
    entry: Callable
    cost: float = 1.0  # rough relative cost (only for ordering messages)


#: figure id -> spec, in paper order (filled by ``figures.py``)
FIGURES: dict[str, FigureSpec] = {}


def paper_order(fid: str):
    """Sort key of a figure id: "fig10a" -> (10, "a"); other ids after the paper's."""
    m = re.fullmatch(r"fig(\d+)([a-z]*)", fid)
    return (int(m[1]), m[2]) if m else (math.inf, fid)


def figure(id: str, title: str, claim: str, cost: float = 1.0):
    """Decorator registering ``entry(ctx, rec)`` as the reproduction of figure ``id`` (the
    registry stays in paper order whatever the order of registration)."""

    def deco(fn):
        FIGURES[id] = FigureSpec(id, title, claim, fn, cost)
        for k in sorted(FIGURES, key=paper_order):
            FIGURES[k] = FIGURES.pop(k)
        return fn

    return deco


class Context:
    """What a figure entry gets: the output folder, the mode, a per-run cache of shared results
    (e.g. Fig. 8 reuses the basins of Fig. 7a) and the current record for saved files."""

    def __init__(self, out: Path, quick: bool = False, workers: int | None = None,
                 log: Callable[[str], None] | None = None):
        self.out = Path(out)
        self.quick = bool(quick)
        self.workers = workers
        self.log = log or (lambda msg: None)
        self.cache: dict = {}
        self.current: FigureRecord | None = None

    def setting(self, group: str, name: str):
        """Setting ``name`` of ``group`` in this run's mode (``settings.SETTINGS``)."""
        from .settings import SETTINGS
        return SETTINGS[group][name][self.quick]

    def shared(self, key: str, compute: Callable):
        """Compute once per run; later figures get the same object (errors are re-raised)."""
        if key not in self.cache:
            try:
                self.cache[key] = ("ok", compute())
            except Exception as exc:  # noqa: BLE001 - re-raised for every user of the result
                self.cache[key] = ("error", exc)
        kind, value = self.cache[key]
        if kind == "error":
            raise value
        return value

    def _record(self, path: Path) -> Path:
        if self.current is not None:
            self.current.files.append(path)
        return path

    def save(self, ds, name: str) -> Path:
        from ..io import save_dataset
        return self._record(save_dataset(ds, self.out / f"{name}.nc"))

    def savefig(self, fig, name: str) -> Path:
        from ..io import save_figure
        p = self.out / f"{name}.png"
        save_figure(fig, p, dpi=110)
        return self._record(p)


def run_figures(ids, ctx: Context, done: Callable[[FigureRecord], None] = lambda rec: None
                ) -> list[FigureRecord]:
    """Run the figures ``ids`` in order and hand each record to ``done`` as soon as the figure
    is finished (the report is rewritten there, so an interrupted run keeps what is done). A
    failing figure gets its error recorded and the run goes on; on Ctrl-C the figure in
    progress is recorded as interrupted, handed to ``done``, and the interrupt goes on."""
    records = []
    for fid in ids:
        spec = FIGURES[fid]
        rec = FigureRecord(fid, spec.title)
        ctx.current = rec
        ctx.log(f"{fid}: {spec.title} ...")
        t0 = time.perf_counter()
        try:
            spec.entry(ctx, rec)
        except KeyboardInterrupt:
            rec.seconds = time.perf_counter() - t0
            rec.error = "interrupted before the figure was finished (its files may be partial)"
            done(rec)
            raise
        except Exception as exc:  # noqa: BLE001 - one figure never stops the run
            rec.error = f"{type(exc).__name__}: {exc}".strip()
            rec.traceback = traceback.format_exc(limit=6)
        finally:
            rec.seconds = time.perf_counter() - t0
            ctx.current = None
        if rec.ok and not any(str(f).endswith(".png") for f in rec.files):
            rec.error = "no PNG figure was produced"
        if rec.ok and not any(str(f).endswith(".nc") for f in rec.files):
            rec.error = "no netCDF data file was produced"
        c = rec.counts()
        status = f"FAILED ({rec.error})" if rec.error else (
            f"{c[AGREES]} agree, {c[DIFFERS]} differ, {c[NOT_STATED]} not stated")
        ctx.log(f"{fid}: {rec.seconds:.1f} s, {status}")
        records.append(rec)
        done(rec)
    return records


# -- verdict helpers (every verdict in the report comes from one of these) -------------------
def agree_if(condition) -> str:
    """AGREES when ``condition`` is true, DIFFERS otherwise (None or NaN = DIFFERS)."""
    try:
        return AGREES if bool(condition) else DIFFERS
    except (TypeError, ValueError):
        return DIFFERS


def period_text(p) -> str:
    """'period 3', 'not periodic (...)', 'not settled (...)' (a negative code: the analyses'
    label of a section that has not settled yet) or 'unknown'."""
    if p is None or (isinstance(p, float) and math.isnan(p)):
        return "unknown"
    p = int(p)
    if p == 0:
        return "not periodic (period 0: chaotic or quasi-periodic)"
    if p < 0:
        return "not settled (no period can be told yet; a longer transient is needed)"
    return f"period {p}"


def _pm(x: float, err: float) -> str:
    """'0.058 ± 0.0061': the error to 2 significant digits, x to the same decimals."""
    if not (math.isfinite(x) and math.isfinite(err)) or err <= 0:
        return f"{fmt(x, 3)} ± {fmt(err, 2)}"
    dec = max(0, 1 - math.floor(math.log10(err)))
    return f"{x:.{dec}f} ± {err:.{dec}f}"


def lyapunov_text(src, *, with_period: bool = True, **sel) -> str:
    """Evidence for a claim of chaos: the detected period beside the largest Lyapunov exponent
    with its standard error and the library's verdict (``motion``), e.g. "not periodic (period
    0), lambda1 = 0.058 ± 0.006 /s > 0 (9.5 errors): chaotic".

    ``src``: a Dataset of ``poincare`` / ``bifurcation_diagram`` (``lambda1``,
    ``lambda1_stderr``, ``motion``, ``period``; ``sel`` picks one point of a sweep, e.g.
    ``sweep=0, omega=0.92``, by position for an integer and by label otherwise), a
    ``lyapunov`` Dataset (``lyapunov_class``), or a tuple ``(lambda1, stderr[, motion[,
    period]])``. Only lambda1 > N_SIGMA errors is called chaotic; within the errors of 0 the
    text says that the run cannot tell quasi-periodic motion or a long transient from chaos."""
    from ..analysis.stability import CHAOTIC, N_SIGMA, VERDICTS, classify
    if isinstance(src, tuple):
        lam, err, motion, period = (tuple(src) + (None, None))[:4]
    else:
        def get(name):
            if name not in src:
                return None
            da = src[name]
            for dim, key in sel.items():
                if dim in da.dims:
                    da = da.isel({dim: key}) if isinstance(key, (int, np.integer)) \
                        else da.sel({dim: key}, method="nearest")
            return da.values.item() if da.ndim == 0 else None
        lam, err = get("lambda1"), get("lambda1_stderr")
        motion = get("motion")
        if motion is None:
            motion = get("lyapunov_class")
        period = get("period")
    head = ""
    if with_period and period is not None:
        p = period_text(period)
        head = ("not periodic (period 0)" if p.startswith("not periodic") else p) + ", "
    try:
        lam, err = float(lam), float(err)
    except (TypeError, ValueError):
        return head + "lambda1 not computed"
    if math.isnan(lam):
        return head + "lambda1 not computed (NaN)"
    if lam == -math.inf:
        return head + "lambda1 = -inf /s: perturbations are annihilated (sticking), not chaos"
    per = None if period is None or (isinstance(period, float) and math.isnan(period)) \
        else int(period)
    if motion is None or int(motion) == 0:
        motion = classify(lam, err, per if per is not None else 0)
    verdict = VERDICTS.get(int(motion), "unknown")
    if err == 0.0 and per is not None and per > 0:  # a periodic point's Floquet lambda1
        return head + (f"lambda1 = {fmt(lam, 4)} /s = ln|mu_1| / (p T) of the leading Floquet "
                       f"multiplier: {verdict}")
    val = f"lambda1 = {_pm(lam, err)} /s"
    if not err > 0 or not math.isfinite(err):
        return head + f"{val} (no error estimate): {verdict}"
    z = lam / err
    if lam > N_SIGMA * err:
        rel = f"> 0 ({z:.1f} errors)"
        word = "chaotic" if int(motion) == CHAOTIC else verdict
    elif abs(lam) <= N_SIGMA * err:
        rel = f"within {N_SIGMA:g} errors of 0"
        word = ("periodic (a neutral direction)" if per is not None and per > 0 else
                "quasi-periodic or a long transient; chaos is not shown by lambda1")
    else:
        rel = f"< 0 ({-z:.1f} errors)"
        word = ("periodic" if per is not None and per > 0 else
                "contracting: a period longer than the search or a transient, not chaos")
    return head + f"{val} {rel}: {word}"


def verdict_period(claimed: int, measured) -> str:
    """Claimed period (0 = chaotic) against the detected one."""
    if measured is None:
        return DIFFERS
    return agree_if(int(measured) == int(claimed))


def fmt(x, digits: int = 4) -> str:
    try:
        x = float(x)
    except (TypeError, ValueError):
        return str(x)
    if math.isnan(x):
        return "NaN"
    return f"{x:.{digits}g}"
