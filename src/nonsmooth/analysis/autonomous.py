"""Self-excited (autonomous) systems: Poincaré sections on a surface, limit cycles with their
period as an unknown, equilibria with their eigenvalues, and the Hopf points of equilibria along
a parameter (issue 23, item 3).

A system is autonomous when its field does not depend on time: a model whose forcing amplitude
(``Model.forcing_amplitude``, e.g. ``F0``) is 0, or a model without forcing terms. Its forcing
frequency then only sets the kernel's time unit T = 2 pi / omega (step budgets, output
intervals), never a number of the results.

* **Section surface** h(u) = 0, crossed in a direction (``"decreasing"``: h from
  positive to negative, the default; ``"increasing"``; ``"both"``): given as an expression in
  the state, with the model's parameters allowed (``"V"``, ``"X - delta"``,
  ``("V - v_belt", "increasing")``, ``"X**2 + V**2 - 4"``). Crossings are located by the
  kernel like switching events (``hybrid.advance_tangent`` with a section row), to the
  kernel's event tolerance: an affine h = a . u + b as an affine row; any other as a curved
  guard (:class:`Surface`: h and its gradient a(u), derived by SymPy, compiled into the
  ``curved`` function of the flow's ``fns``, ``contract.SECTION_K``).
* **A forced system** (``surface_section``, ``surface_bifurcation_diagram``): its crossings
  of a surface come with the forcing phase omega t mod 2 pi (``phase``); the runs go over
  whole forcing periods from a period's start (``_Flow.record``). A section on a switching
  surface itself counts the switching event as the crossing, with the state before the
  transition (the kernel's ``_section_hit``): the impact map (phase, velocity before impact).
* **Return map** P: a point z on the section to the next crossing in the direction; its time is
  the return time. Its Jacobian from the flow's tangent Phi (saltation matrices at the
  switches included) and the field f at the crossing: dP = (I - f a^T / (a . f)) Phi, a the
  gradient there.
* **Limit cycle** (:func:`limit_cycle`): Newton's method for P(z) = z on the section's
  coordinates (an orthonormal basis B of a(z)^perp, the tangent plane at z): (B^T dP B - I) dw
  = -B^T (P(z) - z), the step z + B dw moved back onto a curved surface along a(z); the
  period is the return time. The Floquet multipliers are the eigenvalues of B^T dP B, the
  n - 1 nontrivial ones (the trivial multiplier 1, along the flow, is removed).
* **Equilibria** (:func:`equilibria`): Newton on f(mode, u) = 0 in every mode of the method,
  from given starts (or a default set), kept where the mode holds (its guards >= 0 there);
  eigenvalues of the mode's Jacobian, stable when every real part is < 0.
* **Hopf points** (:func:`equilibrium_branch`): an equilibrium followed along a parameter
  (Newton from the previous value), its eigenvalues at each value, and the values where a
  complex pair crosses the imaginary axis, located by the secant / Illinois method to 1e-10.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from .. import status as st
from ..checks import check_positive
from ..errors import IntegrationError, ParameterError
from ..integrate.contract import ST_MODE
from ..io import apply_state_units, provenance_attrs
from ..kernels import Solver, output_buffers
from ..models.base import KERNEL_GENERIC
from ..section_surface import (DIRECTIONS, Surface, check_autonomous, is_forced,  # noqa: F401
                               parse_section)

#: Newton's tolerance on |P(z) - z| / (1 + |z|) and the largest residual a converged cycle
#: may show when integrated again (confirmation).
CONFIRM_TOL = 1e-7


# ---- the flow to the section --------------------------------------------------------------
class _Flow:
    """The generic kernel with a section surface, from Python: crossings, the return map and
    its Jacobian."""

    def __init__(self, params, solver, surface, max_time):
        from ..tangent import TangentSetup
        self.setup = TangentSetup(solver)
        self.setup.fns = surface.fns(solver.fns, params.model, solver.method)
        self.model = params.model
        self.p = params.pack()
        self.surface = surface
        self.H = surface.H
        self.direction = surface.direction
        self.T = params.period
        self.budget = max(1, int(math.ceil(max_time / self.T)))
        self.max_time = max_time
        self.forced = is_forced(params)
        from ..integrate.contract import OPT_PHASE
        self.psi = float(self.setup.opts[OPT_PHASE])  # the forcing phase at a period's start

    def record(self, state, skip, m):
        """Advance ``state`` (in place) past ``skip`` crossings, then record the next ``m``:
        (status, U (m x n), times since the last skipped crossing (since the start when
        ``skip`` is 0), forcing phases omega t mod 2 pi at the crossings (None: autonomous)).
        A forced system's field depends on t, so its runs go over whole forcing periods from
        a period's start (``_forced_record``) and ``state`` ends at the end of the period of
        the last crossing; an autonomous one stops on the crossings."""
        if self.forced:
            return self._forced_record(state, skip, m)
        if skip:
            status = self.crossings(state, skip)[0]
            if status != "ok":
                return f"transient: {status}", None, None, None
        status, _, U, Tc, _ = self.crossings(state, m, record=m)
        return status, U, Tc, None

    def _forced_record(self, state, skip, m):
        """``record`` of a forced system: runs of whole periods (their number estimated from
        the crossings seen so far, at most 256), each recording every crossing it meets (run
        again with room for all where more came than it had room for), until skip + m."""
        n, total = self.model.n, skip + m
        U = np.empty((total, n))
        Tc = np.empty(total)
        count, periods, chunk = 0, 0, 1
        while count < total:
            if periods >= self.budget:
                return (f"no crossing: {count} of {total} crossings of the section in its "
                        f"direction ({skip} transient, {m} recorded) within "
                        f"{self.max_time:g} time units"), None, None, None
            k = min(chunk, self.budget - periods)
            cap = 4 * (total - count) + 64
            while True:
                s = state.copy()
                SEC = np.array([self.direction, 0.0, 0.0, 0.0])
                Ub, Tb = np.empty((cap, n)), np.empty(cap)
                code, _ = self.setup.run(self.p, s, k, np.zeros((self.setup.N, 0)),
                                         section=(self.H, SEC, Ub, Tb))
                if code != st.OK:
                    return f"integration failed: {st.message(code)}", None, None, None
                got = int(SEC[2])
                if got <= cap:
                    break
                cap = got
            state[:] = s
            take = min(got, total - count)
            U[count:count + take] = Ub[:take]
            Tc[count:count + take] = Tb[:take] + periods * self.T
            count += take
            periods += k
            chunk = (min(256, 2 * chunk) if count == 0 else
                     max(1, min(256, int(math.ceil((total - count) * periods / count)))))
        phase = np.mod(self.psi + 2.0 * math.pi * Tc[skip:] / self.T, 2.0 * math.pi)
        t = Tc[skip:] - (Tc[skip - 1] if skip else 0.0)
        return "ok", U[skip:], t, phase

    def crossings(self, state, m, record=0, tangent=False):
        """Advance ``state`` (in place) to its m-th crossing; returns (status, time, U, T, Y):
        the first ``record`` crossings' states and times, and the flow's Jacobian Phi (N x N)
        when ``tangent``. Status "no crossing" when fewer than m come within max_time."""
        n, N = self.setup.n, self.setup.N
        SEC = np.array([self.direction, float(m), 0.0, 0.0])
        U = np.empty((record, n))
        Tc = np.empty(record)
        Y = np.eye(N) if tangent else np.zeros((N, 0))
        code, _ = self.setup.run(self.p, state, 0, Y, transient=self.budget,
                                 section=(self.H, SEC, U, Tc))
        if code != st.OK:
            return f"integration failed: {st.message(code)}", math.nan, U, Tc, Y
        if SEC[2] < m:
            return (f"no crossing: {int(SEC[2])} of {m} crossings of the section within "
                    f"{self.max_time:g} time units"), math.nan, U, Tc, Y
        if not SEC[3] > 1e-9 * self.T:  # on the section and not leaving it: an equilibrium
            return ("no crossing: the state stays on the section (an equilibrium there)",
                    math.nan, U, Tc, Y)
        return "ok", float(SEC[3]), U, Tc, Y

    def field(self, state):
        """The field f at a kernel state (its mode)."""
        from ..models._probe import call_field
        from ..simulate import state_u
        from ..integrate.contract import ST_EXTRA
        u = state_u(self.model, state)
        du = np.zeros(self.model.n)
        nm = self.model.n_memory
        mem = np.zeros(max(1, nm))
        mem[:nm] = state[ST_EXTRA + self.model.n - 2:ST_EXTRA + self.model.n - 2 + nm]
        call_field(self.setup.fns, int(state[ST_MODE]), 0.0, 1.0, 0.0, u, self.p, mem, du)
        return du

    def return_map(self, state, m: int = 1):
        """(status, state at the m-th next crossing, return time, dP (n x n))."""
        s = state.copy()
        status, t, _, _, Y = self.crossings(s, m, tangent=True)
        if status != "ok":
            return status, s, t, None
        n = self.model.n
        f = self.field(s)
        from ..simulate import state_u
        a = self.surface.gradient(state_u(self.model, s), self.p)  # at the crossing
        af = float(a @ f)
        if abs(af) <= 1e-12 * (np.linalg.norm(a) * np.linalg.norm(f) + 1e-300):
            return "grazing the section (the flow is tangent to it)", s, t, None
        Phi = Y[:n, :n]
        dP = Phi - np.outer(f, a @ Phi) / af
        return "ok", s, t, dP


def _start(params, solver, x0, v0, u0):
    from ..simulate import check_admissible, initial_u, state_from_u
    from ..kernels import run
    u = initial_u(params.model, x0, v0, u0)
    check_admissible(solver, params, u)
    s = state_from_u(u)
    run(KERNEL_GENERIC, solver.fns, params.pack(), solver.opts(), s, 1, 0, 0,
        *output_buffers(0))  # classify the mode without moving
    return u, s


def _setup(params, section, method, rtol, atol, max_time, who, forced_ok=False):
    from ..simulate import check_params
    params = check_params(params)
    solver = Solver(method=method, rtol=rtol, atol=atol, model=params.model)
    if not (forced_ok and is_forced(params)):
        check_autonomous(params, who, solver)
    surface = parse_section(params, section)
    max_time = check_positive("max_time", max_time)
    return params, solver, _Flow(params, solver, surface, max_time), surface.text


def _xv(model, dims, U, what: str, suffix: str = "") -> dict:
    """Variables of the state U (last axis: components): X, V and one per further component
    (``io.components`` assembles them)."""
    from ..io import xv_units
    from ..simulate import component_variables
    ux, uv = xv_units(model)
    return {f"X{suffix}": (dims, U[..., 0], {"long_name": f"X{what}", "units": ux}),
            f"V{suffix}": (dims, U[..., 1], {"long_name": f"V{what}", "units": uv}),
            **component_variables(model, dims, U, suffix=suffix, what=what)}


# ---- analyses -------------------------------------------------------------------------------
def surface_section(params, section="V", *, crossings: int = 200, transient: int = 20,
                    x0: float = 0.0, v0: float = 0.0, u0=None, method: str = "exact",
                    rtol: float = 1e-10, atol: float = 1e-12,
                    max_time: float = 1e4) -> xr.Dataset:
    """Poincaré section on a surface (of a self-excited system; of a forced one, below): from
    (x0, v0) (or ``u0``), skip ``transient`` crossings, then record ``crossings`` crossings of
    ``section`` (see the module docstring) in its direction. Returns a Dataset over
    ``crossing`` with the state (``X``, ``V`` and one variable per further component,
    ``io.components(ds)``), the time ``t`` since the last transient crossing and the
    ``return_time`` from the crossing before; scalars ``cycle_crossings`` (the smallest q <= 16
    with u repeating after q crossings to 1e-6 (1 + ‖u‖); 0: none), ``cycle_period`` (the
    time of those q crossings; NaN: none) and ``at_equilibrium`` (the crossings converge onto
    an equilibrium, a focus: no cycle). A surface the orbit stops crossing within
    ``max_time`` (per call: the transient, then the record) raises a one-line
    IntegrationError.

    A forced system (its forcing amplitude not 0) is recorded too, with ``phase``, the
    forcing phase omega t mod 2 pi at each crossing (its cycles: the crossings and their
    phases repeat; ``at_equilibrium`` is 0; ``max_time`` bounds the transient and the record
    together). On a switching surface (``"Z"`` for the bouncing ball) this is the impact
    map: each crossing is the event, recorded with the state before the reset."""
    from ..simulate import check_int, start_attrs
    params, solver, flow, text = _setup(params, section, method, rtol, atol, max_time,
                                        "surface_section", forced_ok=True)
    crossings = check_int("crossings", crossings, 1)
    transient = check_int("transient", transient, 0)
    u_start, s = _start(params, solver, x0, v0, u0)
    status, U, Tc, phase = flow.record(s, transient, crossings)
    if status != "ok":
        raise IntegrationError(f"surface_section: {status}")
    ret = np.diff(np.concatenate([[0.0], Tc]))
    q_found, period, at_rest = _repetition(flow, s, U, Tc, phase)
    return xr.Dataset(
        {
            **_xv(params.model, "crossing", U, " at the crossing"),
            **_phase_variable("crossing", phase),
            "t": ("crossing", Tc, {"long_name": "time since the last transient crossing",
                                   "units": "s"}),
            "return_time": ("crossing", ret, {"long_name": "time from the crossing before",
                                              "units": "s"}),
            "cycle_crossings": ((), np.int64(q_found), {
                "long_name": "crossings per cycle (0: no repetition found)", "units": "1"}),
            "cycle_period": ((), period, {"long_name": "period of the cycle", "units": "s"}),
            "at_equilibrium": ((), np.int8(at_rest), {
                "long_name": "1: the crossings converge onto an equilibrium (the field "
                             "vanishes at the last one to 1e-6)",
                "flag_values": np.array([0, 1], np.int8),
                "flag_meanings": "moving at_equilibrium"}),
        },
        coords={"crossing": np.arange(crossings)},
        attrs=provenance_attrs(params, solver, analysis="surface_section", section=text,
                               transient=transient, **start_attrs(u_start),
                               max_time=flow.max_time),
    )


#: |f| <= EQUILIBRIUM_TOL (1 + |u|) at a section point: an equilibrium, not a cycle
EQUILIBRIUM_TOL = 1e-6


def _phase_variable(dims, phase) -> dict:
    """The forcing phase at the crossings of a forced system's section (none: autonomous)."""
    if phase is None:
        return {}
    return {"phase": (dims, phase, {"long_name": "forcing phase omega t mod 2 pi at the "
                                                 "crossing", "units": "rad"})}


def _repetition(flow, s, U, Tc, phase=None):
    """(q, cycle period, at rest) of recorded crossings U at times Tc, the state ``s`` after
    the last: the smallest q <= 16 with U (and a forced system's forcing ``phase``, mod 2 pi)
    repeating after q crossings to 1e-6 (1 + ‖U‖) (0: none; NaN period), and whether they
    converge onto an equilibrium (an autonomous system's field vanishes at ``s`` to 1e-6: a
    focus, whose crossings repeat too but are no cycle)."""
    crossings = len(U)
    q_found, period = 0, math.nan
    scale = 1.0 + float(np.max(np.abs(U)))
    at_rest = phase is None and float(np.linalg.norm(flow.field(s))) <= EQUILIBRIUM_TOL * scale
    for q in range(1, 0 if at_rest else min(16, crossings // 2) + 1):
        dph = 0.0 if phase is None else float(np.max(np.abs(np.angle(
            np.exp(1j * (phase[q:] - phase[:-q]))))))
        if max(float(np.max(np.abs(U[q:] - U[:-q]))), dph) <= 1e-6 * scale:
            q_found, period = q, float(np.mean([Tc[i + q] - Tc[i]
                                                for i in range(crossings - q)]))
            break
    return q_found, period, at_rest


def _param_values(params, param, values):
    """(parameter name, values as a 1-D float array) of a sweep; one-line errors."""
    if not isinstance(param, str):
        raise ParameterError(f"param: expected a parameter name, got {param!r}")
    param = params.model.param(param).name
    try:
        values = np.asarray(values, dtype=float).ravel()
    except (TypeError, ValueError):
        raise ParameterError(f"values: expected numbers, got {values!r}") from None
    if values.size < 1 or not np.all(np.isfinite(values)):
        raise ParameterError(f"values: expected finite values of {param}")
    for v in (values.min(), values.max()):
        params.replace(**{param: float(v)})  # in the parameter's range
    return param, values


def surface_bifurcation_diagram(params, param: str, values, section="V", *,
                                crossings: int = 50, transient: int = 100, x0: float = 0.0,
                                v0: float = 0.0, u0=None, method: str = "exact",
                                rtol: float = 1e-10, atol: float = 1e-12,
                                max_time: float = 1e4) -> xr.Dataset:
    """The bifurcation diagram of a self-excited system on a section surface: for each value of
    ``param`` in the order given (each run goes on from the previous value's last state, so
    the sweep follows an attractor, as ``bifurcation_diagram`` does for forced systems),
    ``transient`` crossings of ``section`` (see the module docstring) are skipped and the next
    ``crossings`` recorded.

    Returns a Dataset over (``param``, ``crossing``): the state at the crossings (``X``, ``V``
    and one variable per further component) and the ``return_time`` from the crossing before;
    over ``param``: ``cycle_crossings`` (the smallest q <= 16 after which the crossings repeat
    to 1e-6; 0: none, e.g. chaos or a torus), ``cycle_period``, ``at_equilibrium`` (the
    crossings converge onto an equilibrium) and ``status`` (0 ok; 1 the orbit failed or
    stopped crossing within ``max_time``: NaN crossings, and the sweep goes on from the start
    state). A failing value never stops the sweep. A forced system's crossings also carry
    ``phase`` (param, crossing), the forcing phase at each (see ``surface_section``: on a
    switching surface, the impact map)."""
    from ..simulate import check_int, check_params, start_attrs
    params = check_params(params)
    param, values = _param_values(params, param, values)
    crossings = check_int("crossings", crossings, 2)
    transient = check_int("transient", transient, 0)
    params0, solver, _, text = _setup(params.replace(**{param: float(values[0])}), section,
                                      method, rtol, atol, max_time,
                                      "surface_bifurcation_diagram", forced_ok=True)
    u_start, s0 = _start(params0, solver, x0, v0, u0)
    n = params.model.n
    U = np.full((values.size, crossings, n), np.nan)
    RT = np.full((values.size, crossings), np.nan)
    q = np.zeros(values.size, np.int64)
    per = np.full(values.size, np.nan)
    rest = np.zeros(values.size, np.int8)
    status = np.zeros(values.size, np.int8)
    PH = None  # the forcing phases, from the first forced value on (an autonomous system: none)
    notes = []
    s = s0.copy()
    for i, v in enumerate(values):
        p_i, _, flow, _ = _setup(params.replace(**{param: float(v)}), section, method, rtol,
                                 atol, max_time, "surface_bifurcation_diagram",
                                 forced_ok=True)
        why, Ui, Tc, ph = flow.record(s, transient, crossings)
        if why != "ok":
            status[i] = 1
            notes.append(f"{param} = {v:g}: {why}")
            s = s0.copy()
            continue
        U[i] = Ui
        RT[i] = np.diff(np.concatenate([[0.0], Tc]))
        if ph is not None:
            PH = np.full((values.size, crossings), np.nan) if PH is None else PH
            PH[i] = ph
        q[i], per[i], at_rest = _repetition(flow, s, Ui, Tc, ph)
        rest[i] = int(at_rest)
    spec = params.model.param(param)
    return xr.Dataset(
        {
            **_xv(params.model, (param, "crossing"), U, " at the crossing"),
            **_phase_variable((param, "crossing"), PH),
            "return_time": ((param, "crossing"), RT, {
                "long_name": "time from the crossing before", "units": "s"}),
            "cycle_crossings": (param, q, {"long_name": "crossings per cycle (0: no "
                                                        "repetition found)", "units": "1"}),
            "cycle_period": (param, per, {"long_name": "period of the cycle", "units": "s"}),
            "at_equilibrium": (param, rest, {
                "long_name": "1: the crossings converge onto an equilibrium",
                "flag_values": np.array([0, 1], np.int8),
                "flag_meanings": "moving at_equilibrium"}),
            "status": (param, status, {
                "long_name": "0: recorded; 1: the orbit failed or stopped crossing the "
                             "section (see the attr notes)",
                "flag_values": np.array([0, 1], np.int8), "flag_meanings": "ok failed"}),
        },
        coords={param: (param, values, {"long_name": spec.long_name, "units": spec.units}),
                "crossing": np.arange(crossings)},
        attrs=provenance_attrs(params, solver, swept=(param,),
                               analysis="surface_bifurcation_diagram", param=param,
                               section=text, transient=transient, crossings=crossings,
                               notes="; ".join(notes) or "none", **start_attrs(u_start),
                               max_time=float(max_time)),
    )


def limit_cycle(params, section="V", *, x0: float = 0.0, v0: float = 0.0, u0=None,
                transient: int = 20, method: str = "exact", tol: float = 1e-10,
                max_iter: int = 40, rtol: float = 1e-10, atol: float = 1e-12,
                max_time: float = 1e4, samples: int = 400, crossings: int = 1) -> xr.Dataset:
    """A limit cycle of a self-excited system, stable or unstable, with its period, by Newton
    shooting on ``section`` (see the module docstring) from the ``transient``-th crossing of
    the trajectory from (x0, v0) (or ``u0``; ``transient`` >= 1: Newton starts on the
    section): a fixed point of the ``crossings``-th return
    (a cycle that crosses the section that many times per turn, e.g. both ways).

    Returns a Dataset: ``period``, the section point (``X_section``, ``V_section``, ...), the
    nontrivial
    Floquet multipliers ``multiplier_real``/``_imag``/``_abs`` (n - 1 of them, largest modulus
    first; the trivial 1 is removed), ``stable`` (all ‖mu‖ < 1 - 1e-6), ``max_X``, ``min_X``
    and the cycle sampled at ``samples`` points (``X``, ``V``, ... and ``mode`` over ``t``);
    attrs
    ``status`` ("converged", "max_iter", "diverged", "singular", "no crossing: ...",
    "integration failed: ...", "grazing the section ...", "not confirmed: ...",
    "equilibrium: ..."), ``iterations``,
    ``residual``. A converged cycle is integrated once more without tangents and must close on
    itself to ``CONFIRM_TOL``; a point where the field vanishes (to ``EQUILIBRIUM_TOL``: the
    shooting converged onto an equilibrium that lies on the section, e.g. a stable focus) is
    no cycle: status "equilibrium: ...", not converged."""
    from ..simulate import check_int, start_attrs
    from .stability import _section_state, damped_step
    params, solver, flow, text = _setup(params, section, method, rtol, atol, max_time,
                                        "limit_cycle")
    transient = check_int("transient", transient, 1)
    max_iter = check_int("max_iter", max_iter, 1)
    samples = check_int("samples", samples, 2)
    crossings = check_int("crossings", crossings, 1)
    tol = check_positive("tol", tol)
    n = params.model.n
    u_start, s = _start(params, solver, x0, v0, u0)
    status, _, _, _, _ = flow.crossings(s, transient)
    from ..simulate import state_u
    surface = flow.surface
    res, it, period, J = math.inf, 0, math.nan, None
    if status == "ok":
        status = "max_iter"
        for it in range(1, max_iter + 1):
            z = state_u(params.model, s)
            # the tangent plane's basis at z (a curved surface: a Newton step along it is
            # projected back onto the surface along the normal at z)
            B = surface.basis(z, flow.p)
            got, s1, t1, dP = flow.return_map(s, crossings)
            if got != "ok":
                status = got
                break
            F = state_u(params.model, s1) - z
            res = float(np.linalg.norm(F))
            J = B.T @ dP @ B
            period = t1
            if res <= tol * (1.0 + float(np.linalg.norm(z))):
                status = "converged"
                break
            try:
                dw = np.linalg.solve(J - np.eye(n - 1), -B.T @ F)
            except np.linalg.LinAlgError:
                status = "singular"
                break
            def trial(zt, a=surface.gradient(z, flow.p)):
                if surface.curved:
                    zt = surface.project(zt, a, flow.p)
                st_t = _section_state(flow.setup, flow.p, zt, s)  # mode kept if it holds
                s1t = st_t.copy()
                got_t = flow.crossings(s1t, crossings)[0]
                return st_t, (float(np.linalg.norm(state_u(params.model, s1t) - zt))
                              if got_t == "ok" else math.inf)
            zt, st_t = damped_step(z, B @ dw, res, trial)
            if zt is None:
                status = "diverged"
                break
            s = st_t
    if s[ST_MODE] < 0:  # a Newton step's state whose mode was left to the kernel
        from ..kernels import run
        run(KERNEL_GENERIC, solver.fns, params.pack(), solver.opts(), s, 1, 0, 0,
            *output_buffers(0))
    mu = np.linalg.eigvals(J) if J is not None and np.all(np.isfinite(J)) else np.array([])
    mu = mu[np.argsort(-np.abs(mu), kind="stable")]
    converged = status == "converged"
    z = state_u(params.model, s)
    if converged and float(np.linalg.norm(flow.field(s))) <= EQUILIBRIUM_TOL * (
            1.0 + float(np.linalg.norm(z))):
        # a focus on the section: its crossings return to it too (to any tolerance), with a
        # return time and a multiplier that depend on where Newton stopped: no cycle
        status, converged = ("equilibrium: the shooting converged onto an equilibrium on the "
                             "section (the field vanishes there): no cycle"), False
    # the cycle itself, sampled, and the confirmation without tangents
    U = np.full((samples, n), np.nan)
    R = np.full(samples, -1, np.int8)
    mx = mn = math.nan
    if converged:
        s_c = s.copy()
        got, t_c, _, _, _ = flow.crossings(s_c, crossings)
        miss = (float(np.linalg.norm(state_u(params.model, s_c) - z)) if got == "ok"
                else math.inf)
        if not miss <= CONFIRM_TOL * (1.0 + float(np.linalg.norm(z))):
            status, converged = f"not confirmed: integrated again, the cycle misses its start " \
                                f"by {miss:.3g}", False
        U, R, mx, mn, _ = _sample_cycle(params, solver, s, period, samples)
    absmu = np.abs(mu)
    stable = bool(converged and absmu.size and np.all(absmu < 1.0 - 1e-6))
    t = np.arange(samples) * (period / samples) if converged else np.full(samples, np.nan)
    ds = xr.Dataset(
        {
            "period": ((), period if converged else math.nan,
                       {"long_name": "period of the limit cycle", "units": "s"}),
            **_xv(params.model, (), z, " of the cycle's point on the section", "_section"),
            "multiplier_real": ("multiplier", mu.real, {"units": "1"}),
            "multiplier_imag": ("multiplier", mu.imag, {"units": "1"}),
            "multiplier_abs": ("multiplier", absmu, {
                "long_name": "modulus of the nontrivial Floquet multipliers", "units": "1"}),
            "stable": ((), np.int8(stable), {"long_name": "1: every nontrivial |mu| < 1 - 1e-6",
                                             "flag_values": np.array([0, 1], np.int8),
                                             "flag_meanings": "not_stable stable"}),
            "max_X": ((), mx, {"long_name": "largest X over the cycle (samples)", "units": "1"}),
            "min_X": ((), mn, {"long_name": "smallest X over the cycle (samples)",
                               "units": "1"}),
            **_xv(params.model, "t", U, " on the cycle"),
            "mode": ("t", R, {"long_name": "mode at t",
                              "flag_values": np.arange(len(params.model.mode_names),
                                                       dtype=np.int8),
                              "flag_meanings": " ".join(params.model.mode_names)}),
        },
        coords={"multiplier": np.arange(1, len(mu) + 1),
                "t": ("t", t, {"long_name": "time from the section point", "units": "s"})},
        attrs=provenance_attrs(params, solver, analysis="limit_cycle", section=text,
                               transient=transient, **start_attrs(u_start), tol=tol,
                               crossings=crossings,
                               status=status, iterations=it, residual=res,
                               converged=int(converged),
                               verdict=("stable" if stable else "unstable") if converged
                               else "not found"),
    )
    return apply_state_units(ds, params.model)


def _sample_cycle(params, solver, state, period, samples):
    """The cycle from ``state`` sampled at ``samples`` equal steps of its period: (U, modes,
    max X, min X, bit mask of the modes visited) (the kernel's output grid: intervals of
    T / per_period with T / per_period a whole fraction of the cycle's period is not possible
    in general, so each sample is its own call from the previous one: autonomous, the time
    origin does not matter)."""
    from ..simulate import state_u
    n = params.model.n
    U = np.empty((samples, n))
    R = np.empty(samples, np.int8)
    p = params.pack()
    opts = solver.opts()
    s = state.copy()
    dt = period / samples
    mx, mn = -math.inf, math.inf
    visited = 0
    from ..kernels import run
    for i in range(samples):
        U[i] = state_u(params.model, s)
        R[i] = int(s[ST_MODE])
        # one output interval of length dt: a "period" T' = dt (omega' = 2 pi / dt; the
        # slot of a model's forcing period holds T' itself)
        pp = p.copy()
        pp[params.model.frame_index] = dt if params.model.period is not None else \
            2.0 * math.pi / dt
        bufs = output_buffers(1)
        code = run(KERNEL_GENERIC, solver.fns, pp, opts, s, 1, 0, 1, *bufs)
        if code != st.OK:
            U[i:] = np.nan
            break
        mx, mn = max(mx, float(bufs[4][0])), min(mn, float(bufs[5][0]))
        visited |= int(bufs[3][0])
    return U, R, mx, mn, visited


def _newton_equilibrium(fns, mode, p, u, mem, tol=1e-12, max_iter=50):
    """(converged, u, eigenvalues sorted by decreasing real part) of f(mode, u) = 0 from u."""
    from ..models._probe import call_field, call_jacobian
    n = u.size
    u = u.copy()
    f, J = np.zeros(n), np.zeros((n, n))
    ok = False
    for _ in range(max_iter):
        call_field(fns, mode, 0.0, 1.0, 0.0, u, p, mem, f)
        if np.linalg.norm(f) <= tol * (1.0 + np.linalg.norm(u)):
            ok = True
            break
        call_jacobian(fns, mode, 0.0, 1.0, 0.0, u, p, mem, J)
        try:
            u = u - np.linalg.solve(J, f)
        except np.linalg.LinAlgError:
            break
        if not np.all(np.isfinite(u)):
            break
    if not ok:
        return False, u, None
    call_jacobian(fns, mode, 0.0, 1.0, 0.0, u, p, mem, J)
    ev = np.linalg.eigvals(J)
    return True, u, ev[np.lexsort((-ev.imag, -ev.real))]


def _holds(fns, mode, p, opts, u) -> bool:
    """Does ``mode`` hold at the state u (its guards >= 0)?"""
    from ..kernels import mode_holds
    from ..integrate.contract import N_STATE, ST_EXTRA
    n = u.size
    s = np.zeros(N_STATE)
    s[0], s[1], s[2], s[ST_MODE] = u[0], u[1], u[1], mode
    s[ST_EXTRA:ST_EXTRA + n - 2] = u[2:]
    return bool(mode_holds(KERNEL_GENERIC, fns, p, opts, s))


def _eq_dataset(params, solver, found, dim, coord, extra=None, **attrs):
    m = params.model
    n = m.n
    k = len(found)
    U = np.array([f[0] for f in found]).reshape(k, n)
    EV = np.array([f[2] for f in found]).reshape(k, n)
    data = {
        **_xv(m, dim, U, " at the equilibrium"),
        "mode": (dim, np.array([f[1] for f in found], np.int8), {
            "long_name": "mode of the equilibrium",
            "flag_values": np.arange(len(m.mode_names), dtype=np.int8),
            "flag_meanings": " ".join(m.mode_names)}),
        "eigenvalue_real": ((dim, "eigenvalue"), EV.real, {"units": "1/s"}),
        "eigenvalue_imag": ((dim, "eigenvalue"), EV.imag, {"units": "1/s"}),
        "stable": (dim, np.array([bool(np.all(np.real(f[2]) < 0)) for f in found], np.int8),
                   {"long_name": "1: every eigenvalue has a negative real part",
                    "flag_values": np.array([0, 1], np.int8),
                    "flag_meanings": "not_stable stable"}),
    }
    data.update(extra or {})
    return xr.Dataset(data, coords={**coord, "eigenvalue": np.arange(1, n + 1),
                                    },
                      attrs=provenance_attrs(params, solver, **attrs))


def equilibria(params, *, method: str = "exact", starts=None, tol: float = 1e-12,
               max_iter: int = 50) -> xr.Dataset:
    """Equilibria of a self-excited system in every mode of ``method`` (a mode's memory slots
    at 0): Newton on
    f(mode, u) = 0 with the mode's Jacobian from each start (``starts``: states, n numbers
    each; default: the origin and +-1 along X and V), kept where the mode holds (its guards
    >= 0 there), duplicates merged. Returns a Dataset over ``equilibrium``: ``u``
    (equilibrium, component), ``mode``, ``eigenvalue_real``/``_imag`` (equilibrium,
    eigenvalue; largest real part first) and ``stable`` (every real part < 0)."""
    from ..simulate import check_params
    params = check_params(params)
    solver = Solver(method=method, model=params.model)
    check_autonomous(params, "equilibria", solver)
    m = params.model
    n = m.n
    fns, p, opts = solver.fns, params.pack(), solver.opts()
    if starts is None:
        starts = [np.zeros(n)] + [sg * np.eye(n)[i] for i in range(min(n, 2)) for sg in (1, -1)]
    starts = [np.asarray(u, dtype=float).ravel() for u in starts]
    for u in starts:
        if u.size != n or not np.all(np.isfinite(u)):
            raise ParameterError(f"starts: each start needs {n} finite numbers "
                                 f"({', '.join(m.state_names)})")
    modes = solver.spec.modes or tuple(range(len(m.mode_names)))
    mem = np.zeros(max(1, m.n_memory))
    found = []
    for mode in modes:
        for u0 in starts:
            ok, u, ev = _newton_equilibrium(fns, mode, p, u0, mem, tol, max_iter)
            if not ok or not _holds(fns, mode, p, opts, u):
                continue
            if any(fm == mode and np.linalg.norm(fu - u) <= 1e-8 * (1 + np.linalg.norm(u))
                   for fu, fm, _ in found):
                continue
            found.append((u, mode, ev))
    return _eq_dataset(params, solver, found, "equilibrium",
                       {"equilibrium": np.arange(len(found))}, analysis="equilibria")


def _pair(ev):
    """(real part, |imaginary part|) of the complex pair of eigenvalues with the largest real
    part ((NaN, NaN) if none)."""
    c = ev[np.abs(ev.imag) > 1e-12]
    if not c.size:
        return math.nan, math.nan
    e = c[int(np.argmax(c.real))]
    return float(e.real), float(abs(e.imag))


def _pair_real(ev) -> float:
    return _pair(ev)[0]


def equilibrium_branch(params, param: str, values, *, method: str = "exact", start=None,
                       mode: str | None = None) -> xr.Dataset:
    """An equilibrium followed along ``param`` over ``values`` (sorted ascending; Newton from
    the previous value's equilibrium, the first from ``start`` (n numbers) or the first one
    :func:`equilibria` finds, in ``mode`` if named), with its eigenvalues at each value and its
    Hopf points: where the largest real part of a complex pair changes sign, located to 1e-10
    by the Illinois method. Returns a Dataset over ``param``: ``u``, ``mode``, the eigenvalues,
    ``stable``, ``holds`` (the mode holds there: 0 where the equilibrium has left its mode,
    its data NaN beyond a failed Newton), and over ``hopf``: ``hopf_<param>`` and
    ``hopf_frequency`` (the imaginary part there, rad/s)."""
    from ..integrate.roots import illinois_point, illinois_update
    from ..simulate import check_params
    from .bifurcation import check_values
    params = check_params(params)
    check_autonomous(params, "equilibrium_branch")
    if not isinstance(param, str):
        raise ParameterError(f"param: expected a parameter name, got {param!r}")
    param = params.model.param(param).name
    values = check_values(param, values)
    for v in (values[0], values[-1]):
        params.replace(**{param: float(v)})
    solver = Solver(method=method, model=params.model)
    m = params.model
    n = m.n
    fns, opts = solver.fns, solver.opts()
    mem = np.zeros(max(1, m.n_memory))
    first = equilibria(params.replace(**{param: float(values[0])}), method=method,
                       starts=None if start is None else [start])
    sel = np.arange(first.sizes["equilibrium"])
    if mode is not None:
        if mode not in m.mode_names:
            raise ParameterError(f"mode: unknown mode {mode!r} (modes: "
                                 f"{', '.join(m.mode_names)})")
        sel = sel[first.mode.values == m.mode_names.index(mode)]
    if sel.size == 0:
        raise ParameterError(f"start: no equilibrium found at {param} = {values[0]:g}"
                             + (f" in mode {mode}" if mode else ""))
    from ..io import components
    u = components(first).values[sel[0]]
    code = int(first.mode.values[sel[0]])

    def at(v, u0):
        pv = params.replace(**{param: float(v)}).pack()
        ok, uv, ev = _newton_equilibrium(fns, code, pv, u0, mem)
        return ok, uv, ev, ok and _holds(fns, code, pv, opts, uv)

    found, holds = [], []
    for v in values:
        ok, u1, ev, hd = at(v, u)
        if not ok:
            found.append((np.full(n, np.nan), code, np.full(n, np.nan + 0j)))
            holds.append(False)
            continue
        u = u1
        found.append((u1, code, ev))
        holds.append(hd)
    hopf = []
    for i in range(len(values) - 1):
        a, b = _pair_real(found[i][2]), _pair_real(found[i + 1][2])
        if not (holds[i] and holds[i + 1]) or not (a * b < 0.0):
            continue
        lo, hi, glo, ghi, side = float(values[i]), float(values[i + 1]), a, b, 0
        u_h, ev_h = found[i][0], found[i][2]
        for _ in range(100):
            if hi - lo <= 1e-10 * max(1.0, abs(hi)):
                break
            x = illinois_point(lo, hi, glo, ghi)
            ok, u_h, ev_h, _ = at(x, u_h)
            g = _pair_real(ev_h) if ok else math.nan
            if not math.isfinite(g):
                break
            lo, hi, glo, ghi, side = illinois_update(lo, hi, glo, ghi, side, x, g)
        if not hi - lo <= 1e-10 * max(1.0, abs(hi)):
            continue  # Newton failed inside the bracket: not located, not reported
        hopf.append((0.5 * (lo + hi), _pair(ev_h)[1]))
    spec = m.param(param)
    extra = {
        "holds": (param, np.array(holds, np.int8), {
            "long_name": "1: the equilibrium lies in its mode (its guards >= 0)",
            "flag_values": np.array([0, 1], np.int8), "flag_meanings": "left holds"}),
        f"hopf_{param}": ("hopf", np.array([h[0] for h in hopf], float), {
            "long_name": f"{param} at the Hopf point", "units": spec.units}),
        "hopf_frequency": ("hopf", np.array([h[1] for h in hopf], float), {
            "long_name": "imaginary part of the critical pair at the Hopf point",
            "units": "rad/s"}),
    }
    coord = {param: (param, values, {"long_name": spec.long_name, "units": spec.units}),
             "hopf": np.arange(len(hopf))}
    return _eq_dataset(params, solver, found, param, coord, extra, swept=(param,),
                       analysis="equilibrium_branch", param=param)


def limit_cycle_branch(params, param: str, values, section="V", *, x0: float = 0.0,
                       v0: float = 0.0, u0=None, transient: int = 20, method: str = "exact",
                       tol: float = 1e-10, rtol: float = 1e-10, atol: float = 1e-12,
                       max_time: float = 1e4) -> xr.Dataset:
    """A limit cycle followed along ``param`` over ``values`` (in the order given): the first
    by :func:`limit_cycle` from (x0, v0) / ``u0`` after ``transient`` crossings, each next one
    by Newton from the previous value's section point (natural-parameter continuation: it
    follows stable and unstable cycles, not around folds). Returns a Dataset over ``param``:
    ``period``, the section point (``X_section``, ``V_section``, ...), the nontrivial
    multipliers (``multiplier_real``/``_imag``/``_abs`` over (param, multiplier)), ``stable``
    and ``converged``; the branch stops (NaN after it) at the first value where no cycle is
    found, the reason in the attr ``status``."""
    from ..io import components
    from ..simulate import check_params
    params = check_params(params)
    param, values = _param_values(params, param, values)
    n = params.model.n
    m = n - 1
    Z = np.full((values.size, n), np.nan)
    MU = np.full((values.size, m), np.nan + 0j)
    per = np.full(values.size, np.nan)
    stable = np.zeros(values.size, np.int8)
    conv = np.zeros(values.size, np.int8)
    status = "completed"
    start = dict(x0=x0, v0=v0, u0=u0, transient=transient)
    text = ""
    for i, v in enumerate(values):
        lc = limit_cycle(params.replace(**{param: float(v)}), section, method=method, tol=tol,
                         rtol=rtol, atol=atol, max_time=max_time, **start)
        text = lc.attrs["section"]
        if lc.attrs["status"] != "converged":
            status = f"stopped at {param} = {v:g}: {lc.attrs['status']}"
            break
        z = components(lc, suffix="_section").values
        Z[i], per[i] = z, float(lc.period)
        mu = lc.multiplier_real.values + 1j * lc.multiplier_imag.values
        MU[i, :mu.size] = mu
        stable[i], conv[i] = int(lc.stable), 1
        start = dict(u0=z, transient=1)
    spec = params.model.param(param)
    solver = Solver(method=method, rtol=rtol, atol=atol, model=params.model)
    return xr.Dataset(
        {
            "period": (param, per, {"long_name": "period of the limit cycle", "units": "s"}),
            **_xv(params.model, param, Z, " of the cycle's point on the section", "_section"),
            "multiplier_real": ((param, "multiplier"), MU.real, {"units": "1"}),
            "multiplier_imag": ((param, "multiplier"), MU.imag, {"units": "1"}),
            "multiplier_abs": ((param, "multiplier"), np.abs(MU), {
                "long_name": "modulus of the nontrivial Floquet multipliers", "units": "1"}),
            "stable": (param, stable, {"long_name": "1: every nontrivial |mu| < 1 - 1e-6",
                                       "flag_values": np.array([0, 1], np.int8),
                                       "flag_meanings": "not_stable stable"}),
            "converged": (param, conv, {"long_name": "1: a cycle was found at this value",
                                        "flag_values": np.array([0, 1], np.int8),
                                        "flag_meanings": "not_found converged"}),
        },
        coords={param: (param, values, {"long_name": spec.long_name, "units": spec.units}),
                "multiplier": np.arange(1, m + 1)},
        attrs=provenance_attrs(params, solver, swept=(param,), analysis="limit_cycle_branch",
                               param=param, section=text, status=status),
    )


#: Labels of :func:`surface_basins` that are not an attractor.
LABEL_UNDECIDED = -1


def surface_basins(params, section="V", *, x=(-1.0, 1.0), v=(-1.0, 1.0), grid=20,
                   u0=None, transient: int = 50, record: int = 32, max_period: int = 8,
                   method: str = "exact", rtol: float = 1e-10, atol: float = 1e-12,
                   max_time: float = 1e4, progress=None) -> xr.Dataset:
    """Basins of attraction of a self-excited system over a grid of initial (X, V) (the other
    components from ``u0``, else 0), "featurize, then group" on a section surface: each
    initial condition runs ``transient`` crossings of ``section``, then ``record`` more; it
    ends at an **equilibrium** when its crossings converge onto one (the field vanishes at the
    last crossing to 1e-6, or the orbit stops crossing within ``max_time`` and comes to rest),
    on a **cycle** when its crossings repeat after q <= ``max_period`` of them (to 1e-6 of the
    scale), else it is undecided (-1: chaotic, quasi-periodic, still converging, or failed).
    Equilibria are matched by their state, cycles by their section points (any phase), both to
    1e-4 of the scale.

    Returns a Dataset with ``label`` (v0, x0) (CF flags, -1 undecided) and per ``attractor``:
    ``kind`` (0 equilibrium, 1 cycle), ``fraction``, ``count``, ``crossings`` (q; 0 for an
    equilibrium) and its state (``X``, ``V``, ...: the equilibrium, or a cycle's first section
    point); ``undecided_fraction``. The points run one after the other (a Python loop over the
    compiled kernel): for grids of hundreds of points, not of a million."""
    from ..simulate import check_int, initial_u, state_from_u, state_u
    from ..sweep import progress_callback
    from ..checks import check_grid, check_range
    from ..kernels import run
    progress = progress_callback(progress, "surface_basins")
    params, solver, flow, text = _setup(params, section, method, rtol, atol, max_time,
                                        "surface_basins")
    x_lo, x_hi = check_range("x", x)
    v_lo, v_hi = check_range("v", v)
    nx, nv = check_grid(grid)
    transient = check_int("transient", transient, 0)
    record = check_int("record", record, 2)
    max_period = check_int("max_period", max_period, 1)
    if 2 * max_period > record:
        raise ParameterError(f"record: must be >= 2 max_period = {2 * max_period}, got {record}")
    base = initial_u(params.model, 0.0, 0.0, u0)
    xs, vs = np.linspace(x_lo, x_hi, nx), np.linspace(v_lo, v_hi, nv)
    scale = max(abs(x_lo), abs(x_hi), abs(v_lo), abs(v_hi), 1.0)
    p, opts = params.pack(), solver.opts()
    found = []  # (kind, q, points (q x n))
    label = np.full((nv, nx), LABEL_UNDECIDED, np.int64)
    match = 1e-4 * scale

    def classify(s):
        status, _, _, _, _ = flow.crossings(s, transient) if transient else ("ok",) * 5
        if status == "ok":
            status, _, U, _, _ = flow.crossings(s, record, record=record)
        if status != "ok":  # no more crossings: at rest, or failed / escaped
            if status.startswith("no crossing") and np.linalg.norm(flow.field(s)) <= 1e-6 * (
                    1.0 + np.linalg.norm(state_u(params.model, s))):
                return 0, 0, state_u(params.model, s)[None, :]
            return None
        tol = 1e-6 * (1.0 + float(np.max(np.abs(U))))
        if np.linalg.norm(flow.field(s)) <= tol:
            return 0, 0, U[-1:]
        for q in range(1, max_period + 1):
            if np.max(np.abs(U[q:] - U[:-q])) <= tol:
                return 1, q, U[-q:]
        return None

    done = 0
    for j, v0 in enumerate(vs):
        for i, x0 in enumerate(xs):
            u = base.copy()
            u[0], u[1] = x0, v0
            s = state_from_u(u)
            run(KERNEL_GENERIC, solver.fns, p, opts, s, 1, 0, 0, *output_buffers(0))
            feat = classify(s)
            done += 1
            if progress is not None:
                progress(done, nx * nv)
            if feat is None:
                continue
            kind, q, pts = feat
            for k, (kk, qq, ref) in enumerate(found):
                if kk == kind and qq == q and min(np.linalg.norm(ref - pt, axis=1).min()
                                                  for pt in pts) <= match:
                    label[j, i] = k
                    break
            else:
                found.append((kind, q, pts))
                label[j, i] = len(found) - 1
    na = len(found)
    counts = np.array([int(np.sum(label == k)) for k in range(na)], np.int64)
    first = np.array([f[2][0] for f in found]).reshape(na, params.model.n)
    from ..io import flag_attrs
    names = [("equilibrium" if f[0] == 0 else f"cycle_{f[1]}") + f"_{k}"
             for k, f in enumerate(found)]
    lab_attrs = dict(long_name="attractor reached (-1: undecided)")
    if na:
        lab_attrs.update(flag_values=np.arange(-1, na, dtype=np.int64),
                         flag_meanings=" ".join(["undecided"] + names))
    ds = xr.Dataset(
        {
            "label": (("v0", "x0"), label, lab_attrs),
            "kind": ("attractor", np.array([f[0] for f in found], np.int8), flag_attrs(
                ("equilibrium", "cycle"), dtype=np.int8, long_name="kind of attractor")),
            "fraction": ("attractor", counts / (nx * nv), {
                "long_name": "fraction of the grid attracted", "units": "1"}),
            "count": ("attractor", counts, {"long_name": "grid points attracted", "units": "1"}),
            "crossings": ("attractor", np.array([f[1] for f in found], np.int64), {
                "long_name": "crossings of the section per cycle (0: equilibrium)",
                "units": "1"}),
            **_xv(params.model, "attractor", first, " of the attractor (an equilibrium, or a "
                  "cycle's first section point)"),
            "undecided_fraction": ((), float(np.mean(label == LABEL_UNDECIDED)), {
                "long_name": "fraction of the grid undecided", "units": "1"}),
        },
        coords={"x0": ("x0", xs, {"long_name": "initial X", "units": "1"}),
                "v0": ("v0", vs, {"long_name": "initial V", "units": "1/s"}),
                "attractor": np.arange(na)},
        attrs=provenance_attrs(params, solver, analysis="surface_basins", section=text,
                               transient=transient, record=record, max_period=max_period,
                               max_time=flow.max_time, u0=base),
    )
    return apply_state_units(ds, params.model)


#: status of a branch of cycles that ends on an equilibrium (the corrector's point is a cycle of
#: no extent: the equilibrium on the section, a fixed point of the return map)
_SHRUNK = "the cycle shrinks onto an equilibrium (a Hopf point ends the branch)"


class _CycleBranch:
    """Limit cycles of a self-excited system as a branch for pseudo-arclength continuation
    (the interface of ``continuation._Branch``): a point is y = (w, lam), the cycle's section
    point z = z_ref + B w on the section hyperplane (B: an orthonormal basis of its directions,
    so the n - 1 coordinates carry no multiplier of the flow direction) and the parameter;
    F(w, lam) = B^T (P(z; lam) - z) with P the return map (k crossings), its Jacobian
    B^T dP B - I from the tangent kernel (saltation matrices included, the flow direction
    projected out) and dF/dlam by central differences of the map."""

    def __init__(self, params, param, solver, flow, z_ref, template, k, tol, level):
        self.params0, self.param, self.solver, self.flow = params, param, solver, flow
        self.B = flow.surface.basis(z_ref, flow.p)
        self.a_ref = flow.surface.gradient(z_ref, flow.p)
        self.z_ref, self.template, self.k, self.tol, self.level = z_ref, template, k, tol, level
        self.N = params.model.n - 1

    def p(self, lam):
        # packed afresh: a derived slot of the packed vector follows the parameter
        return self.params0.replace(**{self.param: float(lam)}).pack()

    def z(self, w):
        """The section point of coordinates w: on the tangent plane at z_ref, moved along the
        normal there onto a curved surface (at the parameter of ``flow.p``)."""
        z = self.z_ref + self.B @ w
        surface = self.flow.surface
        return surface.project(z, self.a_ref, self.flow.p) if surface.curved else z

    def _map(self, w, lam, template, tangent):
        from ..simulate import state_u
        from .stability import _section_state
        flow = self.flow
        try:
            flow.p = self.p(lam)
        except ParameterError:  # outside the parameter's range: no map there
            return None
        s = _section_state(flow.setup, flow.p, self.z(w), template)
        s0 = s.copy()
        if tangent:
            got, s1, t1, dP = flow.return_map(s, self.k)
        else:
            got, t1 = flow.crossings(s, self.k)[:2]
            s1, dP = s, None
        if got != "ok":
            return None
        Bz1 = self.B.T @ state_u(self.params0.model, s1)
        if flow.surface.curved:  # F itself: z(w) moves with the parameter
            Bz1 = Bz1 - self.B.T @ self.z(w)
        return s0, Bz1, t1, dP

    def evaluate(self, w, lam):
        """(F, dF/dw, dF/dlam, start state, period) at (w, lam), or None."""
        got = self._map(w, lam, self.template, True)
        if got is None:
            return None
        s0, Bz1, period, dP = got
        if self.flow.surface.curved:  # dz/dw = B - a_ref (g^T B) / (g . a_ref), g at z(w)
            F = Bz1
            g = self.flow.surface.gradient(self.z(w), self.flow.p)
            Zw = self.B - np.outer(self.a_ref, g @ self.B) / float(g @ self.a_ref)
            J = self.B.T @ dP @ Zw - np.eye(self.N)
        else:
            F = Bz1 - self.B.T @ self.z(w)
            J = self.B.T @ dP @ self.B - np.eye(self.N)
        h = 1e-7 * max(1.0, abs(lam))
        up, down = (self._map(w, lam + sg * h, s0, False) for sg in (1.0, -1.0))
        self.flow.p = self.p(lam)
        if up is not None and down is not None:
            Fl = (up[1] - down[1]) / (2.0 * h)
        elif up is not None or down is not None:  # at a limit of the parameter's range:
            Fl = ((up[1] - Bz1) if up is not None else (Bz1 - down[1])) / h  # one-sided
        else:
            return None
        return F, J, Fl, s0, period

    def correct(self, y_pred, t, base, max_iter=12):
        """Newton's corrector onto F = 0 in the hyperplane t . (y - y_pred) = 0: (y, evaluation,
        iterations) or None. The corrected point must lie within one step (|y_pred - base|,
        ``base`` the corrected point the prediction steps from) of its prediction: past a fold,
        Newton may otherwise land on an equilibrium on the section, a fixed point of the map."""
        from .continuation import _accepted
        y = y_pred.copy()
        N = self.N
        reach = np.linalg.norm(y_pred - base) + 1e3 * self.tol * (1.0 + np.linalg.norm(y))
        for it in range(1, max_iter + 1):
            ev = self.evaluate(y[:N], y[N])
            if ev is None:
                return None
            F, J, Fl = ev[:3]
            A = np.vstack([np.hstack([J, Fl[:, None]]), t[None, :]])
            try:
                d = np.linalg.solve(A, -np.r_[F, t @ (y - y_pred)])
            except np.linalg.LinAlgError:
                return None
            if not np.all(np.isfinite(d)):
                return None
            y = y + d
            if np.linalg.norm(y - y_pred) > reach:  # wandered off: a shorter step is tried
                return None
            z = self.z(y[:N])
            if (np.linalg.norm(F) <= self.tol * (1.0 + np.linalg.norm(z))
                    and np.linalg.norm(d) <= 1e3 * self.tol * (1.0 + np.linalg.norm(y))):
                return _accepted(self, y, it)
        return None

    def tangent(self, ev, t_prev):
        """Unit tangent at a corrected point, oriented along t_prev."""
        J = np.hstack([ev[1], ev[2][:, None]])
        try:
            v = np.linalg.solve(np.vstack([J, t_prev[None, :]]), np.r_[np.zeros(self.N), 1.0])
        except np.linalg.LinAlgError:
            v = t_prev.copy()
        return v / np.linalg.norm(v)

    def features(self, y, ev, t):
        """Nontrivial multipliers, test functions and cycle features of a corrected point."""
        from .continuation import FOLD, GRAZING, NEIMARK_SACKER, PERIOD_DOUBLING, _SAMPLES
        from ..kernels import run
        _, J, _, s0, period = ev
        mu = np.linalg.eigvals(J + np.eye(self.N))
        mu = mu[np.argsort(-np.abs(mu), kind="stable")]
        params = self.params0.replace(**{self.param: float(y[-1])})
        s0 = s0.copy()  # its mode classified (-1: left to the kernel) before it is sampled
        run(KERNEL_GENERIC, self.solver.fns, params.pack(), self.solver.opts(), s0, 1, 0, 0,
            *output_buffers(0))
        U, R, mx, mn, visited = _sample_cycle(params, self.solver, s0, period, _SAMPLES)
        cm = params.model.contact_modes
        contact = float(np.mean(((1 << R.astype(np.int64)) & cm) != 0)) if cm else 0.0
        ns_test = 1.0
        for i in range(len(mu)):
            for j in range(i + 1, len(mu)):
                ns_test *= mu[i] * mu[j] - 1.0
        z = self.z(y[:self.N])
        tests = {FOLD: t[-1], PERIOD_DOUBLING: float(np.real(np.prod(mu + 1.0))),
                 NEIMARK_SACKER: float(np.real(ns_test)),
                 GRAZING: mx - self.level if self.level is not None else math.nan}
        return dict(mu=mu, max_X=mx, min_X=mn, contact=contact, tests=tests, period=period,
                    section=(z[:1], z[1:2], z[None, :]), modes=visited,
                    end=_SHRUNK if np.ptp(U, axis=0).max() <= 1e-7 * (1.0 + np.abs(U).max())
                    else None)


def cycle_continuation(params, param: str, section="V", *, k: int = 1, x0: float = 0.0,
                       v0: float = 0.0, u0=None, transient: int = 0, direction: str = "up",
                       step: float = 0.01, max_step: float | None = None, bounds=None,
                       max_points: int = 400, method: str = "exact", tol: float = 1e-10,
                       rtol: float = 1e-10, atol: float = 1e-12,
                       max_time: float = 1e4) -> xr.Dataset:
    """Pseudo-arclength continuation of a branch of limit cycles of a self-excited system in
    ``param``, through folds (``continuation`` calls it for a model without forcing or with a
    ``section``). The first cycle is :func:`limit_cycle`'s from (x0, v0) / ``u0`` after
    ``transient`` crossings (0: 20) at ``params``; a cycle is a fixed point of the k-crossing
    return map of ``section`` (kept as it is at the start: it must not name ``param``), its
    period an unknown. Every point has its nontrivial Floquet multipliers (the trivial one is
    removed by the section), and fold (a multiplier crosses +1, the branch turns), period
    doubling, Neimark-Sacker and grazing points are located on it as for forced orbits.
    Returns the Dataset of :func:`~nonsmooth.continuation` with ``period`` over ``point``
    and the attr ``section``; ``k``: the cycle's crossings of the section per turn (e.g. 2 for
    a section counted both ways). Branch switching (``start``) and section phases are for
    forced orbits."""
    import re

    from ..io import components
    from .continuation import _dataset, _follow, branch_arguments
    text0 = section[0] if isinstance(section, (tuple, list)) and section else section
    params, solver, flow, text = _setup(params, section, method, rtol, atol, max_time,
                                        "continuation")
    param, k, max_points, step, max_step, tol, lo, hi = branch_arguments(
        params, param, k, max_points, step, max_step, tol, direction, bounds)
    if param in (params.model.forcing_amplitude, params.model.forcing_param):
        raise ParameterError(f"param: {param} is the forcing's; a branch of a self-excited "
                             f"system follows one of its own parameters")
    if isinstance(text0, str) and param in re.findall(r"[A-Za-z_]\w*", text0):
        raise ParameterError(f"section: {text0!r} names the continued parameter {param}: a "
                             f"branch needs a section that stays put")
    lc = limit_cycle(params, section, x0=x0, v0=v0, u0=u0, transient=transient or 20,
                     method=method, tol=tol, rtol=rtol, atol=atol, max_time=max_time,
                     crossings=k)
    lam0 = float(getattr(params, param))
    if lc.attrs["status"] != "converged":
        raise ParameterError(f"start: no limit cycle found on {text} at {param} = {lam0:g} "
                             f"({lc.attrs['status']}); try another start (x0, v0, u0) or "
                             f"transient")
    z0 = components(lc, suffix="_section").values
    _, s_start = _start(params, solver, 0.0, 0.0, z0)
    level = params.model.contact_level(params) if params.model.contact_level else None
    br = _CycleBranch(params, param, solver, flow, z0, s_start, k, tol, level)
    N = br.N
    y = np.r_[np.zeros(N), lam0]
    ev = br.evaluate(y[:N], y[N])
    if ev is None:
        raise ParameterError(f"start: the cycle at {param} = {lam0:g} has no return map on "
                             f"{text}")
    sign = 1.0 if direction == "up" else -1.0
    t = br.tangent(ev, np.r_[np.zeros(N), sign])
    if t[N] * sign < 0:
        t = -t
    pts = [(y, br.features(y, ev, t))]
    br, specials, _, status = _follow(br, pts, t, step, max_step, max_points, lo, hi)
    # the specials' points in the state's coordinates (z, lam), as for forced orbits
    specials = [(s[0], s[1], s[2], s[3], np.r_[br.z(s[4][:N]), s[4][N]], *s[5:])
                for s in specials]
    ds = _dataset(params, solver, param, 1, pts, specials, status, params.model.n, direction,
                  (lo, hi))
    ds["period"] = ("point", np.array([f["period"] for _, f in pts]),
                    {"long_name": "period of the limit cycle", "units": "s"})
    for c in ("X_section", "V_section"):
        ds[c].attrs["long_name"] = (f"{c[0]} where the cycle crosses the section")
    ds.attrs.update(section=text, k=k)
    return ds
