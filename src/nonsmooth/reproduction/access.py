"""Reading the analyses' results: the one place that knows where a result is stored (a scalar
data variable or an attribute; true extrema of X), so that the figures read every result the
same way."""

from __future__ import annotations

import numpy as np


def value(ds, name: str, default=float("nan")):
    """Scalar result ``name`` of an analysis Dataset: a 0-d data variable, else an attribute,
    else ``default``."""
    if name in ds.data_vars and ds[name].ndim == 0:
        return ds[name].values.item()
    return ds.attrs.get(name, default)


def number(ds, name: str) -> float:
    """:func:`value` as a float (NaN when missing or not a number)."""
    try:
        return float(value(ds, name))
    except (TypeError, ValueError):
        return float("nan")


def x_extrema(ds, start: int = 0) -> tuple[float, float]:
    """(max, min) of X of a ``simulate`` Dataset over the sample intervals after sample
    ``start``: the kernels' true extrema (``X_max``, ``X_min``, interior extrema included),
    not the extremes of the samples."""
    return (float(np.nanmax(ds["X_max"].values[start + 1:])),
            float(np.nanmin(ds["X_min"].values[start + 1:])))
