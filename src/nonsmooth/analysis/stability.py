"""Stability and chaos of any model: Lyapunov spectra (Benettin) and periodic orbits, stable or
unstable, by Newton shooting with Floquet multipliers.

Both rest on the tangent kernel (``integrate.hybrid.advance_tangent``, driven through
:mod:`nonsmooth.tangent`): tangent vectors follow the variational equation of each mode (the
model's Jacobian; the mode's propagator in closed form for the exact method's linear modes)
and jump by the saltation matrix at every switch, reset (impact) and stick/slip transition, so
the numbers are the derivatives of the non-smooth flow, not of a smoothed substitute.

Tangent space: the state u (n components) and the continuous memory of the method (the
smoothed support model's eq. 13a entry velocity): N = n + n_cm. Lyapunov exponents are those
of the n state perturbations; Floquet multipliers are the eigenvalues of the monodromy of the
section point's active coordinates: u, and the memory slots the orbit reads before rewriting
them (the entry velocity counts only when the section point lies inside Sigma_alpha).
"""

from __future__ import annotations

import dataclasses
import math

import numba as nb
import numpy as np
import xarray as xr

from .. import status as st
from ..checks import check_positive
from ..errors import IntegrationError
from ..integrate.contract import OPT_NO_EXTREMA, ST_H, ST_MODE
from ..io import apply_state_units, check_memory, provenance_attrs, state_long_name
from ..kernels import mode_holds, output_buffers, run, tangent_function
from ..models.base import KERNEL_GENERIC
from ..simulate import (check_int, component_variables, start_attrs, start_trajectory,
                        state_u)
from ..tangent import TangentSetup, period_map

#: Lyapunov verdicts (CF flag values of ``lyapunov_class``).
PERIODIC, QUASI_PERIODIC, CHAOTIC, NOT_SETTLED = 1, 2, 3, 4
VERDICTS = {0: "unknown", PERIODIC: "periodic", QUASI_PERIODIC: "quasi-periodic",
            CHAOTIC: "chaotic", NOT_SETTLED: "not settled"}
#: A nonzero lambda1 must exceed this many standard errors.
N_SIGMA = 3.0
#: |mu| within this of 1 is neutral (e.g. the time shift of an unforced limit cycle).
NEUTRAL = 1e-6
#: A converged orbit integrated again (other steps) must close to this (relative to 1 + |z|).
CONFIRM_TOL = 1e-6
_ORBIT_SAMPLE_BYTES = 40.0  # X, V, mode, bounds of one orbit sample (with their copies)
ALIGN = 100  # periods of the transient that also carry the tangent vectors (alignment)
_SLICE = 2000  # periods per kernel call (progress and Ctrl-C between calls)


def classify(lambda1: float, error: float, period: int = 0) -> int:
    """Verdict from lambda1 (per unit time) with its standard error and the detected period
    (> 0 periodic, 0 none, -1 not settled; None: not looked for): periodic when a period was
    found (then lambda1 < 0 beyond its error, or a neutral orbit); chaotic when lambda1 > 0
    beyond ``N_SIGMA`` errors; quasi-periodic when lambda1 is within ``N_SIGMA`` errors of 0;
    for lambda1 < 0 beyond its error: periodic when no period was looked for (a contracting
    attractor of the period map is a periodic orbit), else not settled (no period found: a
    periodic orbit longer than the period search, or a transient)."""
    if period is not None and period > 0:
        return PERIODIC
    if not (math.isfinite(lambda1) and math.isfinite(error)):
        return NOT_SETTLED if lambda1 == -math.inf else 0
    if lambda1 > N_SIGMA * error:
        return CHAOTIC
    if abs(lambda1) <= N_SIGMA * error:
        return QUASI_PERIODIC
    return PERIODIC if period is None else NOT_SETTLED


def block_error(logs: np.ndarray, blocks: int) -> np.ndarray:
    """Standard error of the mean of per-period growth logs (periods x n) from ``blocks``
    consecutive block means (per period)."""
    n = logs.shape[0]
    b = max(2, min(blocks, n))
    size = n // b
    if size < 1:
        return np.full(logs.shape[1], np.nan)
    means = logs[: b * size].reshape(b, size, -1).mean(axis=1)
    with np.errstate(invalid="ignore"):
        return means.std(axis=0, ddof=1) / math.sqrt(b)


def _checkpoints(periods: int, n_max: int = 500) -> np.ndarray:
    """Period counts at which the running estimate is stored (about n_max, geometric)."""
    pts = np.unique(np.geomspace(1, periods, min(n_max, periods)).astype(np.int64))
    return pts


def lyapunov(params, *, periods: int = 10000, transient: int = 1000, x0: float = 0.0,
             v0: float = 0.0, method: str = "smooth", rtol: float = 1e-8, atol: float = 1e-10,
             blocks: int = 20, progress=None, section_phase: float = 0.0,
             u0=None) -> xr.Dataset:
    """Lyapunov spectrum of the trajectory from (x0, v0) (or from ``u0``, every component, see
    ``simulate``), any model.

    The trajectory first runs ``transient`` forcing periods (the last ``ALIGN`` of them with
    the tangent vectors, so that they are aligned when recording starts); then the n tangent
    vectors of the state are propagated over ``periods`` periods (variational equations and
    saltation matrices, :mod:`nonsmooth.tangent`) and re-orthonormalised by QR at every
    period end (Benettin's method): lambda_i = (1 / (periods T)) sum_k log R_ii(k).

    Returns a Dataset with ``exponent`` (per unit time) and ``exponent_per_period`` (times T)
    over the coordinate ``i`` = 1..n, ``stderr`` (standard error of ``exponent`` from
    ``blocks`` block means; a strongly correlated chaotic signal needs long blocks), the
    ``running`` estimate at ~500 checkpoints (``period``), ``lambda1``, ``lambda1_stderr``,
    ``exponent_sum`` and ``lyapunov_class`` (1 periodic: lambda1 < 0 beyond its error, 2
    quasi-periodic: within its error of 0, 3 chaotic: > 0 beyond it; :func:`classify`).
    Exponents of -inf mean that perturbations are annihilated (sticking, impacts with
    r = 0).
    ``progress`` (None or False: silent; True: a progress bar with a time estimate on a terminal,
    plain lines elsewhere; or a callable ``progress(done, total)``): reports the work done.
    """
    from ..sweep import progress_callback
    progress = progress_callback(progress, "lyapunov")
    params, solver, p, opts, state = start_trajectory(params, x0, v0, method, rtol, atol,
                                                      section_phase, u0)
    u_start = state_u(params.model, state)
    periods = check_int("periods", periods, 1)
    transient = check_int("transient", transient, 0)
    blocks = check_int("blocks", blocks, 2)
    setup = TangentSetup(solver)
    n, N = setup.n, setup.N
    check_memory(8.0 * periods * (n + 2), "periods", "compute fewer periods (the log of every "
                 "period's growth is kept for the error estimate)", size=(periods, 1))
    T = params.period
    total = transient + periods
    done = 0

    def tick(k):
        nonlocal done
        done += k
        if progress is not None:
            progress(done, total)

    plain = max(0, transient - ALIGN)
    while done < plain:  # transient without tangent vectors
        k = min(_SLICE, plain - done)
        bufs = output_buffers(0)
        code = run(KERNEL_GENERIC, setup.fns, p, opts, state, 1, k, 0, *bufs)
        if code != st.OK:
            raise IntegrationError(f"lyapunov: transient failed after {done} periods: "
                                   f"{st.message(code)}")
        tick(k)
    Y = np.ascontiguousarray(np.eye(N)[:, :n])
    align = transient - plain
    if align:
        code, _ = setup.run(p, state, 0, Y, np.zeros((0, n)), transient=align)
        if code != st.OK:
            raise IntegrationError(f"lyapunov: transient failed after {done} periods: "
                                   f"{st.message(code)}")
        tick(align)
    logs = np.empty((periods, n))
    k0 = 0
    while k0 < periods:
        k = min(_SLICE, periods - k0)
        code, _ = setup.run(p, state, k, Y, logs[k0:k0 + k])
        if code != st.OK:
            raise IntegrationError(f"lyapunov: integration failed after {transient + k0} "
                                   f"periods: {st.message(code)}")
        k0 += k
        tick(k)
    with np.errstate(invalid="ignore"):
        per_period = logs.mean(axis=0)
        err = block_error(logs, blocks) / T
        cum = np.cumsum(logs, axis=0)
    expo = per_period / T
    pts = _checkpoints(periods)
    running = cum[pts - 1] / (pts[:, None] * T)
    l1, e1 = float(expo[0]), float(err[0])
    cls = classify(l1, e1, None)
    i = np.arange(1, n + 1)
    ds = xr.Dataset(
        {
            "exponent": ("i", expo, {"long_name": "Lyapunov exponent", "units": "1/s"}),
            "exponent_per_period": ("i", per_period, {
                "long_name": "Lyapunov exponent per forcing period (exponent x T)",
                "units": "1"}),
            "stderr": ("i", err, {"long_name": f"standard error of the exponent "
                                               f"({max(2, min(blocks, periods))} block means)",
                                  "units": "1/s"}),
            "running": (("period", "i"), running, {
                "long_name": "running estimate of the exponents", "units": "1/s"}),
            "lambda1": ((), l1, {"long_name": "largest Lyapunov exponent", "units": "1/s"}),
            "lambda1_stderr": ((), e1, {"long_name": "standard error of lambda1",
                                        "units": "1/s"}),
            "exponent_sum": ((), float(expo.sum()), {
                "long_name": "sum of the exponents (time average of the divergence, saltation "
                             "included)", "units": "1/s"}),
            "lyapunov_class": ((), np.int8(cls), {
                "long_name": "verdict from lambda1 and its error",
                "flag_values": np.arange(5, dtype=np.int8),
                "flag_meanings": "unknown periodic quasi_periodic chaotic not_settled"}),
        },
        coords={"i": ("i", i, {"long_name": "exponent index (largest first)"}),
                "period": ("period", pts, {"long_name": "recorded forcing periods"})},
        attrs=provenance_attrs(params, solver, analysis="lyapunov", periods=periods,
                               transient=transient, **start_attrs(u_start), blocks=blocks,
                               forcing_period=T, state_names=" ".join(params.model.state_names),
                               verdict=VERDICTS[cls]),
    )
    return ds


# ---- periodic orbits by Newton shooting -------------------------------------------------------
def _section_state(setup, p, z, template):
    """Kernel state at section point z: the template's mode and memory flags if that mode still
    holds there, else classified by the model (mode -1)."""
    s = setup.state_of(z, template)
    if s[ST_MODE] >= 0 and not mode_holds(KERNEL_GENERIC, setup.fns, p, setup.opts, s):
        s[ST_MODE] = -1.0
    return s


def _off_its_drift(setup, p, s) -> str:
    """Why the section state ``s`` cannot carry its mode, or "": a mode whose ``linear`` row
    is a drift X' = b0, V' = 0 (stick on a belt, a ball riding on its table) holds V = b0. A
    state with another V that the model itself puts in another mode (``initial``) is an
    artefact of Newton's steps (the mode carried over while V moved), not a point of an orbit:
    integrated, such a state keeps its V while X drifts."""
    from ..integrate.contract import OPT_NMEM, OPT_PHASE, ST_EXTRA, ST_V, ST_X
    from ..integrate.hybrid import _drift
    from ..models._probe import call_initial, call_linear
    spec = setup.solver.spec
    mode = int(s[ST_MODE])
    if not spec.closed_form or spec.linear is None or setup.n != 2 or mode < 0:
        return ""
    row = np.zeros(10)
    if call_linear(setup.fns, mode, p, row) != 2 or not _drift(row) or s[ST_V] == row[4]:
        return ""
    nm = int(setup.opts[OPT_NMEM])
    mem = np.array(s[ST_EXTRA:ST_EXTRA + nm], dtype=np.float64) if nm else np.zeros(1)
    psi = float(setup.opts[OPT_PHASE])
    u = np.array([s[ST_X], s[ST_V]], dtype=np.float64)
    if call_initial(setup.fns, math.cos(psi), math.sin(psi), u, p, mem) == mode:
        return ""
    return (f"its section state has V = {s[ST_V]:.6g} in mode "
            f"{setup.model.mode_names[mode]!r}, whose drift holds V = {row[4]:.6g} (a state "
            f"the model puts in another mode: not a point of an orbit)")


def periodic_orbit(params, *, k: int = 1, x0: float = 0.0, v0: float = 0.0,
                   method: str = "exact", transient: int = 0, tol: float = 1e-10,
                   max_iter: int = 40, rtol: float = 1e-10, atol: float = 1e-12,
                   samples_per_period: int = 200, section_phase: float = 0.0,
                   u0=None) -> xr.Dataset:
    """A k-periodic orbit (fixed point of the k-fold stroboscopic map), stable or unstable, by
    Newton shooting from (x0, v0) (or from ``u0``, every component, see ``simulate``; after
    ``transient`` periods).

    Newton's iteration on F(z) = P^k(z) - z with the monodromy M = dP^k/dz from the tangent
    kernel (F' = M - I): quadratic convergence; a step that does not reduce ‖F‖ is halved up
    to 12 times (damped Newton). Converged when ‖F‖ <= tol (1 + ‖z‖).

    Returns a Dataset: the section points ``X_section``, ``V_section`` (k of them, ``point``),
    the Floquet multipliers ``multiplier_real`` / ``multiplier_imag`` and ``multiplier_abs``
    (largest modulus first), ``stable`` (all ‖mu‖ < 1), ``max_X``, ``min_X`` over the orbit
    (interior extrema), ``contact_fraction`` (fraction of the orbit's samples in the model's
    contact modes), the orbit itself (``X``, ``V``, ``mode`` over ``t``, one period k T at
    ``samples_per_period`` per period; a model with more state components has one variable
    each, ``<name>_section`` over ``point`` and ``<name>`` over ``t``), and attrs ``status`` ("converged", "max_iter",
    "diverged", "integration failed: ...", "singular", "not confirmed: ..."), ``iterations``,
    ``residual`` and ``confirmation_residual``: a converged orbit is integrated once more,
    sampled ``samples_per_period`` times a period (so with other steps than Newton's), and is
    reported converged only if it closes on itself to ``CONFIRM_TOL`` (1 + ‖z‖).
    Bad input raises one-line ParameterErrors; a failed search is a status, not an error."""
    from ..simulate import check_forced
    check_forced(params, "periodic_orbit")
    params, solver, p, opts, state = start_trajectory(params, x0, v0, method, rtol, atol,
                                                      section_phase, u0)
    u_start = state_u(params.model, state)
    k = check_int("k", k, 1)
    transient = check_int("transient", transient, 0)
    max_iter = check_int("max_iter", max_iter, 1)
    spp = check_int("samples_per_period", samples_per_period, 1)
    big = ("k", k) if k >= spp else ("samples_per_period", spp)  # name the larger factor
    check_memory(_ORBIT_SAMPLE_BYTES * k * spp, big[0],
                 f"the orbit is k x samples_per_period = {k:,} x {spp:,} samples",
                 size=(big[1], 1))
    tol = check_positive("tol", tol)
    setup = TangentSetup(solver)
    N = setup.N
    if transient:
        code = run(KERNEL_GENERIC, setup.fns, p, opts, state, 1, transient, 0,
                   *output_buffers(0))
        if code != st.OK:
            raise IntegrationError(f"periodic_orbit: transient failed: {st.message(code)}")
    else:  # classify the start (mode and memory) without moving
        run(KERNEL_GENERIC, setup.fns, p, opts, state, 1, 0, 0, *output_buffers(0))
    z = setup.z_of(state)
    template = state
    status = "max_iter"
    res = math.inf
    M = np.full((N, N), np.nan)
    it = 0
    history = []
    for it in range(1, max_iter + 1):
        s0 = _section_state(setup, p, z, template)
        s1, M, code, _ = period_map(setup, p, s0, k)
        if code != st.OK:
            status = f"integration failed: {st.message(code)}"
            M = np.full((N, N), np.nan)
            break
        F = setup.z_of(s1) - z
        res = float(np.linalg.norm(F))
        history.append(res)
        if res <= tol * (1.0 + float(np.linalg.norm(z))):
            status = "converged"
            template = s0
            break
        act = _active(M, setup.n)
        try:
            dz = np.zeros(N)
            dz[act] = np.linalg.solve(M[np.ix_(act, act)] - np.eye(int(act.sum())), -F[act])
            dz[~act] = F[~act]  # memory not read before it is rewritten: take the mapped value
        except np.linalg.LinAlgError:
            status = "singular"
            break
        if not np.all(np.isfinite(dz)):
            status = "diverged"
            break
        def trial(zt):
            st_t = _section_state(setup, p, zt, s0)
            s1t = st_t.copy()  # the k-fold map without the tangent (a line-search trial)
            code_t = run(KERNEL_GENERIC, setup.fns, p, opts, s1t, 1, k, 0, *output_buffers(0))
            return st_t, (float(np.linalg.norm(setup.z_of(s1t) - zt)) if code_t == st.OK
                          else math.inf)
        zt, st_t = damped_step(z, dz, res, trial)
        if zt is None:
            status = "diverged"
            break
        template = st_t
        z = zt
        if not np.all(np.isfinite(z)) or float(np.linalg.norm(z)) > 1e12:
            status = "diverged"
            break
    act = _active(M, setup.n) if np.all(np.isfinite(M)) else np.ones(N, bool)
    Ma = M[np.ix_(act, act)]
    mu = np.linalg.eigvals(Ma) if np.all(np.isfinite(Ma)) else np.full(len(Ma), np.nan + 0j)
    order = np.argsort(-np.abs(mu), kind="stable")
    mu = mu[order]
    converged = status == "converged"
    # the orbit itself, for plotting and its extremes
    n_s = k * spp
    bufs = output_buffers(n_s)
    s_orbit = _section_state(setup, p, z, template)
    run(KERNEL_GENERIC, setup.fns, p, opts, s_orbit, 1, 0, 0, *output_buffers(0))  # classify
    start = s_orbit.copy()
    U = np.empty((n_s, setup.n))
    code, _ = setup.run(p, s_orbit, k, np.zeros((N, 0)), per_period=spp, out=bufs, U=U)
    Xs, Vs, R, Mk, Xmax, Xmin = bufs
    if code != st.OK:
        Xs[:] = np.nan
    # confirmation: the orbit integrated again, sampled samples_per_period times a period (other
    # steps than Newton's), must close on itself
    confirm = (float(np.linalg.norm(setup.z_of(s_orbit) - setup.z_of(start)))
               if code == st.OK else math.inf)
    if converged and not confirm <= CONFIRM_TOL * (1.0 + float(np.linalg.norm(z))):
        status = (f"not confirmed: integrated again at {spp} samples per period, the orbit "
                  f"misses its start by {confirm:.3g}")
        converged = False
    why = _off_its_drift(setup, p, start) if converged else ""
    if why:
        status = f"not confirmed: {why}"
        converged = False
    X = np.concatenate([[start[0]], Xs])
    V = np.concatenate([[start[1]], Vs])
    R = np.concatenate([[int(start[ST_MODE])], R]).astype(np.int8)
    U = np.concatenate([state_u(params.model, start)[None, :], U])
    if code != st.OK:
        U[:] = np.nan
    T = params.period
    t = np.arange(n_s + 1) * (T / spp)
    cmask = params.model.contact_modes
    in_contact = ((1 << R[1:].astype(np.int64)) & cmask) != 0 if cmask else np.zeros(n_s, bool)
    absmu = np.abs(mu)
    stable = bool(converged and np.all(absmu < 1.0 - NEUTRAL))
    neutral = bool(converged and not stable and np.all(absmu <= 1.0 + NEUTRAL))
    ds = xr.Dataset(
        {
            "X_section": ("point", X[::spp][:k], {"long_name": "X at the section t = jT",
                                                  "units": "1"}),
            "V_section": ("point", V[::spp][:k], {"long_name": "V at the section t = jT",
                                                  "units": "1/s"}),
            "multiplier_real": ("multiplier", mu.real, {"long_name": "Floquet multiplier, real "
                                                                     "part", "units": "1"}),
            "multiplier_imag": ("multiplier", mu.imag, {"long_name": "Floquet multiplier, "
                                                                     "imaginary part",
                                                        "units": "1"}),
            "multiplier_abs": ("multiplier", absmu, {"long_name": "modulus of the Floquet "
                                                                  "multiplier", "units": "1"}),
            "monodromy": (("row", "col"), M, {"long_name": "monodromy matrix dP^k/dz of the "
                                                           "section point z", "units": "1"}),
            "stable": ((), np.int8(stable), {"long_name": "1: every multiplier inside the unit "
                                                          "circle by more than 1e-6 "
                                                          "(asymptotically stable)",
                                             "flag_values": np.array([0, 1], np.int8),
                                             "flag_meanings": "not_stable stable"}),
            "max_X": ((), float(np.max(Xmax)) if code == st.OK else np.nan,
                      {"long_name": "largest X over the orbit (interior extrema included)",
                       "units": "1"}),
            "min_X": ((), float(np.min(Xmin)) if code == st.OK else np.nan,
                      {"long_name": "smallest X over the orbit (interior extrema included)",
                       "units": "1"}),
            "contact_fraction": ((), float(in_contact.mean()), {
                "long_name": "fraction of the orbit's samples in contact modes", "units": "1"}),
            "X": ("t", X, {"long_name": state_long_name(params.model, 0), "units": "1"}),
            "V": ("t", V, {"long_name": state_long_name(params.model, 1), "units": "1/s"}),
            **component_variables(params.model, "point", U[::spp][:k], suffix="_section",
                                  what=" at the section t = jT"),
            **component_variables(params.model, "t", U),
            "mode": ("t", R, {"long_name": "mode at t",
                              "flag_values": np.arange(len(params.model.mode_names),
                                                       dtype=np.int8),
                              "flag_meanings": " ".join(params.model.mode_names)}),
        },
        coords={"point": np.arange(k), "multiplier": np.arange(1, len(mu) + 1),
                "t": ("t", t, {"long_name": "time from the section point", "units": "s"})},
        attrs=provenance_attrs(params, solver, analysis="periodic_orbit", k=k,
                               **start_attrs(u_start), transient=transient, tol=tol,
                               status=status, iterations=it, residual=res,
                               confirmation_residual=confirm,
                               converged=int(converged),
                               verdict=("stable" if stable else "neutral" if neutral
                                        else "unstable") if converged else "not found",
                               forcing_period=T),
    )
    return apply_state_units(ds, params.model)


def damped_step(z, dz, res, trial, halvings: int = 12):
    """Damped Newton: the first of z + dz, z + dz/2, ... (``halvings`` halvings) whose
    ``trial(zt) -> (state, residual)`` has a residual below ``res``; returns (zt, state), or
    (None, None) when none does."""
    lam = 1.0
    for _ in range(halvings + 1):
        zt = z + lam * dz
        state, r = trial(zt)
        if r < res:
            return zt, state
        lam *= 0.5
    return None, None


def _active(M, n):
    """Coordinates of the section point that the map depends on: the state, and the memory
    slots that the state after k periods depends on (a memory value that is rewritten before
    it is read, e.g. an entry velocity at a section point outside its band, is not a
    coordinate of the map; keeping it would add a spurious multiplier 1 or 0)."""
    act = np.ones(M.shape[0], bool)
    for q in range(n, M.shape[0]):
        act[q] = bool(np.any(M[:n, q] != 0.0))
    return act


# ---- lambda1 of many points (sweeps) ----------------------------------------------------------
@nb.njit(cache=True)
def _period_outputs(m):
    """The kernel's per-period output buffers (X, V, R, M, X_max, X_min) of ``m`` periods."""
    return (np.empty(m), np.empty(m), np.empty(m, np.int8), np.empty(m, np.uint8),
            np.empty(m), np.empty(m))


@nb.njit(cache=True, parallel=True)
def _lambda1_many(tangent, fns, P, opts, states, align, periods, N, cmi, logs, status, Ys):
    """One tangent vector per point (``Ys[i]``, carried in and out) over ``align`` + ``periods``
    periods (normalised each period): logs[i, k] = log growth of recorded period k (after the
    ``align`` periods that turn the vector into the leading direction); status[i] the kernel
    status."""
    for i in nb.prange(P.shape[0]):
        Y = np.zeros((N, 1))
        for r in range(N):
            Y[r, 0] = Ys[i, r]
        L = np.empty((periods, 1))
        X, V, R, M, Xa, Xb = _period_outputs(periods)
        status[i] = tangent(fns, P[i], opts, states[i], 1, align, periods, X, V, R, M, Xa, Xb,
                            Y, L, cmi, 1, np.zeros((0, 0)), np.zeros(0), np.zeros(4),
                            np.zeros((0, 0)), np.zeros(0))
        for k in range(periods):
            logs[i, k] = L[k, 0]
        for r in range(N):
            Ys[i, r] = Y[r, 0]


def quiet_opts(setup) -> np.ndarray:
    """The tangent setup's opts for runs whose per-period outputs nobody reads (the lambda1 of
    many points): no interior extrema of X (``OPT_NO_EXTREMA``; the trajectory is the same)."""
    o = setup.opts.copy()
    o[OPT_NO_EXTREMA] = 1.0
    return o


def generic_states(states, rows: int, reclassify: bool) -> np.ndarray:
    """A copy of kernel ``states`` (``rows`` of them) for the generic kernel: with
    ``reclassify`` (states of a specialised kernel or of another method) mode -1 and step
    size 0, so that the kernel classifies each point and chooses its step."""
    S = np.array(states, dtype=np.float64, copy=True).reshape(rows, -1)
    if reclassify:
        S[:, ST_MODE] = -1.0
        S[:, ST_H] = 0.0
    return S


#: Benettin's lambda1 of a non-periodic point runs in stages: FIRST_STAGE periods, then stages
#: of a quarter of the periods done (at least FIRST_STAGE / 2), and stops once its standard
#: error is at most REL_STDERR |lambda1| (or the record is used up): a record of at most
#: FIRST_STAGE periods runs whole, in one stage. A point runs at most half as many periods
#: again as the target needs, a quarter past 2 FIRST_STAGE (doubling stages: up to twice).
FIRST_STAGE = 1000
REL_STDERR = 0.05


def lambda1_points(P, solver, states, periods: int, *, blocks: int = 10, workers=None):
    """lambda1 (per unit time) and its standard error for many points at once: rows of packed
    parameters ``P`` from kernel ``states`` (copied; a specialised kernel's state is
    re-classified for the generic kernel, mode -1), at most ``periods`` periods each after
    max(20, min(periods, FIRST_STAGE) // 4) periods of alignment, one tangent vector (all
    local cores). A point stops after the first stage (FIRST_STAGE periods, then a quarter
    of the periods done, at least FIRST_STAGE / 2) at which the standard error from
    ``blocks`` block means is <= REL_STDERR |lambda1|.
    Returns (lambda1, stderr, status) arrays."""
    from ..sweep import deferred_interrupts, threads
    setup = TangentSetup(solver)
    P = np.array(np.atleast_2d(P), dtype=np.float64, order="C")  # writable, contiguous
    S = generic_states(states, P.shape[0], solver.code != KERNEL_GENERIC)
    n = P.shape[0]
    om = solver.model.frequency(P)
    T = 2.0 * np.pi / om
    Ys = np.zeros((n, setup.N))
    Ys[:, :2] = 1.0
    logs = np.zeros((n, periods))
    used = np.zeros(n, np.int64)
    status = np.zeros(n, np.int64)
    lam = np.full(n, np.nan)
    err = np.full(n, np.nan)
    active = np.arange(n)
    align = max(20, min(periods, FIRST_STAGE) // 4)
    opts = quiet_opts(setup)
    while active.size:
        done = int(used[active[0]])  # the active points have all run the same stages
        m = min(periods - done, FIRST_STAGE if done == 0
                else max(FIRST_STAGE // 2, done // 4))
        Pa, Sa, Ya = P[active], S[active], Ys[active]
        la = np.zeros((active.size, m))
        sa = np.zeros(active.size, np.int64)
        with threads(workers), deferred_interrupts():
            _lambda1_many(tangent_function(), setup.fns, Pa, opts, Sa,
                          align if done == 0 else 0, m, setup.N, setup.cmi, la, sa, Ya)
        S[active], Ys[active], status[active] = Sa, Ya, sa
        logs[active, done:done + m] = la
        used[active] = done + m
        with np.errstate(invalid="ignore"):
            lam[active] = logs[active, :done + m].mean(axis=1) / T[active]
            err[active] = block_error(logs[active, :done + m].T, blocks) / T[active]
        finished = (done + m >= periods) | (sa != st.OK) | (err[active] <= REL_STDERR
                                                              * np.abs(lam[active]))
        active = active[~finished]
    bad = status != st.OK
    lam[bad] = np.nan
    err[bad] = np.nan
    return lam, err, status


@nb.njit(cache=True, parallel=True)
def _monodromy_many(tangent, fns, P, opts, states, k, N, cmi, mono, status):
    """The monodromy (N x N) of the k[i]-fold period map from each ``states[i]`` (tangent
    kernel, no re-orthonormalisation); status[i] the kernel status."""
    for i in nb.prange(P.shape[0]):
        Y = np.eye(N)
        m = k[i]
        X, V, R, M, Xa, Xb = _period_outputs(m)
        status[i] = tangent(fns, P[i], opts, states[i], 1, 0, m, X, V, R, M, Xa, Xb, Y,
                            np.zeros((0, 0)), cmi, 0, np.zeros((0, 0)), np.zeros(0),
                            np.zeros(4), np.zeros((0, 0)), np.zeros(0))
        for a in range(N):
            for b in range(N):
                mono[i, a, b] = Y[a, b]


def floquet_lambda1_points(P, solver, states, period, *, workers=None):
    """lambda1 = ln|mu_1| / (p T) of points on periodic orbits (period ``p`` > 0 each, kernel
    ``states`` on the orbit at a period boundary): the leading Floquet multiplier of the
    p-fold map, from one pass of the tangent kernel over p periods (``_active`` coordinates:
    memory slots the map does not depend on are left out). Returns (lambda1, status)."""
    from ..sweep import deferred_interrupts, threads
    setup = TangentSetup(solver)
    P = np.array(np.atleast_2d(P), dtype=np.float64, order="C")
    S = generic_states(states, P.shape[0], solver.code != KERNEL_GENERIC)
    k = np.asarray(period, dtype=np.int64).ravel()
    n = P.shape[0]
    mono = np.zeros((n, setup.N, setup.N))
    status = np.zeros(n, np.int64)
    with threads(workers), deferred_interrupts():
        _monodromy_many(tangent_function(), setup.fns, P, quiet_opts(setup), S, k, setup.N,
                        setup.cmi, mono, status)
    lam = np.full(n, np.nan)
    om = solver.model.frequency(P)
    T = 2.0 * np.pi / om
    ok = status == st.OK
    groups = {}
    for i in np.flatnonzero(ok).tolist():
        groups.setdefault(tuple(_active(mono[i], setup.n)), []).append(i)
    for act, idx in groups.items():
        a = np.flatnonzero(act)
        sub = mono[np.ix_(idx, a, a)]
        with np.errstate(divide="ignore"):
            lam[idx] = np.log(np.abs(np.linalg.eigvals(sub)).max(axis=1)) / (k[idx] * T[idx])
    return lam, status


def classify_points(lam, err, period) -> np.ndarray:
    """:func:`classify` over arrays (period -1: not settled)."""
    lam = np.asarray(lam, dtype=float)
    err = np.asarray(err, dtype=float)
    period = np.asarray(period)
    finite = np.isfinite(lam) & np.isfinite(err)
    return np.select(
        [period > 0, period == -1, ~finite & (lam == -np.inf), ~finite, lam > N_SIGMA * err,
         np.abs(lam) <= N_SIGMA * err],
        [PERIODIC, NOT_SETTLED, NOT_SETTLED, 0, CHAOTIC, QUASI_PERIODIC],
        NOT_SETTLED).astype(np.int8)


def motion_attrs() -> dict:
    """CF flag attributes of a ``motion`` variable (:data:`VERDICTS`)."""
    from ..io import flag_attrs
    return flag_attrs([VERDICTS[k].replace("-", "_") for k in sorted(VERDICTS)],
                      dtype=np.int8,
                      long_name="motion: periodic (a period found), chaotic (lambda1 > 0 beyond "
                                f"{N_SIGMA:g} standard errors), quasi-periodic (no period, "
                                f"lambda1 within {N_SIGMA:g} standard errors of 0), not "
                                "settled")


def wants_lyapunov(flag, solver) -> bool:
    """Whether a sweep computes lambda1: ``flag`` True/False, or None (the default) = yes
    (every model and method has tangent dynamics)."""
    return True if flag is None else bool(flag)


def evidence_method(solver) -> str:
    """The method whose tangent dynamics give ``solver``'s lambda1 evidence: the one its
    method names as ``evidence`` (the same equations solved more precisely and faster, e.g.
    support's ``smooth_closed_form`` for ``smooth``), else its own."""
    return solver.spec.evidence or solver.method


def evidence_solver(solver, states):
    """(solver, kernel states) for ``solver``'s lambda1 evidence from its ``states`` (one per
    row): :func:`evidence_method`, with the states re-classified for it when it is another
    method, else ``solver`` and ``states`` themselves."""
    name = evidence_method(solver)
    if name == solver.method:
        return solver, states
    states = np.atleast_2d(states)
    return dataclasses.replace(solver, method=name), generic_states(states, states.shape[0],
                                                                    True)


def lambda1_evidence(P, solver, states, periods: int, period, *, workers=None):
    """(lambda1, stderr) of many points (rows of ``P``, kernel ``states`` on their attractors,
    detected ``period`` per point, > 0 periodic): a periodic point's lambda1 is ln|mu_1| / (p T)
    of its leading Floquet multiplier, from one tangent pass over its p periods
    (:func:`floquet_lambda1_points`, stderr 0: exact up to the orbit's settling); any other
    point's is Benettin's estimate over ``periods`` periods (:func:`lambda1_points`); both by
    the tangent dynamics of :func:`evidence_solver`."""
    solver, states = evidence_solver(solver, states)
    per = np.asarray(period, dtype=np.int64).ravel()
    n = per.size
    lam = np.full(n, np.nan)
    err = np.full(n, np.nan)
    periodic = np.flatnonzero(per > 0)
    rest = np.flatnonzero(per <= 0)
    if periodic.size:
        lam[periodic] = floquet_lambda1_points(P[periodic], solver, states[periodic],
                                               per[periodic], workers=workers)[0]
        err[periodic] = np.where(np.isfinite(lam[periodic]), 0.0, np.nan)
    if rest.size:
        lam[rest], err[rest], _ = lambda1_points(P[rest], solver, states[rest], periods,
                                                 workers=workers)
    return lam, err


def lyapunov_variables(P, solver, states, periods: int, period, dims) -> dict:
    """Dataset variables ``lambda1``, ``lambda1_stderr``, ``motion`` for points (rows of
    ``P``, kernel ``states`` on their attractors, detected ``period`` of shape ``dims``
    sizes): :func:`lambda1_evidence` (Floquet on periodic points, Benettin over ``periods``
    periods on the others), then :func:`classify_points`."""
    period = np.asarray(period)
    P = np.atleast_2d(P)
    states = np.asarray(states, dtype=np.float64).reshape(P.shape[0], -1)
    lam, err = lambda1_evidence(P, solver, states, periods, period)
    lam = lam.reshape(period.shape)
    err = err.reshape(period.shape)
    motion = classify_points(lam, err, period)
    if not dims:
        lam, err, motion = float(lam[0]), float(err[0]), np.int8(motion[0])
    attrs = lyapunov_attrs(periods, solver)
    return {"lambda1": (dims, lam, attrs["lambda1"]),
            "lambda1_stderr": (dims, err, attrs["lambda1_stderr"]),
            "motion": (dims, motion, attrs["motion"])}


def lyapunov_attrs(periods: int, solver) -> dict:
    """CF attributes of the ``lambda1``, ``lambda1_stderr`` and ``motion`` variables of a
    sweep (lambda1 over ``periods`` periods per point, by the tangent dynamics of
    :func:`evidence_solver` of ``solver``: attribute ``tangent_method``)."""
    return {
        "lambda1": {"long_name": "largest Lyapunov exponent (tangent dynamics with saltation "
                                 "matrices): ln|mu_1| / (p T) of the leading Floquet "
                                 "multiplier at periodic points, Benettin's estimate over "
                                 "at most 'periods' periods elsewhere (ended once its "
                                 "standard error is below 5% of |lambda1|)", "units": "1/s",
                    "periods": periods,
                    "tangent_method": evidence_method(solver)},
        "lambda1_stderr": {"long_name": "standard error of lambda1 (10 block means; 0 at "
                                        "periodic points)", "units": "1/s"},
        "motion": motion_attrs(),
    }
