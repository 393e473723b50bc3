"""Reading a start shape from a file: CSV (two columns x, y) or netCDF (variables x, y)."""

from __future__ import annotations

import numpy as np

from .. import _validate as V


def read_shape(path) -> tuple[np.ndarray, np.ndarray]:
    """Points (x, y) of a start curve from a CSV file (two columns x, y; a header line is
    skipped) or a netCDF file (variables ``x`` and ``y``), listed from the held end; the
    curve is translated so that its first point (the held end) is at the origin."""
    from .._files import check_input

    p = check_input(path, name="shape")
    if p.endswith((".nc", ".nc4", ".cdf")):
        from ._netcdf import open_netcdf

        ds = open_netcdf(p)
        if "x" not in ds.variables or "y" not in ds.variables:
            raise V.SnappingInputError(f"shape={p!r}: a netCDF shape file needs variables x and y; it has "
                                       f"{sorted(map(str, ds.variables))[:6]}")
        if ds["x"].ndim != 1 or ds["y"].ndim != 1:
            raise V.SnappingInputError(f"shape={p!r}: x and y must be 1-D (one point each along the curve); got "
                                       f"dimensions {ds['x'].dims} and {ds['y'].dims}")
        x, y = (np.asarray(ds[k].values, dtype=float) for k in ("x", "y"))
    else:
        import warnings

        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # (an empty file warns; it is refused below)
                a = np.genfromtxt(p, delimiter=",", dtype=float, comments="#")
        except (OSError, ValueError) as exc:
            first = (str(exc).strip().splitlines() or [""])[-1][:160]
            raise V.SnappingInputError(f"shape={p!r}: cannot read it as CSV of two columns x, y ({first})") from None
        a = np.atleast_2d(a)
        if a.ndim != 2 or a.shape[1] != 2 or a.shape[0] == 0:
            raise V.SnappingInputError(f"shape={p!r}: expected two comma-separated columns x, y; got "
                                       f"{a.shape[1] if a.ndim == 2 else 0} columns")
        if np.all(np.isnan(a[0])):  # a header line reads as NaN: only the first row may be one
            a = a[1:]
        bad = np.flatnonzero(np.any(np.isnan(a), axis=1))
        if bad.size:
            raise V.SnappingInputError(f"shape={p!r}: data row {int(bad[0]) + 1} is not two numbers x, y (only the "
                                       f"first line may be a header)")
        x, y = a[:, 0], a[:, 1]
    if x.size < 2 or not np.all(np.isfinite(x) & np.isfinite(y)):
        raise V.SnappingInputError(f"shape={p!r}: needs at least 2 finite points (x, y); got {x.size}")
    return x - x[0], y - y[0]
