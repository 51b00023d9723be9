"""Benchmark: forcing periods per second of every built-in model and method, nonsmooth against
scipy ``solve_ivp`` on the SAME model.

For each built-in model (``support``, ``two_sided``, ``impact``, ``stick_slip``,
``bouncing_ball``, ``impact_2dof``, ``jeffcott_rotor``; a model whose module does not exist yet is skipped) and each method (``smooth``, ``exact``), one trajectory
from X = V = 0:

* nonsmooth: ``Solver(model=m, method=...)`` through ``kernels.run`` (the model's specialised
  kernel for ``support``, the generic kernel otherwise), after a warm-up call that loads or
  compiles it; thousands of forcing periods;
* scipy: ``solve_ivp`` with a Python event loop on the model's own compiled functions
  (``model.fns(method)``: ``call_guards``, ``call_transition``, ``call_initial`` of
  :mod:`nonsmooth.models._probe`; the field through a small ``njit`` wrapper of the same
  compiled ``field``, because ``_probe.call_field`` spends ~130 us per call typing the ``fns``
  tuple, ~100x the field itself, which would inflate the ratios), so both sides integrate
  exactly the same vector fields, switching surfaces and transitions: integrate in a mode
  with the mode's guards as terminal events (g_k = G[k, :n] . u + G[k, n]
  + G[k, n+1] cos(omega t) + G[k, n+2] sin(omega t), or the model's ``curved`` function for a
  curved row, left when one turns negative), apply the
  model's transition at the located event, continue in the new mode. RK45 at rtol 1e-8,
  atol 1e-10 (as ours) for ``smooth``; DOP853 at rtol 1e-10, atol 1e-12 for ``exact``; tens of
  forcing periods.

Rates are CPU seconds of this process (single-threaded on both sides), best of ``--repeat``.
Targets (issue): >= 200x for smooth, >= 1000x for exact where the modes are linear (closed
form). The last stdout line is one number: the total nonsmooth seconds of the timed part (for
``../shared/tools/side-by-side``).

Usage::

    python benchmarks/bench_models.py [--periods 4000] [--scipy-periods 30] [--repeat 3]
                                      [--models support,stick_slip] [--methods smooth]
"""

from __future__ import annotations

import argparse
import importlib
import math
import time

import numba as nb
import numpy as np
from scipy.integrate import solve_ivp

import nonsmooth as ns
from nonsmooth import kernels
from nonsmooth.integrate.contract import MAX_GUARDS
from nonsmooth.integrate.pwlinear import N_MC

try:  # (a tree before 6fd7526, run side by side: general rows all on the series)
    from nonsmooth.integrate.hybrid import _oscillator
except ImportError:
    _oscillator = None
try:  # (a tree before the drift's closed form)
    from nonsmooth.integrate.hybrid import _drift
except ImportError:
    _drift = None
from nonsmooth.models import BUILTIN
from nonsmooth.models._probe import call_guards, call_initial, call_linear, call_transition

#: Parameters per model where it actually switches every period (or nearly).
CASES = (
    ("support", lambda m: ns.preset("table3"),
     "table3 (omega = 0.91): contact with the support every period"),
    ("two_sided", lambda m: m.preset("table3"),
     "table3 supports on both sides, gaps 1: both supports reached"),
    ("impact", lambda m: m.params(F0=0.5, omega=0.8, r=0.8),
     "F0 = 0.5, omega = 0.8, r = 0.8: impacts every period"),
    ("stick_slip", lambda m: m.params(),
     "defaults: unforced stick-slip cycle (omega = omega0)"),
    ("stick_slip", lambda m: m.params(omega=0.95),
     "defaults, omega = 0.95: stick-slip cycle, Coulomb slip in closed form"),
    ("bouncing_ball", lambda m: m.preset("period_one"),
     "Gamma = 1.3 from Z = V = 0: an orbit that chatters (some 26 impacts) and rides on the "
     "table once per period (free flight in closed form)"),
    ("impact_2dof", lambda m: m.params(),
     "defaults: one impact per period, four states (closed form between impacts)"),
    ("jeffcott_rotor", lambda m: m.preset("partial_rub"),
     "partial_rub: two crossings of the clearance circle per turn (a curved guard), four "
     "states"),
)

SCIPY = {"smooth": dict(method="RK45", rtol=1e-8, atol=1e-10),
         "exact": dict(method="DOP853", rtol=1e-10, atol=1e-12)}
#: a method solved to about 1e-12 (support's smooth_closed_form) against the exact reference
SCIPY["smooth_closed_form"] = SCIPY["exact"]


def available(name: str) -> bool:
    try:
        importlib.import_module(BUILTIN[name])
        return True
    except ImportError:
        return False


# ---- nonsmooth ------------------------------------------------------------------------------
def rate_nonsmooth(model, params, method, periods, repeat):
    """(periods/s best of ``repeat``, seconds of the best run, status)."""
    solver = kernels.Solver(model=model, method=method)
    p = params.pack()
    code, fns, opts = solver.code, solver.fns, solver.opts()
    kernels.run(code, fns, p, opts, kernels.new_state(0.0, 0.0), 1, 0, 5,
                *kernels.output_buffers(5))  # warm-up: load / compile
    best, status = math.inf, 0
    for _ in range(repeat):
        st = kernels.new_state(0.0, 0.0)
        buf = kernels.output_buffers(periods)
        t0 = time.process_time()
        status = kernels.run(code, fns, p, opts, st, 1, 0, periods, *buf)
        best = min(best, time.process_time() - t0)
    return periods / best, best, int(status)


# ---- scipy on the same model ----------------------------------------------------------------
def _field_caller(field_cfunc):
    """An njit entry calling the model's compiled ``field`` (about 1 us from Python)."""
    field_cfunc = getattr(field_cfunc, "cfunc", field_cfunc)  # a CompiledFunction wraps it

    @nb.njit
    def call(mode, t, c, s, u, p, mem, du):
        return field_cfunc(mode, t, c, s, u, p, mem, du)

    return call


def _curved_caller(curved_cfunc):
    """An njit entry calling the model's compiled ``curved`` guard function."""
    curved_cfunc = getattr(curved_cfunc, "cfunc", curved_cfunc)

    @nb.njit
    def call(mode, k, t, c, s, u, p, mem, grad):
        return curved_cfunc(mode, k, t, c, s, u, p, mem, grad)

    return call


def propagation(model, params, method) -> str:
    """How the method's modes are propagated: closed form for those ``linear`` declares at
    these parameters, else the RKF45."""
    m = model.method(method)
    if not m.closed_form:
        return "RKF45"
    n = model.n
    fns, p, out = model.fns(method), params.pack(), np.zeros(max(4, n * n + 3 * n))
    modes = m.modes or tuple(range(len(model.mode_names)))
    om = 2 * math.pi / params.period if params.period else None

    def kind(r):  # a general row (2) of the oscillator's form takes its formulas, as in the kernel
        if r == 2 and n == 2 and om and _oscillator and _oscillator(out, om, np.zeros(N_MC)):
            return "oscillator"
        if r == 2 and n == 2 and _drift and _drift(out):
            return "drift"
        return {1: "oscillator", 2: "series"}.get(r)

    closed = [f"{model.mode_names[k]} ({w})" for k in modes
              if (w := kind(int(call_linear(fns, k, p, out))))]
    return f"closed form in {', '.join(closed)}" if closed else "RKF45 (no linear mode)"


class SameModel:
    """The model's compiled functions called from Python, for ``solve_ivp``."""

    def __init__(self, model, params, method):
        self.fns = model.fns(method)
        self.n = model.n
        self.p = params.pack()
        self.om = float(self.p[model.index[model.omega]])
        self.mem = np.zeros(max(1, model.n_memory))
        self.G = np.zeros((MAX_GUARDS, self.n + 3))
        self.du = np.zeros(self.n)
        self.call_field = _field_caller(self.fns[0])
        self.call_field(0, 0.0, 1.0, 0.0, np.zeros(self.n), self.p, self.mem, self.du)  # compile
        self.call_curved = _curved_caller(self.fns[6])
        self.grad = np.zeros(self.n + 1)

    def guard(self, mode, k, row, t, u):
        """Guard k (``row`` of G) at (t, u): affine, or the model's curved function."""
        n, om = self.n, self.om
        c, s = math.cos(om * t), math.sin(om * t)
        if math.isnan(row[n]):
            return float(self.call_curved(mode, k, t, c, s, u, self.p, self.mem, self.grad))
        return float(row[:n] @ u[:n] + row[n] + row[n + 1] * c + row[n + 2] * s)

    def field(self, mode):
        p, mem, du, om, call_field = self.p, self.mem, self.du, self.om, self.call_field

        def rhs(t, u):
            call_field(mode, t, math.cos(om * t), math.sin(om * t), u, p, mem, du)
            return du.copy()

        return rhs

    def events(self, mode, t0, u0):
        """The mode's guards as terminal events (leaving: g decreasing through 0). As in the
        kernel's exit test, a guard a round-off below 0 at the start (entered on its border)
        counts from 0 and the exit needs g < 0 strictly (a guard that stays at 0, e.g. the
        band edge of a frozen velocity, is no exit): g is shifted up by 1e-14 of its scale,
        since solve_ivp also fires on g = 0."""
        ng = int(call_guards(self.fns, mode, self.p, self.mem, self.G))
        rows = self.G[:ng].copy()
        n, om = self.n, self.om
        out = []
        for k in range(ng):
            if math.isnan(rows[k, n]):  # a curved guard: from 0 if a round-off below
                g0 = self.guard(mode, k, rows[k], t0, u0)
                shift = -min(g0, 0.0) + 1e-14 * max(abs(g0), 1e-300)

                def gc(t, u, k=k, row=rows[k], shift=shift):
                    return self.guard(mode, k, row, t, u) + shift

                gc.terminal = True
                gc.direction = -1
                out.append(gc)
                continue
            a, b, cc, ss = rows[k, :n], rows[k, n], rows[k, n + 1], rows[k, n + 2]
            g0 = float(a @ u0[:n] + b + cc * math.cos(om * t0) + ss * math.sin(om * t0))
            scale = float(np.abs(a) @ np.abs(u0[:n]) + abs(b) + abs(cc) + abs(ss))
            b = b - min(g0, 0.0) + 1e-14 * max(scale, 1e-300)

            def g(t, u, a=a, b=b, cc=cc, ss=ss):
                return float(a @ u[:n] + b + cc * math.cos(om * t) + ss * math.sin(om * t))

            g.terminal = True
            g.direction = -1
            out.append(g)
        return out

    def immediate_exit(self, mode, t, u) -> int:
        """The first guard with g <= 0 and g' < 0 at (t, u) (-1 if none): a mode entered on
        one of its borders and left at once (solve_ivp sees no sign change there)."""
        ng = int(call_guards(self.fns, mode, self.p, self.mem, self.G))
        n, om = self.n, self.om
        c, s = math.cos(om * t), math.sin(om * t)
        f = self.field(mode)(t, u)
        for k in range(ng):
            row = self.G[k]
            if math.isnan(row[n]):
                g = self.guard(mode, k, row, t, u)
                dg = float(self.grad[:n] @ f + self.grad[n])
            else:
                g = row[:n] @ u + row[n] + row[n + 1] * c + row[n + 2] * s
                dg = row[:n] @ f - row[n + 1] * om * s + row[n + 2] * om * c
            if g <= 0.0 and dg < 0.0:
                return k
        return -1

    def integrate(self, t_end, opts, max_events=1_000_000):
        """Integrate from X = V = 0 at t = 0 to ``t_end``; returns (events, nfev)."""
        u = np.zeros(self.n)
        self.mem[:] = 0.0
        mode = int(call_initial(self.fns, 1.0, 0.0, u, self.p, self.mem))
        t, n_ev, nfev, stuck = 0.0, 0, 0, 0
        while t < t_end:
            k = self.immediate_exit(mode, t, u)
            if k >= 0:  # as the kernel: g <= 0 and g' < 0 at the start leaves at once
                c, s = math.cos(self.om * t), math.sin(self.om * t)
                mode = int(call_transition(self.fns, mode, k, t, c, s, u, self.p, self.mem))
                stuck += 1
                if stuck > 50:
                    raise RuntimeError(f"no progress at t = {t:.6g} (repeated events)")
                n_ev += 1
                continue
            # a guard with forcing terms (a time-dependent surface) can dip below zero and come
            # back inside one long step (a zero field, e.g. a ball resting on its table, lets
            # the steps grow without bound): steps of at most T/8 see every such dip
            ng = int(call_guards(self.fns, mode, self.p, self.mem, self.G))
            timed = bool(np.any(self.G[:ng, self.n + 1:self.n + 3] != 0.0))
            kw = dict(opts, max_step=math.pi / (4.0 * self.om)) if timed else opts
            sol = solve_ivp(self.field(mode), (t, t_end), u, events=self.events(mode, t, u), **kw)
            nfev += sol.nfev
            if sol.status == -1:
                raise RuntimeError(f"solve_ivp failed: {sol.message}")
            if sol.status != 1:
                u = sol.y[:, -1].copy()
                break
            hits = [(te[0], k, ye[0]) for k, (te, ye) in enumerate(zip(sol.t_events, sol.y_events))
                    if len(te)]
            te, k, ye = min(hits)
            u = np.array(ye, dtype=float)
            c, s = math.cos(self.om * te), math.sin(self.om * te)
            mode = int(call_transition(self.fns, mode, k, te, c, s, u, self.p, self.mem))
            stuck = stuck + 1 if te - t < 1e-12 * max(1.0, te) else 0
            if stuck > 50:
                raise RuntimeError(f"no progress at t = {te:.6g} (repeated events)")
            t = te
            n_ev += 1
            if n_ev > max_events:
                raise RuntimeError("too many events")
        return n_ev, nfev, u


def rate_scipy(model, params, method, periods, repeat):
    """(periods/s best of ``repeat``, events, nfev) of the scipy event loop."""
    same = SameModel(model, params, method)
    t_end = periods * 2.0 * math.pi / same.om
    # an untimed period first: it compiles the curved-guard caller (jeffcott_rotor: about
    # 0.15 s, which a single timed run of 10 periods counted as scipy's, 1.8-3x its time, up
    # to 2026-11-30) and loads the probes of ``_probe`` from numba's cache
    same.integrate(2.0 * math.pi / same.om, SCIPY[method])
    best, n_ev, nfev = math.inf, 0, 0
    for _ in range(repeat):
        t0 = time.process_time()
        n_ev, nfev, _ = same.integrate(t_end, SCIPY[method])
        best = min(best, time.process_time() - t0)
    return periods / best, n_ev, nfev


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--periods", type=int, default=4000, help="forcing periods, nonsmooth")
    ap.add_argument("--scipy-periods", type=int, default=30, help="forcing periods, scipy")
    ap.add_argument("--repeat", type=int, default=3, help="nonsmooth runs (best is kept)")
    ap.add_argument("--scipy-repeat", type=int, default=1, help="scipy runs (best is kept)")
    ap.add_argument("--models", default=",".join(BUILTIN), help="comma-separated model names")
    ap.add_argument("--methods", default="smooth,exact", help="comma-separated methods")
    args = ap.parse_args(argv)
    wanted = [m.strip() for m in args.models.split(",") if m.strip()]

    rows, total = [], 0.0
    for name, make, note in CASES:
        if name not in wanted:
            continue
        if not available(name):
            print(f"# {name}: module {BUILTIN[name]} not available yet, skipped")
            continue
        model = ns.model(name)
        params = make(model)
        for method in args.methods.split(","):
            if method not in model.methods:
                continue
            ours, secs, status = rate_nonsmooth(model, params, method, args.periods, args.repeat)
            total += secs
            try:
                ref, n_ev, nfev = rate_scipy(model, params, method, args.scipy_periods,
                                             args.scipy_repeat)
                ref_note = f"{n_ev} events, nfev {nfev}"
            except Exception as exc:  # noqa: BLE001 - reported in the table
                ref, ref_note = math.nan, f"scipy failed: {exc}"
            how = propagation(model, params, method)
            target = 200 if method == "smooth" else 1000
            rows.append((name, method, ours, ref, ours / ref, target, status,
                         f"{note}; {how}; {ref_note}"))

    scipy_name = {m: f"{o['method']} {o['rtol']:g}" for m, o in SCIPY.items()}
    print(f"nonsmooth: {args.periods} periods (best of {args.repeat}); scipy: "
          f"{args.scipy_periods} periods, event loop on the model's own functions "
          f"(smooth: {scipy_name['smooth']}, exact: {scipy_name['exact']}); CPU seconds")
    print(f"{'model':11s} {'method':7s} {'nonsmooth/s':>12s} {'scipy/s':>10s} {'ratio':>9s} "
          f"{'target':>7s} {'status':>6s}  note")
    for name, method, ours, ref, ratio, target, status, note in rows:
        print(f"{name:11s} {method:7s} {ours:12.4g} {ref:10.4g} {ratio:8.0f}x {target:6d}x "
              f"{status:6d}  {note}")
    print(f"{total:.4f}")  # last line: total nonsmooth seconds of the timed part
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
