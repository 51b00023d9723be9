"""The contract every trajectory kernel implements (the generic kernel of :mod:`.hybrid` for
any model, and the built-in models' specialised kernels).

A kernel ``advance(p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin) -> status``
(the generic one takes the model's compiled functions first: ``advance_generic(fns, p, ...)``)
integrates from a forcing-period boundary (local time t_s = ``opts[OPT_PHASE]`` / omega, 0
by default; the specialised kernels know only 0) over ``n_skip + n_out`` output intervals of
length T / ``per_period`` (T = 2 pi / omega); the local time is reset to t_s at every period
boundary, so the numbers do not depend on how a run is split into calls that each start
on a period boundary. For output k (0 <= k < n_out), at the end of interval ``n_skip + k``:

* ``X[k], V[k]``  the state (u[0], u[1] of the model's state u);
* ``R[k]``        the mode code at that instant (int8; the model's ``mode_names``);
* ``M[k]``        bit mask of the modes visited during the interval (uint8, bit r = mode r);
* ``Xmax[k], Xmin[k]``  the extremes of X over the interval (interior extrema included).

``p`` is the model's packed parameters (``params.pack()``, order ``model.param_names``);
``opts`` and ``state`` are float64 arrays with the layouts below; ``state`` is updated in place
so that the next call continues the same trajectory (u[2:] and the model's memory live in
``state[ST_EXTRA:]``). ``fns`` is the tuple of the model's compiled functions with the
signatures ``MODEL_SIGNATURES`` (see :mod:`nonsmooth.models.base` for their meaning). Kernels
never print or raise: they return a status code from :mod:`nonsmooth.status`.
"""

# opts layout
OPT_RTOL = 0
OPT_ATOL = 1
OPT_MAX_STEPS = 2  # steps allowed per forcing period, on average over a call
OPT_VARIANT = 3  # Method.variant: a specialised kernel's variant (support smooth: 0 eq. 13, 1 eq. 12)
OPT_OMEGA = 4  # index of the forcing frequency omega in p (generic kernel)
OPT_N = 5  # state dimension n >= 2 (generic kernel)
OPT_NMEM = 6  # number of discrete memory slots (generic kernel)
OPT_CLOSED_FORM = 7  # 1: propagate the modes a model declares linear in closed form (generic)
OPT_PHASE = 8  # forcing phase psi = omega t_s of the section (generic): periods start at t_s
OPT_FRAME_PERIOD = 9  # 1: p[opts[OPT_OMEGA]] is the forcing period T, omega = 2 pi / T
OPT_NO_DOP853 = 10  # 1: the RKF45 even below rk8.HI_ORDER_RTOL (Method.dop853 False; generic)
OPT_NO_EXTREMA = 11  # 1: no interior extrema of X (Xmax/Xmin outputs: the ends of the steps
#                      only; generic): a tangent run whose outputs nobody reads (lambda1 evidence)
N_OPTS = 12

# state layout
ST_X = 0
ST_V = 1
ST_VA = 2  # entry velocity into Sigma_alpha (eq. 13a memory); unused by the exact model
ST_MODE = 3  # region/mode code; -1 = classify from (X, V) at the start
ST_H = 4  # step size to try next (adaptive kernels); <= 0 = choose
ST_EXTRA = 5  # generic kernel: u[2:n], then the memory mem[0:n_mem]
N_STATE = 16  # so n - 2 + n_mem <= N_STATE - ST_EXTRA = 11

#: Largest number of switching surfaces (guards) one mode may watch.
MAX_GUARDS = 8

#: A guard row whose constant column ``G[k, n]`` holds NaN is a *curved* guard: the kernel
#: evaluates it, with its gradient, by the model's ``curved(mode, k, t, c, s, u, p, mem, grad)``
#: (``models.base.curved_row`` writes such a row); every other row is affine.

#: A curved row with G[k, n + 1] = 1 is a *label* (``models.oscillator.label_row``): the mode
#: on its other side has the same field, the transition resets nothing, and it is the only
#: surface of both modes (a smoothed method's modes that only name the side of a surface). The
#: kernel does not locate its crossing: it switches the mode at the end of the first step that
#: ends on the other side (no tangent saltation, which would be the identity); a pass and
#: return inside a step that the Hermite of (g, g') at its ends shows adds the mode across to
#: the visited mask (one shorter than that, a graze of a step's size, is not seen).

#: A section surface ``H`` whose constant entry ``H[n]`` is NaN is curved: the kernel evaluates
#: it through the ``curved`` function of ``fns`` with k = SECTION_K (h) or SECTION_K + 1 (-h,
#: the row's other orientation), which a curved section's ``fns`` answer (see
#: ``analysis.autonomous``); no model guard has so large an index (MAX_GUARDS).
SECTION_K = 64


def _quiet_first_class_functions():
    """First-class functions are "experimental" in numba, and numba warns each time it types a
    tuple of them, i.e. on every call that passes a model's ``fns`` from Python (with ``-W
    error`` that call would fail). They are what keeps kernels taking a model's functions
    cacheable (see ``kernels.py``), so that one warning is silenced where numba emits it."""
    import functools
    import warnings

    from numba.core import utils

    original = utils.unified_function_type
    if getattr(original, "_nonsmooth_quiet", False):
        return

    @functools.wraps(original)
    def quiet(*args, **kwargs):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", category=numba.NumbaExperimentalFeatureWarning)
            return original(*args, **kwargs)

    import numba
    quiet._nonsmooth_quiet = True
    utils.unified_function_type = quiet


def _model_signatures():
    from numba import types as t

    _quiet_first_class_functions()

    i8, f8 = t.int64, t.float64
    a1 = t.float64[::1]
    a2 = t.float64[:, ::1]
    field = i8(i8, f8, f8, f8, a1, a1, a1, a1)
    jacobian = i8(i8, f8, f8, f8, a1, a1, a1, a2)
    guards = i8(i8, a1, a1, a2)
    transition = i8(i8, i8, f8, f8, f8, a1, a1, a1)
    initial = i8(f8, f8, a1, a1, a1)
    linear = i8(i8, a1, a1)
    curved = f8(i8, i8, f8, f8, f8, a1, a1, a1, a1)
    sigs = (field, jacobian, guards, transition, initial, linear, curved)
    return sigs, t.Tuple(tuple(t.FunctionType(s) for s in sigs))


class ModelFns(tuple):
    """A model's compiled functions (the ``fns`` tuple of the generic kernel). numba types it
    by a direct lookup (``MODEL_FNS_TYPE``) instead of typing each first-class function on
    every call from Python (~60 us per call), and unboxes each element from its cached
    address (:class:`CompiledFunction`)."""

    __slots__ = ()


class CompiledFunction:
    """A compiled ``cfunc`` with its machine-code addresses looked up once (numba's wrapper
    address protocol): numba would otherwise ask LLVM for the address of every function on
    every call from Python. ``jit_address`` is the native function behind the C wrapper:
    compiled code calls a first-class function there when it has one (numba's calling
    convention, no C wrapper rebuilding the arrays between), which numba looks up by
    ``_get_jit_address`` for its own dispatchers only (extended here).
    A model function must not raise (its cfunc is compiled with ``error_model="numpy"``):
    an exception would end the kernel early."""

    __slots__ = ("cfunc", "address", "jit_address")

    def __init__(self, cfunc):
        self.cfunc = cfunc
        self.address = cfunc.address
        wrapper = cfunc.native_name  # "cfunc." + the native function's symbol
        self.jit_address = (cfunc._library.get_pointer_to_function(wrapper[len("cfunc."):])
                            if wrapper.startswith("cfunc.") else 0)

    def __wrapper_address__(self, sig=None):
        return self.address


def _register_jit_address():
    """numba unboxes a first-class function with the native address that
    ``function_type._get_jit_address`` gives (looked up by name when compiled code unboxes
    one); give a :class:`CompiledFunction`'s."""
    from numba.experimental import function_type

    numba_lookup = getattr(function_type, "_get_jit_address", None)
    if numba_lookup is None:  # another numba: its C wrappers are called, as before
        return

    def _get_jit_address(func, sig):
        if isinstance(func, CompiledFunction) and func.jit_address > 0:
            return func.jit_address
        return numba_lookup(func, sig)
    function_type._get_jit_address = _get_jit_address


def _register_typeof():
    from numba.extending import typeof_impl

    @typeof_impl.register(ModelFns)
    def _typeof_model_fns(val, c):
        return MODEL_FNS_TYPE


#: numba signatures of a model's compiled functions (see ``nonsmooth.models.base``), in the
#: order of the tuple ``fns`` that the generic kernel receives, and the type of that tuple.
MODEL_SIGNATURES, MODEL_FNS_TYPE = _model_signatures()
(FIELD_SIG, JACOBIAN_SIG, GUARDS_SIG, TRANSITION_SIG, INITIAL_SIG, LINEAR_SIG,
 CURVED_SIG) = MODEL_SIGNATURES
_register_typeof()
_register_jit_address()


def _signatures():
    from numba import types as t

    f8 = t.float64[:]  # any layout: the kernels touch these arrays once per call or interval
    args = (f8, f8, f8, t.int64, t.int64, t.int64, f8, f8, t.int8[:], t.uint8[:], f8, f8)
    tangent = (t.float64[:, ::1], t.float64[:, ::1], t.int64[::1], t.int64, t.float64[:, ::1],
               t.float64[::1], t.float64[::1], t.float64[:, ::1], t.float64[::1])
    return (t.int64(*args), t.int64(MODEL_FNS_TYPE, *args),
            t.int64(t.int64, MODEL_FNS_TYPE, *args), t.int64(MODEL_FNS_TYPE, *args, *tangent))


#: Explicit numba signatures of a kernel, of the method dispatcher and of the tangent kernel
#: (``hybrid.advance_tangent``: the generic kernel's arguments, then Y, L_out, cmi, qr, U_out,
#: H, SEC, U_sec, T_sec).
#: Compiling the kernels for exactly these types means one machine-code version each: without
#: them numba would compile (and cache) a new copy of every kernel for each combination of
#: literal integers that a caller happens to pass.
KERNEL_SIGNATURE, GENERIC_KERNEL_SIGNATURE, DISPATCH_SIGNATURE, TANGENT_KERNEL_SIGNATURE = (
    _signatures())


class KernelFunction:
    """A kernel (``hybrid.advance_generic``, ``hybrid.advance_tangent``, or a specialised kernel
    behind the generic signature) as a numba first-class function. The compiled cores that run
    many trajectories take it as an argument (``KERNEL_FN_TYPE`` / ``TANGENT_FN_TYPE``) and call
    it through its address: a core that called a kernel by name would have numba link the
    kernel's machine code into the core and optimise it again there, about 10 s of compiling
    for each parallel core on an empty cache (0.5 s this way), and a kernel compiled per model
    would recompile every core. The address (numba's wrapper address protocol) is looked up
    once per process. Called this way, through its C wrapper as the model's functions are, a
    kernel must never raise (the kernel contract: a status code, never an exception): numba's
    wrapper would print an exception and return 0 (``status.OK``)."""

    __slots__ = ("dispatcher", "type", "address")

    def __init__(self, dispatcher, signature):
        from numba import types as t
        from numba.experimental.function_type import _get_wrapper_address
        self.dispatcher = dispatcher
        self.type = t.FunctionType(signature)
        self.address = _get_wrapper_address(dispatcher, signature)

    def __wrapper_address__(self, sig=None):
        return self.address


def _register_kernel_typeof():
    from numba.extending import typeof_impl

    @typeof_impl.register(KernelFunction)
    def _typeof_kernel(val, c):
        return val.type


def _kernel_fn_types():
    from numba import types as t
    return t.FunctionType(GENERIC_KERNEL_SIGNATURE), t.FunctionType(TANGENT_KERNEL_SIGNATURE)


#: numba types of a kernel passed as an argument (:class:`KernelFunction`): the generic
#: signature (``fns`` first) and the tangent kernel's.
KERNEL_FN_TYPE, TANGENT_FN_TYPE = _kernel_fn_types()
_register_kernel_typeof()
