"""The run Datasets a scaling analysis reads: the variables it needs (:func:`check_run`), a run
file (:func:`load_run`), and a sweep Dataset split into its runs (:func:`iter_runs`).
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .. import _validate as V
from .. import schema

if TYPE_CHECKING:  # annotations only
    import xarray as xr


T = "t"
_PEAK_VARS = ("v_max", "a_max", "sigma_max")
assert all(v in schema.STEP_VARS for v in _PEAK_VARS + ("a_end", "kappa_max", "s_kappa_max"))


def _t(ds) -> np.ndarray:
    return np.asarray(ds[T].values, dtype=float)


def check_run(ds, *, require: tuple[str, ...] = _PEAK_VARS, name: str = "run") -> None:
    """Check that ``ds`` is a run Dataset with the variables the analysis needs.

    Parameters
    ----------
    ds : xarray.Dataset
        A run (:mod:`snapping.schema`).
    require : tuple of str
        Step variables that must be present.
    name : str
        How to call the run in error messages (e.g. its file name).

    Raises
    ------
    SnappingInputError
        Not a Dataset, no time coordinate ``t`` on dimension ``step``, or missing
        variables.

    Examples
    --------
    >>> import xarray as xr
    >>> check_run(xr.Dataset())
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: run is not a run Dataset: no time coordinate 't' along dimension 'step'
    """
    import xarray as xr

    if not isinstance(ds, xr.Dataset):
        raise V.SnappingInputError(f"{name}={type(ds).__name__} is not a run Dataset (expected an xarray.Dataset)")
    if T not in ds.variables or schema.STEP_DIM not in ds[T].dims:
        raise V.SnappingInputError(
            f"{name} is not a run Dataset: no time coordinate {T!r} along dimension {schema.STEP_DIM!r}"
        )
    missing = [v for v in require if v not in ds.variables]
    if missing:
        raise V.SnappingInputError(f"{name} is not a run Dataset: missing variables {missing}")


def load_run(path) -> "xr.Dataset":
    """Open a run file (netCDF4) into memory and check it is a run Dataset.

    Parameters
    ----------
    path : str or Path
        The file written by :mod:`snapping.simulate` (or a sweep file combining runs).

    Returns
    -------
    xarray.Dataset

    Raises
    ------
    SnappingInputError
        Missing or unreadable file, or not a run Dataset.

    Examples
    --------
    >>> load_run("no/such/run.nc")
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: path='no/such/run.nc' does not exist
    """
    import xarray as xr

    p = Path(V.file_path("path", path))
    if not p.exists():
        raise V.SnappingInputError(f"path={str(path)!r} does not exist")
    if not p.is_file():
        raise V.SnappingInputError(f"path={str(path)!r} is not a file")
    try:
        with xr.open_dataset(p) as ds:
            ds = ds.load()
    except Exception as exc:  # netCDF4/h5 raise OSError, ValueError, KeyError ...
        msg = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        raise V.SnappingInputError(
            f"path={str(path)!r} is not a readable netCDF run file ({type(exc).__name__}: {msg[:160]})"
        ) from None
    check_run(ds, name=repr(str(path)))
    return ds


def iter_runs(ds):
    """Split a sweep Dataset (extra dimensions such as ``chi``, ``N``) into runs.

    A plain run is yielded as is. For a sweep (:func:`snapping.sweep.combine`),
    each combination of the extra dimensions gives one run: its steps where ``t``
    is defined, ``t`` as the coordinate, and the sweep coordinates and 0-d summary
    variables (``v_peak``, ...) as attributes.

    Parameters
    ----------
    ds : xarray.Dataset

    Yields
    ------
    xarray.Dataset

    Examples
    --------
    >>> import xarray as xr
    >>> t = np.linspace(0, 1, 6)
    >>> sweep = xr.Dataset({"t": (("chi", "step"), [t, t]), "v_max": (("chi", "step"), [t, 2 * t])},
    ...                    coords={"chi": [0.1, 0.2]})
    >>> [float(r.attrs["chi"]) for r in iter_runs(sweep)]
    [0.1, 0.2]
    """
    check_run(ds, require=("v_max",))
    extra = [d for d in ds["v_max"].dims if d != schema.STEP_DIM]
    if not extra:
        yield ds
        return
    for idx in itertools.product(*(range(ds.sizes[d]) for d in extra)):
        sub = ds.isel(dict(zip(extra, idx)))
        t = np.asarray(sub[T].values, dtype=float)
        keep = np.isfinite(t)
        if keep.sum() < 5:
            continue
        sub = sub.isel({schema.STEP_DIM: np.nonzero(keep)[0]})
        if T not in sub.coords:
            sub = sub.set_coords(T)
        attrs = dict(ds.attrs)
        for d in extra:
            if d in sub.coords:
                val = sub[d].values.item()
                attrs[d] = val
        for k in list(sub.data_vars):
            if sub[k].ndim == 0 and (k in schema.RESULT_ATTRS or k in schema.INPUT_ATTRS):
                val = sub[k].values.item()
                if not (isinstance(val, float) and math.isnan(val)):
                    attrs[k] = val
                sub = sub.drop_vars(k)
        sub = sub.drop_vars([d for d in extra if d in sub.coords])
        sub.attrs = attrs
        yield sub
