"""The order in which ``basins`` visits the grid (coarse to fine, in rounds) and the pace of
its compiled calls (slices)."""

from __future__ import annotations

import math
import time

import numba as nb
import numpy as np

from ... import sweep

_CHUNK_MAX = 16384  # largest round
_SLICE_FACTOR = 2.0  # a compiled call of a round: about 2 x sweep.SLICE_SECONDS (<= 0.2 s)


class _Pace:
    """Trajectory-periods per compiled call, sized from the speed of the previous call so that
    each call returns to Python after about _SLICE_FACTOR x ``sweep.SLICE_SECONDS`` (Ctrl-C,
    progress; every parallel call ends in a barrier that costs more on a loaded machine). Unlike
    ``sweep.Slicer`` it counts the work actually done: points decided early use less than their
    share (``fill``, the share used in the previous call, at least 1/4), so the shares grow and
    a short round is one call. Never changes a result (split invariance)."""

    def __init__(self, first: int):
        self.size = max(1, int(first))
        self.fill = 1.0

    def share(self, unit: int) -> int:
        """Items (of ``unit`` periods) or periods per item (of ``unit`` items) per call."""
        return max(1, int(self.size / (unit * self.fill)))

    def run(self, call, items, nominal):
        """``call()`` over ``items`` independent points, at most ``nominal`` periods (in
        chunks of at most 8 points, fewer when they are few: the call ends with less waiting),
        returns the periods it did."""
        old = nb.get_parallel_chunksize()
        nb.set_parallel_chunksize(max(1, min(8, items // (8 * nb.get_num_threads()))))
        t0 = time.perf_counter()
        try:
            with sweep.deferred_interrupts():
                done = call()
        finally:
            nb.set_parallel_chunksize(old)
        dt = time.perf_counter() - t0
        size = max(1, int(done / max(dt, 1e-9) * _SLICE_FACTOR * sweep.SLICE_SECONDS))
        # a call that ended early (its points decided) timed mostly the call itself: keep
        # the larger size measured on a full call
        self.size = size if 2 * done >= self.size else max(self.size, size)
        self.fill = min(1.0, max(0.25, done / max(nominal, 1)))


def _coarse_to_fine_order(nx: int, nv: int):
    """Flat indices (ix * nv + iv) ordered coarse sub-grids first, then by index; and the
    number of points of the coarsest sub-grid (the first round)."""
    L = max(0, int(math.floor(math.log2(max(nx, nv) / 4.0))))
    ix, iv = np.meshgrid(np.arange(nx), np.arange(nv), indexing="ij")

    def tz(a):
        out = np.full(a.shape, L)
        for lev in range(L - 1, -1, -1):
            out[(a % (2 ** (lev + 1))) != 0] = lev
        return out

    level = np.minimum(tz(ix), tz(iv)).ravel()
    idx = np.arange(nx * nv)
    return idx[np.lexsort((idx, -level))], int(np.count_nonzero(level == L))


def _round_sizes(n: int, first: int):
    size, start = max(1, first), 0
    while start < n:
        b = min(n, start + size)
        yield start, b
        start = b
        size = min(_CHUNK_MAX, size * 4)
