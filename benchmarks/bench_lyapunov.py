"""Benchmark: cost of the Lyapunov spectrum (``ns.lyapunov``) against the plain trajectory, and
against the scipy baseline a careful user would write, in the same run.

Case: preset ``table3`` at omega = 0.92 (the chaotic grazing orbit of Fig. 10b), from
X = V = 0, ``--transient`` + ``--periods`` forcing periods (default 1,000 + 10,000). For each
method (``exact``, ``smooth``):

* plain trajectory: ``ns.simulate(..., samples_per_period=1)`` (the method's specialised kernel,
  one stored state per period as a spectrum run keeps) and the generic kernel on the same model
  (``kernels.run(KERNEL_GENERIC, ...)``, one output per period);
* ``ns.lyapunov(params, periods=, transient=, method=)`` (skipped, with a line saying so, while
  it does not exist);
* ratio lyapunov / plain against both plain timings. Targets (issue): <= 2x for ``exact``,
  <= 3x for ``smooth``.

Baseline (``scipy_lyapunov``): the exact non-smooth support model (eta = 0) written for
``solve_ivp(method="DOP853", rtol=1e-10, atol=1e-12)`` with plain-Python right-hand sides,
terminal events and a restart loop per mode (free below X = 1, contact, free above X = 1 after
a separation; the mode at a period start is classified from the state, as the model's
``initial``). Its spectrum is computed as textbook: one step per forcing period T, the base
trajectory and n = 2 trajectories from base + eps q_i (eps = 1e-7, forward differences), tangent
columns (x_i - x_base) / eps, ``numpy.linalg.qr``, sum of log |diag R|, q <- Q; exponents per
unit time = sums / (periods T). It runs ``--baseline-transient`` periods (base only) and
``--baseline-periods`` spectrum periods; its cost for the benchmark's transient + periods is
extrapolated linearly from its time per period (printed as such). Its spectrum is printed next
to ``ns.lyapunov``'s: the orbit is chaotic, so they agree only statistically (standard errors
from batch means); lambda1 + lambda2 = -<xi + xi_s 1_contact> (the trace of the Jacobian; the
saltation matrices of this model have determinant 1) checks both.

Times are CPU seconds of this process (``time.process_time``), best of ``--rounds`` after a
warm-up call (compilation / cache load); the baseline runs once. The last stdout line is one
number: the seconds of ``ns.lyapunov`` for ``exact`` (of the plain ``exact`` trajectory while
``ns.lyapunov`` is missing), for ``../shared/tools/side-by-side``.

Usage::

    python benchmarks/bench_lyapunov.py [--periods 10000] [--transient 1000] [--rounds 3]
                                        [--baseline-periods 1000] [--baseline-transient 50]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.integrate import solve_ivp

import nonsmooth as ns
from common import best_of
from nonsmooth.kernels import Solver, new_state, output_buffers, run
from nonsmooth.models.base import KERNEL_GENERIC

METHODS = ("exact", "smooth")
TARGET = {"exact": 2.0, "smooth": 3.0}  # issue: lyapunov <= TARGET x the plain trajectory
SCIPY = dict(method="DOP853", rtol=1e-10, atol=1e-12)
EPS = 1e-7  # finite-difference step of the baseline's tangent


def case():
    """The benchmark's parameters: Table 3 at omega = 0.92 (chaotic)."""
    return ns.preset("table3").replace(omega=0.92)


# ---- nonsmooth ------------------------------------------------------------------------------
def time_simulate(params, method, periods, transient, rounds):
    """Plain trajectory through ``ns.simulate`` (specialised kernel), one sample per period."""
    def call(periods=periods, transient=transient):
        return ns.simulate(params, periods=periods, transient=transient, method=method,
                           samples_per_period=1)
    call(periods=2, transient=1)  # warm-up: load / compile
    return best_of(rounds, call, time.process_time)[0]  # CPU seconds


def time_generic(params, method, n, rounds):
    """Plain trajectory of ``n`` periods on the generic kernel (the model's ``fns``)."""
    s = Solver(method=method)
    p, opts, fns = params.pack(), s.opts(), s.fns

    def call(n=n):
        status = run(KERNEL_GENERIC, fns, p, opts, new_state(0.0, 0.0), 1, 0, n,
                     *output_buffers(n))
        if status != 0:
            raise RuntimeError(f"generic kernel, {method}: status {status}")
        return status
    call(n=5)  # warm-up: load / compile
    return best_of(rounds, call, time.process_time)[0]  # CPU seconds


def time_lyapunov(lyapunov, params, method, periods, transient, rounds):
    """(best seconds, Dataset) of ``ns.lyapunov``."""
    def call(periods=periods, transient=transient):
        return lyapunov(params, periods=periods, transient=transient, method=method)
    call(periods=10, transient=1)  # warm-up: load / compile
    return best_of(rounds, call, time.process_time)  # CPU seconds


def spectrum_of(ds):
    """(exponents, standard errors or None) read from a ``ns.lyapunov`` Dataset, by variable
    name (``exponent``/``lambda``/``spectrum``...; ``stderr``/``error``...), else (None, None)."""
    names = list(ds.data_vars)
    low = {n: n.lower() for n in names}
    err = [n for n in names if "err" in low[n] or "std" in low[n]]
    val = [n for n in names if n not in err and any(k in low[n] for k in
                                                    ("expon", "lambda", "lyap", "spectrum"))]
    exps = np.atleast_1d(np.asarray(ds[val[0]].values, dtype=float)) if val else None
    errs = np.atleast_1d(np.asarray(ds[err[0]].values, dtype=float)) if err else None
    return exps, errs


def describe(ds) -> list[str]:
    """One line per data variable of a Dataset (small ones with their values)."""
    lines = []
    for name, var in ds.data_vars.items():
        vals = np.asarray(var.values)
        shown = (np.array2string(vals, precision=6, separator=", ") if vals.size <= 8
                 else f"shape {vals.shape}")
        lines.append(f"#   {name} {tuple(var.dims)}: {shown}  ({var.attrs.get('long_name', '')})")
    return lines


def contact_share(params, periods, transient):
    """Fraction of time in contact on the exact trajectory (region 3 at 200 samples per
    period; untimed), for the trace check lambda1 + lambda2 = -<xi + xi_s 1_contact>."""
    ds = ns.simulate(params, periods=periods, transient=transient, method="exact")
    return float((ds["region"].values[1:] == 3).mean())


# ---- scipy baseline -------------------------------------------------------------------------
FREE_BELOW, CONTACT, FREE_ABOVE = 0, 1, 2


class SupportIVP:
    """The exact support model for ``solve_ivp``: X'' + xi X' + omega0^2 X = F0 cos(omega t) in
    free flight; in contact the support adds -(omega_s^2 (X - 1) + xi_s V). Contact starts when
    X crosses 1 upwards, ends when the support force F_s = omega_s^2 (X - 1) + xi_s V falls to
    0 (at X > 1, since xi_s V < 0 there); free flight above X = 1 ends when X falls below 1 or
    when F_s turns positive again (contact resumes). Events are terminal and directional, so a
    restart exactly on the surface just left does not fire again.

    solve_ivp looks for sign changes at step ends only, so a short grazing excursion above X = 1
    inside one step (steps are ~0.3 s, such excursions last a few 0.01 s at omega = 0.92) would
    be missed: free flight below X = 1 therefore also records its apexes (V falling through 0,
    not terminal); an apex above X = 1 means a missed crossing, which lies between the last step
    end before the apex and the apex, where X rises monotonically, and is located by integrating
    that piece again. (The other switches cannot be skipped this way here: at a zero of F_s with
    X > 1, V < 0 and F_s decreases strictly; a free minimum of X near 1 needs F0 >= omega0^2.)"""

    def __init__(self, params, opts=SCIPY):
        w02, ws2 = params.omega0 ** 2, params.omega_s ** 2
        xi, xis, F0, om = params.xi, params.xi_s, params.F0, params.omega
        self.w02, self.ws2, self.xi, self.xis, self.F0, self.om = w02, ws2, xi, xis, F0, om
        self.opts = opts

        def free(t, u):
            X, V = u
            return [V, F0 * math.cos(om * t) - w02 * X - xi * V]

        def contact(t, u):
            X, V = u
            return [V, F0 * math.cos(om * t) - w02 * X - xi * V - ws2 * (X - 1.0) - xis * V]

        def reach(t, u):  # X - 1, crossing upwards: contact starts
            return u[0] - 1.0

        def release(t, u):  # support force, falling to 0: separation
            return ws2 * (u[0] - 1.0) + xis * u[1]

        def fall(t, u):  # X - 1, crossing downwards: back below the support
            return u[0] - 1.0

        def push(t, u):  # support force, rising through 0 above X = 1: contact resumes
            return ws2 * (u[0] - 1.0) + xis * u[1]

        def apex(t, u):  # V, falling through 0: a maximum of X (not terminal)
            return u[1]

        for g, d in ((reach, 1), (release, -1), (fall, -1), (push, 1), (apex, -1)):
            g.terminal, g.direction = g is not apex, d
        self.rhs = {FREE_BELOW: free, CONTACT: contact, FREE_ABOVE: free}
        self.events = {FREE_BELOW: [reach, apex], CONTACT: [release], FREE_ABOVE: [fall, push]}
        self.reach = reach

    def classify(self, t, u) -> int:
        """The mode of a state (as the model's ``initial``): contact iff X > 1 and F_s > 0, or
        X = 1 moving up, or X > 1, F_s = 0 and F_s rising in free flight."""
        X, V = u
        Fs = self.ws2 * (X - 1.0) + self.xis * V
        if (X > 1.0 and Fs > 0.0) or (X == 1.0 and V > 0.0):
            return CONTACT
        if X > 1.0 and Fs == 0.0:
            A = self.F0 * math.cos(self.om * t) - self.w02 * X - self.xi * V
            if self.ws2 * V + self.xis * A > 0.0:
                return CONTACT
        return FREE_ABOVE if X > 1.0 else FREE_BELOW

    def transition(self, mode, k, u) -> int:
        """The mode after event ``k`` of ``mode`` at state ``u``."""
        X, V = u
        if mode == FREE_BELOW:  # reached X = 1 moving up (V = 0: grazing touch, no contact)
            return CONTACT if V > 0.0 else FREE_ABOVE
        if mode == CONTACT:  # the support force vanished
            return FREE_ABOVE if X > 1.0 else FREE_BELOW
        if k == 1 and X > 1.0:  # free above: the support force turns positive again
            return CONTACT
        return FREE_BELOW  # free above: X fell below 1

    def crossing_before(self, sol, ta):
        """A solve_ivp result ending at the crossing of X = 1 missed before the apex at
        ``ta`` (X < 1 at the step end before it, X rises monotonically up to ``ta``)."""
        j = int(np.searchsorted(sol.t, ta)) - 1
        sub = solve_ivp(self.rhs[FREE_BELOW], (sol.t[j], ta), sol.y[:, j], events=[self.reach],
                        **self.opts)
        if sub.status != 1:
            raise RuntimeError(f"no crossing of X = 1 before the apex at t = {ta:.6g}")
        return sub

    def flow(self, t0, t1, u):
        """State at ``t1`` from ``u`` at ``t0``: (state, time in contact, events)."""
        t, u = t0, np.asarray(u, dtype=float)
        mode = self.classify(t, u)
        in_contact, n_ev, stuck = 0.0, 0, 0
        while True:
            sol = solve_ivp(self.rhs[mode], (t, t1), u, events=self.events[mode], **self.opts)
            if sol.status == -1:
                raise RuntimeError(f"solve_ivp failed at t = {t:.6g}: {sol.message}")
            if mode == FREE_BELOW:
                missed = [ta for ta, ya in zip(sol.t_events[1], sol.y_events[1]) if ya[0] > 1.0]
                if missed:  # a grazing contact skipped inside a step: locate its start
                    sol = self.crossing_before(sol, missed[0])
            if sol.status == 0:  # reached t1
                if mode == CONTACT:
                    in_contact += t1 - t
                return sol.y[:, -1], in_contact, n_ev
            k = next(i for i, te in enumerate(sol.t_events)  # the terminal event
                     if len(te) and self.events[mode][i].terminal)
            te, u = float(sol.t_events[k][0]), np.array(sol.y_events[k][0], dtype=float)
            if mode == CONTACT:
                in_contact += te - t
            stuck = stuck + 1 if te - t < 1e-12 * max(1.0, abs(te)) else 0
            if stuck > 50:
                raise RuntimeError(f"no progress at t = {te:.6g} (repeated events)")
            mode, t, n_ev = self.transition(mode, k, u), te, n_ev + 1


def scipy_lyapunov(params, periods, transient, eps=EPS, batches=10):
    """The baseline: Lyapunov spectrum by finite-difference tangents and QR once per period.

    Returns a dict: exponents and their standard errors (batch means over ``batches``), contact
    share, events per period, CPU seconds per period of the transient (base trajectory only) and
    of the spectrum (base + 2 perturbed trajectories, QR)."""
    ivp = SupportIVP(params)
    T = 2.0 * math.pi / params.omega
    u = np.zeros(2)
    c0 = time.process_time()
    for k in range(transient):
        u = ivp.flow(k * T, (k + 1) * T, u)[0]
    c1 = time.process_time()
    q = np.eye(2)
    logs = np.empty((periods, 2))
    contact, events = 0.0, 0
    for k in range(transient, transient + periods):
        t0, t1 = k * T, (k + 1) * T
        base, share, n_ev = ivp.flow(t0, t1, u)
        contact, events = contact + share, events + n_ev
        tangent = np.empty((2, 2))
        for i in range(2):  # forward differences along the current orthonormal directions
            tangent[:, i] = (ivp.flow(t0, t1, u + eps * q[:, i])[0] - base) / eps
        q, r = np.linalg.qr(tangent)
        logs[k - transient] = np.log(np.abs(np.diag(r)))
        u = base
    c2 = time.process_time()
    exps = logs.sum(axis=0) / (periods * T)
    nb = max(2, min(batches, periods // 2))
    means = np.array([b.mean(axis=0) for b in np.array_split(logs, nb)]) / T
    errs = means.std(axis=0, ddof=1) / math.sqrt(nb)
    return dict(exponents=exps, stderr=errs, contact=contact / (periods * T),
                events=events / periods, transient_s=(c1 - c0) / max(transient, 1),
                period_s=(c2 - c1) / periods)


# ---- report ---------------------------------------------------------------------------------
def fmt_spectrum(exps, errs) -> str:
    if exps is None:
        return "(no spectrum variable found)"
    parts = []
    for i, lam in enumerate(exps):
        e = "" if errs is None or i >= len(errs) else f" +- {errs[i]:.2g}"
        parts.append(f"lambda{i + 1} = {lam:+.5f}{e}")
    return ", ".join(parts) + f"; sum = {float(np.sum(exps)):+.5f}"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--periods", type=int, default=10_000, help="spectrum periods")
    ap.add_argument("--transient", type=int, default=1_000, help="transient periods")
    ap.add_argument("--rounds", type=int, default=3, help="timed nonsmooth runs (best kept)")
    ap.add_argument("--baseline-periods", type=int, default=1000,
                    help="spectrum periods of the scipy baseline (then extrapolated)")
    ap.add_argument("--baseline-transient", type=int, default=50,
                    help="transient periods of the scipy baseline (base trajectory only)")
    args = ap.parse_args(argv)

    params = case()
    n = args.transient + args.periods
    lyapunov = getattr(ns, "lyapunov", None)
    print(f"# table3, omega = {params.omega}: {args.transient} transient + {args.periods} "
          f"periods from X = V = 0; CPU seconds, best of {args.rounds} after a warm-up")
    if lyapunov is None:
        print("# ns.lyapunov not available yet: its columns are skipped")

    rows, spectra, last = [], {}, math.nan
    for method in METHODS:
        plain = time_simulate(params, method, args.periods, args.transient, args.rounds)
        generic = time_generic(params, method, n, args.rounds)
        lyap = math.nan
        if lyapunov is not None:
            lyap, ds = time_lyapunov(lyapunov, params, method, args.periods, args.transient,
                                     args.rounds)
            spectra[method] = ds
        rows.append((method, plain, generic, lyap))
        if method == "exact":
            last = plain if lyapunov is None else lyap

    base = scipy_lyapunov(params, args.baseline_periods, args.baseline_transient)
    base_s = base["transient_s"] * args.transient + base["period_s"] * args.periods

    print(f"# baseline: scipy solve_ivp {SCIPY['method']} rtol {SCIPY['rtol']:g} atol "
          f"{SCIPY['atol']:g}, events, finite-difference tangent (eps {EPS:g}), QR each period; "
          f"measured over {args.baseline_transient} + {args.baseline_periods} periods: "
          f"{base['transient_s'] * 1e3:.2f} ms per transient period (base only), "
          f"{base['period_s'] * 1e3:.2f} ms per spectrum period (3 trajectories + QR), "
          f"{base['events']:.2f} events per period on the base trajectory")
    print(f"# baseline s below = EXTRAPOLATED linearly to {args.transient} + {args.periods} "
          f"periods: {base['transient_s']:.4g} s x {args.transient} + {base['period_s']:.4g} s "
          f"x {args.periods}")
    print(f"{'method':7s} {'simulate_s':>10s} {'generic_s':>10s} {'lyapunov_s':>10s} "
          f"{'lyap/sim':>9s} {'lyap/gen':>9s} {'target':>7s} {'baseline_s':>11s} "
          f"{'speed-up':>9s}")
    for method, plain, generic, lyap in rows:
        if math.isnan(lyap):  # ns.lyapunov missing
            cols = f"{'n/a':>10s} {'n/a':>9s} {'n/a':>9s}"
            speedup = f"{'n/a':>9s}"
        else:
            cols = f"{lyap:10.4f} {lyap / plain:8.2f}x {lyap / generic:8.2f}x"
            speedup = f"{base_s / lyap:8.0f}x"
        print(f"{method:7s} {plain:10.4f} {generic:10.4f} {cols} {TARGET[method]:6.1f}x "
              f"{base_s:11.1f} {speedup}")

    # Spectra side by side; the trace check uses the contact share of each trajectory.
    xi, xis = params.xi, params.xi_s
    print("# spectrum per unit time (chaotic orbit: agreement is statistical only)")
    print(f"# baseline ({args.baseline_periods} periods): "
          f"{fmt_spectrum(base['exponents'], base['stderr'])}; "
          f"-<xi + xi_s 1_contact> = {-(xi + xis * base['contact']):+.5f} "
          f"(contact share {base['contact']:.4f})")
    if spectra:
        share = contact_share(params, args.periods, args.transient)
        for method, ds in spectra.items():
            exps, errs = spectrum_of(ds)
            print(f"# ns.lyapunov {method} ({args.periods} periods): {fmt_spectrum(exps, errs)}; "
                  f"-<xi + xi_s 1_contact> = {-(xi + xis * share):+.5f} (contact share "
                  f"{share:.4f}, exact trajectory, 200 samples per period)")
            print(f"# ns.lyapunov {method} Dataset variables:")
            print("\n".join(describe(ds)))
    print(f"{last:.4f}")  # last line: seconds of ns.lyapunov exact (plain exact if missing)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
