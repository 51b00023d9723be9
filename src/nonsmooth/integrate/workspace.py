"""Work arrays of a kernel that cost no reference counting.

numba counts references to every array it passes to a function it does not inline (a model's
compiled ``field`` through its pointer, a helper of the kernel): an atomic increment and
decrement of the array's meminfo per array per call. In the generic kernel's inner loop (six
field calls per RKF45 step with four arrays each) those atomics took about 60 % of the time.
An array with a null meminfo costs nothing there (numba's ``NRT_incref``/``NRT_decref`` return
at once on null). :func:`view` makes such arrays: C-contiguous views into one float64
workspace, which the kernel allocates once per call and keeps alive to its end
(:func:`keep_alive`); :func:`unowned` makes one of an array whose owner outlives the call (an
argument of the kernel).
"""

from __future__ import annotations

import numba as nb
from numba import types
from numba.extending import intrinsic
from numba.np.arrayobj import make_array, populate_array


@intrinsic
def view(typingctx, ws, offset, shape):
    """A C-contiguous float64 array of ``shape`` (a tuple of ints) over ``ws[offset:]``, with
    no meminfo: it does not keep ``ws`` alive, so the caller must (:func:`keep_alive`)."""
    if not (isinstance(ws, types.Array) and ws.dtype == types.float64 and ws.layout == "C"
            and isinstance(shape, types.BaseTuple)):
        return None
    ndim = len(shape)
    ret = types.Array(types.float64, ndim, "C")

    def codegen(context, builder, sig, args):
        src = make_array(sig.args[0])(context, builder, value=args[0])
        off = context.cast(builder, args[1], sig.args[1], types.intp)
        dims = [context.cast(builder, builder.extract_value(args[2], i), sig.args[2][i],
                             types.intp) for i in range(ndim)]
        itemsize = context.get_constant(types.intp, 8)
        strides = []
        acc = itemsize
        for d in reversed(dims):
            strides.insert(0, acc)
            acc = builder.mul(acc, d)
        out = make_array(ret)(context, builder)
        populate_array(out, data=builder.gep(src.data, [off]), shape=dims, strides=strides,
                       itemsize=itemsize, meminfo=None)
        return out._getvalue()

    return ret(ws, offset, shape), codegen


@intrinsic
def unowned(typingctx, arr):
    """``arr`` without its meminfo (same data, shape and strides): for an array that its owner
    keeps alive for longer than the result is used."""
    if not isinstance(arr, types.Array):
        return None

    def codegen(context, builder, sig, args):
        a = make_array(sig.args[0])(context, builder, value=args[0])
        out = make_array(sig.return_type)(context, builder)
        populate_array(out, data=a.data, shape=a.shape, strides=a.strides, itemsize=a.itemsize,
                       meminfo=None)
        return out._getvalue()

    return arr(arr), codegen


@nb.njit(cache=True)
def keep_alive(ws):
    """A use of ``ws`` (numba releases an array after its last use): call it where the views
    of ``ws`` are no longer used."""
    return ws.shape[0]
