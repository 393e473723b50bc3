"""Reading netCDF files: the one opener every reader shares (run files, checkpoints,
shape files), and the step records of a run Dataset.

It imports nothing of :mod:`snapping.simulate` but the record names (``kernels``, ``general``), so that the start
of the data flow (:mod:`snapping.simulate.problem` reading a shape file, the engines
restoring a checkpoint) can read files without importing :mod:`snapping.simulate.dataset`,
which is at its end.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from .. import _validate as V
from . import kernels as K


def records_from_dataset(ds: xr.Dataset) -> np.ndarray:
    """The per-step record rows (columns ``kernels.RECORD_NAMES``) of a run Dataset:
    the inverse of :func:`build_dataset` for the step variables (exact)."""
    from . import general as G

    from .. import schema

    names = K.RECORD_NAMES + (G.RECORD_NAMES_G if G.RECORD_NAMES_G[0] in ds.variables else ())
    names += tuple(schema.BODY_STEP_VARS) if "bending_energy" in ds.variables else ()
    n = ds.sizes.get(schema.STEP_DIM, 0)
    # (a column added later, e.g. v_rel_max, is NaN in the files written before it)
    cols = [np.asarray(ds[name].values, dtype=float) if name in ds.variables else np.full(n, np.nan)
            for name in names]
    return np.stack(cols, axis=1) if cols[0].size else np.zeros((0, len(names)))


def open_netcdf(p: str) -> xr.Dataset:
    """The netCDF file at path ``p`` loaded into memory (the file is closed), or
    SnappingInputError saying why it cannot be read."""
    from .. import _files

    p = _files.check_input(p)
    try:
        with xr.open_dataset(p, engine="netcdf4") as f:
            return f.load()
    except Exception as exc:  # netCDF4/HDF5 raise OSError, ValueError, KeyError, ...
        msg = (str(exc).strip().splitlines() or [""])[0][:160]
        raise V.SnappingInputError(f"path={p!r} is not a readable netCDF run file ({type(exc).__name__}: {msg})") from None
