"""Section surfaces h(u) = 0 of the autonomous analyses (``section="V"``, ``("X - 0.5",
"increasing")``, a curved ``"X**2 + V**2 - 4"``) and the forcing checks of a self-excited
system: a light module (sympy, no kernels), so that the CLI refuses a bad section or
direction before the kernels load."""

from __future__ import annotations

import math

import numpy as np

from .errors import ParameterError

#: Crossing directions by name and code (the kernel's SEC[0]).
DIRECTIONS = {"decreasing": -1.0, "increasing": 1.0, "both": 0.0}


# ---- the section surface --------------------------------------------------------------------
def parse_section(params, section):
    """(H, direction code, text) of a section given as an expression, or (expression,
    direction): H = (a, b, 0, 0) with h = a . u + b. One-line ParameterErrors name
    ``section``."""
    import sympy as sp

    model = params.model
    direction = "decreasing"
    if isinstance(section, (tuple, list)):
        if len(section) != 2:
            raise ParameterError(f"section: expected an expression or (expression, direction), "
                                 f"got {section!r}")
        section, direction = section
    if direction not in DIRECTIONS:
        raise ParameterError(f"section: direction must be one of {', '.join(DIRECTIONS)}, got "
                             f"{direction!r}")
    if not isinstance(section, str) or not section.strip():
        raise ParameterError(f"section: expected an expression in the state "
                             f"({', '.join(model.state_names)}), got {section!r}")
    states = [sp.Symbol(nm, real=True) for nm in model.state_names]
    names = {nm: s for nm, s in zip(model.state_names, states)}
    names.update({nm: sp.Symbol(nm, real=True) for nm in model.param_names})
    import re
    unknown = sorted({w for w in re.findall(r"[A-Za-z_]\w*", section)} - set(names)
                     - {"sin", "cos", "exp", "log", "sqrt", "pi", "Abs"})
    if unknown:
        raise ParameterError(f"section: unknown name(s) {', '.join(unknown)} in {section!r} "
                             f"(state: {', '.join(model.state_names)}; parameters allowed)")
    try:
        expr = sp.sympify(section, locals=names)
    except (sp.SympifyError, SyntaxError, TypeError):
        raise ParameterError(f"section: cannot read {section!r}: not an expression in the "
                             f"state ({', '.join(model.state_names)}) and the parameters") from None
    unknown = {str(s) for s in expr.free_symbols} - set(names)
    if unknown:
        raise ParameterError(f"section: unknown name(s) {', '.join(sorted(unknown))} in "
                             f"{section!r} (state: {', '.join(model.state_names)}; parameters "
                             f"allowed)")
    if not any(expr.has(x) for x in states):
        raise ParameterError(f"section: {section!r} does not depend on the state")
    text = f"{section} = 0, {direction}"
    fixed = expr.subs({names[nm]: float(getattr(params, nm)) for nm in model.param_names})
    coeffs = [sp.diff(fixed, s) for s in states]
    if all(sp.simplify(sp.diff(c, s)) == 0 for c in coeffs for s in states):
        try:
            a = np.array([float(c) for c in coeffs])
            b = float(fixed.subs({s: 0 for s in states}))
        except TypeError:
            raise ParameterError(f"section: {section!r} is not affine in the state") from None
        if not np.any(a != 0.0) or not np.all(np.isfinite(a)) or not math.isfinite(b):
            raise ParameterError(f"section: {section!r} does not depend on the state")
        return Surface(np.concatenate([a, [b, 0.0, 0.0]]), DIRECTIONS[direction], text)
    pars = [names[nm] for nm in model.param_names]
    return Surface(np.concatenate([np.zeros(model.n), [math.nan, 0.0, 0.0]]),
                   DIRECTIONS[direction], text, curved=(expr, states, pars))


class Surface:
    """A section surface h(u) = 0 crossed in ``direction`` (the kernel's SEC[0]): affine, the
    row H = (a, b, 0, 0) with h = a . u + b; or curved (H[n] NaN), h any smooth expression of
    the state and the parameters, which the kernel evaluates with its gradient through the
    ``curved`` function of :meth:`fns` (``contract.SECTION_K``)."""

    def __init__(self, H, direction, text, curved=None):
        self.H, self.direction, self.text, self.expr = H, direction, text, curved
        n = H.shape[0] - 3
        if curved is None:
            a = H[:n].copy()
            self.value = lambda u, p: float(a @ u[:n] + H[n])
            self.gradient = lambda u, p: a
        else:
            import sympy as sp
            expr, states, pars = curved
            args = (sp.MatrixSymbol("_u", n, 1), sp.MatrixSymbol("_q", len(pars) + 1, 1))
            rep = {x: args[0][i, 0] for i, x in enumerate(states)}
            rep.update({q: args[1][i, 0] for i, q in enumerate(pars)})
            h = sp.lambdify(args, expr.xreplace(rep), "math")
            dh = sp.lambdify(args, [sp.diff(expr, x).xreplace(rep) for x in states], "math")
            col = lambda v: np.asarray(v, float).reshape(-1, 1)  # noqa: E731
            self.value = lambda u, p: float(h(col(u[:n]), col(p)))
            self.gradient = lambda u, p: np.array(dh(col(u[:n]), col(p)), float)

    @property
    def curved(self) -> bool:
        return self.expr is not None

    def basis(self, z, p):
        """An orthonormal basis (n x (n - 1)) of the surface's tangent plane at z."""
        a = self.gradient(z, p)
        return np.linalg.svd(a[None, :])[2][1:].T

    def project(self, z, a, p, iters: int = 8):
        """z moved along the direction ``a`` onto the surface: Newton on h(z + s a) = 0 (at
        most ``iters`` steps; an affine surface in one). NaN where the line misses the
        surface or Newton ends farther than 1e-10 (1 + |z|) from it (h / |grad h|): the
        callers' Newton and continuation steps then fail there and are shortened."""
        z = np.array(z, float)
        if not self.curved:
            return z - (self.value(z, p) / float(a @ a)) * a
        for _ in range(iters):
            h = self.value(z, p)
            d = float(self.gradient(z, p) @ a)
            if not (math.isfinite(h) and d != 0.0):
                break
            z = z - (h / d) * a
            if abs(h) <= 1e-15 * (1.0 + float(np.linalg.norm(z))):
                break
        g = float(np.linalg.norm(self.gradient(z, p)))
        if not abs(self.value(z, p)) <= 1e-10 * (1.0 + float(np.linalg.norm(z))) * g:
            return np.full_like(z, np.nan)
        return z

    def fns(self, fns, model, method):
        """The model's ``fns`` with its ``curved`` function answering the section too (k =
        SECTION_K, SECTION_K + 1 for -h): a small cfunc compiled once per process and
        surface."""
        if not self.curved:
            return fns
        from .integrate.contract import CompiledFunction, ModelFns
        key = (model.name, method, self.text, id(fns))
        got = _SECTION_FNS.get(key)
        if got is None:
            got = _SECTION_FNS[key] = ModelFns(tuple(fns[:6]) + (CompiledFunction(
                _section_cfunc(self.expr, model, model.method(method).curved)),))
        return got


_SECTION_FNS: dict = {}


def _section_cfunc(curved_expr, model, base):
    """The cfunc ``curved(mode, k, t, c, s, u, p, mem, grad)`` of a curved section: k >=
    SECTION_K gives h (SECTION_K) or -h with the gradient (state; 0 for time), any other k the
    model's own ``base`` (its curved guards; NaN when it has none)."""
    import numba as nb
    import sympy as sp
    from sympy.printing.pycode import PythonCodePrinter

    from .integrate.contract import MODEL_SIGNATURES, SECTION_K
    expr, states, pars = curved_expr
    n = len(states)
    names = {x: sp.Symbol(f"_x{i}") for i, x in enumerate(states)}
    names.update({q: sp.Symbol(f"_p{i}") for i, q in enumerate(pars)})
    printer = PythonCodePrinter({"fully_qualified_modules": True, "standard": "python3"})
    reps, red = sp.cse([expr] + [sp.diff(expr, x) for x in states],
                       symbols=sp.numbered_symbols("_w"))
    body = [f"        _x{i} = u[{i}]" for i in range(n)]
    body += [f"        _p{i} = p[{i}]" for i in range(len(pars))]
    body += [f"        {v} = {printer.doprint(e.xreplace(names))}" for v, e in reps]
    body += ["        _sg = 1.0 if k == SECTION_K else -1.0"]
    body += [f"        grad[{i}] = _sg * float({printer.doprint(e.xreplace(names))})"
             for i, e in enumerate(red[1:])]
    body += [f"        grad[{n}] = 0.0",
             f"        return _sg * float({printer.doprint(red[0].xreplace(names))})"]
    src = "\n".join(["def curved(mode, k, t, c, s, u, p, mem, grad):",
                     "    if k >= SECTION_K:", *body,
                     "    return base(mode, k, t, c, s, u, p, mem, grad)" if base is not None
                     else "    return math.nan"]) + "\n"
    ns_ = {"math": math, "SECTION_K": SECTION_K,
           "base": nb.njit(base) if base is not None and not hasattr(base, "py_func") else base}
    exec(compile(src, f"<section {model.name}>", "exec"), ns_)
    return nb.cfunc(MODEL_SIGNATURES[6], error_model="numpy")(ns_["curved"])


def is_forced(params) -> bool:
    """The model's forcing amplitude is not 0 (a model that names none is unforced)."""
    fa = params.model.forcing_amplitude
    return bool(fa and fa in params.model.param_names and float(getattr(params, fa)) != 0.0)


def check_autonomous(params, who: str, solver=None) -> None:
    """A one-line ParameterError if the model's forcing amplitude is not 0 (a model that
    names none is taken as unforced), or, with ``solver``, if its method carries continuous
    memory (the section point would have to include it)."""
    if solver is not None and solver.spec.continuous_memory:
        raise ParameterError(f"{who}: method {solver.method!r} of {params.model.name} carries "
                             f"a continuous memory slot; use another method (e.g. exact)")
    fa = params.model.forcing_amplitude
    if is_forced(params):
        raise ParameterError(f"{who}: the system is forced ({fa} = {getattr(params, fa):g}): "
                             f"set {fa}=0 for a self-excited system, or use the stroboscopic "
                             f"analyses (poincare, periodic_orbit)")
