"""How unpredictable the final state is, from a basins grid: basin entropy, boundary basin
entropy and the uncertainty exponent (issue 21, item 1).

``basin_entropy(basins_ds, box=5) -> xarray.Dataset``

* **Basin entropy** (Daza, Wagemakers, Georgeot, Guery-Odelin, Sanjuan, Sci. Rep. 6, 31416,
  2016). The grid is tiled by boxes of ``box`` x ``box`` cells; in box i the attractors are
  reached with shares p_ij and the box's Gibbs entropy is S_i = -sum_j p_ij ln p_ij. Then
  S_b = sum_i S_i / N over the N boxes, and the *boundary* basin entropy S_bb = sum_i S_i /
  N_b over the N_b boxes that hold more than one attractor. S_b is 0 for one basin and at most
  ln N_A for N_A attractors (every box a fair mix). S_bb > ln 2 is a sufficient condition for a
  fractal boundary (the "ln 2 criterion": a smooth boundary between two basins splits a box
  into two parts, whose entropy is at most ln 2, and boxes near a smooth boundary are mostly
  unequal mixes). With two attractors S_bb <= ln 2 always: the criterion needs three or more
  (the uncertainty exponent does not). S_i is the plug-in estimate, biased low by about
  (K - 1) / (2 n) for K attractors mixed in a box of n cells: larger boxes for finer values.
* **Uncertainty exponent** (Grebogi, McDonald, Ott, Yorke, Phys. Lett. A 99, 415, 1983): the
  fraction f(eps) of initial conditions whose final state an error of eps can change scales as
  eps^alpha; the boundary's box-counting dimension is d = D - alpha (D = 2 for the plane). It
  is measured here as the share of boxes of e x e cells (e = ``epsilons``) that hold more than
  one attractor, f = N_b / N, and alpha is the slope of ln f against ln eps fitted by least
  squares, with its standard error (boxes that all meet the boundary, f = 1, are its
  plateau alpha = 0, and are fitted too), where eps = e - 1 cell widths is the span of the box's
  sample points (the grid's points are the cells' centres: a straight boundary separates two
  of a box's points with a probability proportional to that span, not to e; with e the fit
  would give 1.2 for a straight line). A smooth boundary has alpha = 1
  (f = eps L / area); a fractal one alpha < 1 (alpha -> 0: riddled basins, unpredictable at any
  resolution).

Cells labelled -1 (undecided or failed) are left out: a box's shares are over its decided
cells, and a box with none is not counted. The numbers depend on the grid (its resolution,
its window): a box must hold enough cells to be a fair sample (box >= 5 is usual), and the
smallest boxes of the exponent's fit must be larger than the grid's cells (eps >= 2).
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from ..errors import ParameterError
from ..io import clean_attrs


def _labels(basins) -> np.ndarray:
    """The 2-D integer label grid of a basins Dataset (or an array)."""
    if isinstance(basins, xr.Dataset):
        if "label" not in basins:
            raise ParameterError("basins: the Dataset has no 'label' variable (expected the "
                                 "result of ns.basins or ns.surface_basins)")
        da = basins["label"]
        if da.dims == ("v0", "x0"):  # surface_basins: X first, as basins
            da = da.transpose("x0", "v0")
        lab = da.values
    else:
        lab = np.asarray(basins)
    if lab.ndim != 2 or min(lab.shape) < 2:
        raise ParameterError(f"basins: labels must form a 2-D grid of at least 2 x 2 cells, "
                             f"got shape {lab.shape}")
    if not np.issubdtype(lab.dtype, np.integer):
        if not np.all(np.isfinite(lab)) or np.any(lab != np.round(lab)):
            raise ParameterError("basins: labels must be integers (-1 = undecided)")
        lab = lab.astype(np.int64)
    return lab.astype(np.int64)


def box_entropies(labels, box: int):
    """Per box of ``box`` x ``box`` cells (the grid tiled from its first cell; a last partial
    row or column of boxes is left out): (S_i, number of attractors in the box, decided cells),
    each an array of shape (nx // box, ny // box)."""
    lab = _labels(labels)
    nx, ny = lab.shape
    bx, by = nx // box, ny // box
    blocks = lab[:bx * box, :by * box].reshape(bx, box, by, box).transpose(0, 2, 1, 3)
    blocks = blocks.reshape(bx, by, box * box)
    n_att = int(lab.max()) + 1 if lab.size else 0
    counts = np.zeros((bx, by, max(n_att, 1)), dtype=np.int64)
    for j in range(n_att):
        counts[:, :, j] = np.count_nonzero(blocks == j, axis=2)
    decided = counts.sum(axis=2)
    with np.errstate(invalid="ignore", divide="ignore"):
        p = counts / decided[:, :, None]
        S = -np.where(p > 0.0, p * np.log(np.where(p > 0.0, p, 1.0)), 0.0).sum(axis=2)
    S[decided == 0] = np.nan
    return S, np.count_nonzero(counts, axis=2), decided


def check_box(box, grid) -> int:
    """``box`` as an int of 2 .. the grid's shorter side (``grid``: a shape or points per
    axis), else a one-line ParameterError."""
    side = min(grid) if isinstance(grid, (tuple, list)) else int(grid)
    if isinstance(box, bool) or not isinstance(box, (int, np.integer)) or not 2 <= box <= side:
        raise ParameterError(f"box: an integer number of cells between 2 and {side} (the "
                             f"grid's shorter side), got {box!r}")
    return int(box)


def _entropy_of(boxes):
    """(S_b, S_bb, N, N_b) of the :func:`box_entropies` ``boxes``."""
    S, k, decided = boxes
    used = decided > 0
    N = int(np.count_nonzero(used))
    Nb = int(np.count_nonzero(k > 1))
    if N == 0:
        return math.nan, math.nan, 0, 0
    total = float(np.nansum(S))
    return total / N, (total / Nb if Nb else 0.0), N, Nb


def default_epsilons(shape) -> np.ndarray:
    """Box sides (cells) for the exponent's fit: from 2 to an eighth of the shorter side
    (at least 4), about geometrically spaced."""
    m = min(shape)
    top = min(max(4, m // 8), m)
    return np.unique(np.round(np.geomspace(2, top, 8)).astype(np.int64)) if m >= 2 else \
        np.array([2])


def uncertainty_exponent(labels, epsilons=None):
    """(alpha, stderr, epsilons, f): the boundary share f = N_b / N of boxes of side e cells
    (``epsilons``) and the least-squares slope alpha of ln f against ln(e - 1) over the sizes
    with f > 0 (NaN with fewer than three)."""
    lab = _labels(labels)
    if epsilons is None:
        eps = default_epsilons(lab.shape)
    else:
        raw = np.asarray(epsilons, dtype=np.float64).ravel()
        if raw.size == 0 or not np.all(np.isfinite(raw)) or np.any(raw != np.round(raw)) or \
                np.any(raw < 2) or np.any(raw > min(lab.shape)):
            raise ParameterError(f"epsilons: box sides must be integers between 2 and "
                                 f"{min(lab.shape)} cells, got {raw.tolist()}")
        eps = np.unique(raw.astype(np.int64))
    f = np.array([nb / max(n, 1) for n, nb in (_entropy_of(box_entropies(lab, int(e)))[2:]
                                               for e in eps)],
                 dtype=np.float64)
    ok = f > 0.0  # (f = 1, every box on the boundary, is the plateau of alpha = 0)
    if np.count_nonzero(ok) < 3:
        return math.nan, math.nan, eps, f
    x, y = np.log(eps[ok].astype(np.float64) - 1.0), np.log(f[ok])
    A = np.vstack([x, np.ones_like(x)]).T
    coef, res, *_ = np.linalg.lstsq(A, y, rcond=None)
    n = x.size
    resid = y - A @ coef
    s2 = float(resid @ resid) / (n - 2) if n > 2 else 0.0
    se = math.sqrt(s2 / float(((x - x.mean()) ** 2).sum()))
    return float(coef[0]), se, eps, f


def basin_entropy(basins, box: int = 5, *, epsilons=None) -> xr.Dataset:
    """Basin entropy S_b, boundary basin entropy S_bb (boxes of ``box`` x ``box`` cells) and
    the uncertainty exponent alpha (box sides ``epsilons`` cells, default
    :func:`default_epsilons`) of a basins grid: the Dataset of :func:`nonsmooth.basins` or
    :func:`nonsmooth.surface_basins` (or a 2-D array of labels, -1 = undecided). See the module
    documentation for the definitions. The result carries the per-box entropy (``box_entropy``,
    for the figure), f(eps) (``boundary_share``), the fit, and the basins' attrs."""
    lab = _labels(basins)
    box = check_box(box, lab.shape)
    S, k, decided = boxes = box_entropies(lab, box)
    Sb, Sbb, N, Nb = _entropy_of(boxes)
    alpha, alpha_se, eps, f = uncertainty_exponent(lab, epsilons)
    n_att = int(lab.max()) + 1 if lab.size else 0
    src = basins.attrs if isinstance(basins, xr.Dataset) else {}
    xname, vname = (("x0", "v0") if isinstance(basins, xr.Dataset)
                    and basins["label"].dims == ("v0", "x0")
                    else tuple(basins["label"].dims) if isinstance(basins, xr.Dataset)
                    else ("x0", "v0"))
    coords = {}
    if isinstance(basins, xr.Dataset):
        for c, nb in ((xname, S.shape[0]), (vname, S.shape[1])):
            vals = basins[c].values[:nb * box].reshape(nb, box).mean(axis=1)
            coords[f"box_{c}"] = (f"box_{c}", vals, {
                **basins[c].attrs, "long_name": f"box centre: {basins[c].attrs.get('long_name', c)}"})
    else:
        coords = {f"box_{xname}": np.arange(S.shape[0]), f"box_{vname}": np.arange(S.shape[1])}
    fractal = int(Sbb > math.log(2.0)) if math.isfinite(Sbb) else 0
    attrs = {k2: v for k2, v in src.items() if k2 != "analysis"}
    attrs.update(analysis="basin_entropy", basins_analysis=src.get("analysis", ""),
                 box=box, n_attractors=n_att, undecided_cells=int(np.count_nonzero(lab < 0)),
                 reference="A. Daza et al., Sci. Rep. 6, 31416 (2016); C. Grebogi et al., "
                           "Phys. Lett. A 99, 415 (1983)")
    ds = xr.Dataset(
        {
            "basin_entropy": ((), Sb, {
                "long_name": "basin entropy S_b: mean Gibbs entropy of the boxes", "units": "1",
                "box_cells": box}),
            "boundary_basin_entropy": ((), Sbb, {
                "long_name": "boundary basin entropy S_bb: mean entropy of the boxes that hold "
                             "more than one attractor (0 where none does)", "units": "1",
                "box_cells": box}),
            "fractal_boundary": ((), np.int8(fractal), {
                "long_name": "S_bb > ln 2 (a sufficient condition for a fractal boundary; 0: "
                             "not shown)", "flag_values": np.array([0, 1], np.int8),
                "flag_meanings": "not_shown fractal"}),
            "boxes": ((), N, {"long_name": "boxes with a decided cell", "units": "1"}),
            "boundary_boxes": ((), Nb, {"long_name": "boxes that hold more than one attractor",
                                        "units": "1"}),
            "uncertainty_exponent": ((), alpha, {
                "long_name": "uncertainty exponent alpha: f(eps) ~ eps^alpha (1: smooth "
                             "boundary; boundary dimension 2 - alpha)", "units": "1"}),
            "uncertainty_exponent_stderr": ((), alpha_se, {
                "long_name": "standard error of the fitted uncertainty exponent", "units": "1"}),
            "boundary_share": (("epsilon",), f, {
                "long_name": "share f(eps) of the boxes of side eps that hold more than one "
                             "attractor", "units": "1"}),
            "box_entropy": ((f"box_{xname}", f"box_{vname}"), S, {
                "long_name": "Gibbs entropy of the box (NaN: no decided cell)", "units": "1"}),
            "box_attractors": ((f"box_{xname}", f"box_{vname}"), k.astype(np.int32), {
                "long_name": "attractors reached from the box", "units": "1"}),
        },
        coords={"epsilon": ("epsilon", eps, {"long_name": "box side e in grid cells (the fit's "
                                                  "scale: e - 1 cell widths)", "units": "1"}),
                **coords},
        attrs=clean_attrs(attrs),
    )
    return ds
