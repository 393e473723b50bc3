"""A sweep's files: each run written atomically and known complete, and the finished runs
combined into one Dataset over (chi, N) (:func:`combine`), checked to share every input that
changes the numbers; the combined file is checked to hold this grid's runs before it is
replaced (:func:`check_combined`)."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from . import _validate as V
from . import schema
from .sweep_failures import _one_line
from .sweep_grid import Grid, grid_key

if TYPE_CHECKING:  # annotations only
    import xarray as xr


def atomic_to_netcdf(ds, path, *, overwrite: bool = True) -> Path:
    """Write ``ds`` to ``path`` as netCDF4 atomically (:func:`snapping.simulate.save`: a
    temporary file in the same directory, flushed and renamed over ``path``, under the
    file's lock), creating the directory. A reader never sees a half-written file.
    """
    from .simulate.dataset import save

    path = Path(V.file_path("path", path))
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise V.SnappingInputError(f"path={str(path)!r}: directory cannot be created ({exc.strerror or exc})") from None
    return Path(save(ds, path, overwrite=overwrite))


def is_complete_run(path) -> bool:
    """True if ``path`` is a readable run file whose status is 'completed'."""
    import xarray as xr

    path = Path(path)
    if not path.is_file():
        return False
    try:
        with xr.open_dataset(path, engine="netcdf4") as ds:
            return ds.attrs.get("status") == "completed"
    except Exception:
        return False


def check_combined(path, grid: Grid, *, overwrite: bool = False) -> Path:
    """Refuse to replace the combined sweep file ``path`` when it holds another grid
    (unless ``overwrite``): two sweeps into one directory would silently swap its
    ``sweep.nc``. The same grid's file is replaced by its update."""
    import xarray as xr

    from ._files import check_output

    path = Path(path)
    if not os.path.lexists(path):
        return path
    check_output(path, name="output", overwrite=True)  # a regular file (not a device, FIFO, ...)
    if overwrite:
        return path
    held = None
    try:
        with xr.open_dataset(path, engine="netcdf4") as ds:
            held = ds.attrs.get("sweep_grid")
    except Exception:  # not a netCDF file: it is not ours to replace
        pass
    if held != grid_key(grid):
        what = "a sweep of another grid" if held else "a file that is not this sweep's combined runs"
        if held:
            g = json.loads(held)
            what += f" (chi={g['chi']}, N={g['N']}, options={g['options']})"
        raise V.SnappingInputError(f"output={str(path)!r} holds {what}: give this sweep its own -o directory, or "
                                   f"--overwrite (overwrite=True) to replace that file")
    return path


_RUN_DIMS = (schema.STEP_DIM, schema.SNAPSHOT_DIM, schema.NODE_DIM, schema.LINK_DIM)

#: Global result attributes that become (chi, N) variables of a combined sweep.
_SUMMARY_ATTRS = [k for k in schema.RESULT_ATTRS if k not in ("status", "stop_reason", "snapping_version")] + \
    [k for k in schema.ELASTIC_RESULT_ATTRS if k not in schema.RESULT_ATTRS]


#: Inputs that must agree between the runs of one combined sweep (``dt0`` too for the
#: Euler-Richardson methods, where it is the step the user chose; the angle-form methods
#: compute their own per run). The combined Dataset keeps them as attributes.
COMBINE_SAME_INPUTS = ("method", "tol", "t_end", "stop_fraction", "t_end_max", "record_thin", "chords", "initial",
                       "max_link_error", "max_energy_drift", "dt_min", "max_rejections")


#: Inputs of the extensible line's runs (snapping.sweep_elastic) that must agree too.
_ELASTIC_INPUTS = ("model", "elastic", "start")


def _same(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape:
        return False
    if a.dtype.kind in "fc" and b.dtype.kind in "fc":
        return bool(np.array_equal(a, b, equal_nan=True))
    return bool(np.all(a == b))


def _problem_key(text) -> str:
    """A run's problem description (its ``problem`` attribute) without what a grid varies (the
    number of links, chi): what must agree between the runs of one combined sweep."""
    try:
        d = json.loads(str(text))
        d.get("chain", {}).pop("N", None)
        d.get("start", {}).pop("chi", None)
        return json.dumps(d, sort_keys=True)
    except (ValueError, AttributeError):
        return str(text)


def _run_piece(item, i: int):
    """(name, run Dataset) of one entry of :func:`combine`: a run file or a run Dataset,
    checked to be a completed run of the paper's problem (SnappingInputError if not)."""
    import xarray as xr

    from .simulate.dataset import load_run

    if isinstance(item, xr.Dataset):
        name, ds = f"paths[{i}] (a Dataset)", item
        if "t" not in ds.variables or "N" not in ds.attrs:
            raise V.SnappingInputError(f"{name} is not a snapping run (no time 't' or attribute 'N'; variables: "
                                       f"{sorted(map(str, ds.variables))[:6]})")
    else:
        path = Path(V.file_path("paths", item))
        name, ds = repr(str(path)), load_run(path)
    for key in ("chi", "N", "status", "method", "tol"):
        if key not in ds.attrs:
            raise V.SnappingInputError(f"{name} is not a run: attribute {key!r} is missing")
    if not np.isfinite(float(ds.attrs["chi"])):
        raise V.SnappingInputError(f"{name} is a run without chi (a general problem or another start): combine "
                                   f"takes runs of the paper's catenary, indexed by (chi, N)")
    if str(ds.attrs["status"]) != "completed":
        raise V.SnappingInputError(f"{name} is not a completed run (status={str(ds.attrs['status'])!r}: "
                                   f"{_one_line(ds.attrs.get('stop_reason', ''))}); combine takes completed runs")
    return name, ds


def combine(paths) -> "xr.Dataset":
    """Combine run files into one Dataset with ``chi`` and ``N`` dimensions.

    Per-step and profile variables keep their ``step``/``snapshot``/``node``/``link``
    dimensions (padded with NaN where runs differ in length); the numeric result
    attributes of each run (``v_peak``, ``t_snap_v``, ``snap_reached``, ...) become
    variables over (chi, N).

    ``paths`` lists run files (or run Datasets). Each must be a completed run of the
    paper's catenary (a sweep's run); anything else (another program's Dataset, a
    combined sweep, a failed or checkpointed run) is refused with a
    :class:`SnappingInputError` naming it. The runs must share their method and every
    input that changes the numbers (:data:`COMBINE_SAME_INPUTS`): runs of different
    methods or tolerances are refused, naming the input and the files that differ,
    instead of being combined into one table that no longer says which is which. The
    shared inputs are the combined Dataset's attributes (``method``, ``tol``, ...).
    """
    import xarray as xr

    if isinstance(paths, (str, os.PathLike, xr.Dataset)) or not hasattr(paths, "__iter__"):
        raise V.SnappingInputError(f"paths={type(paths).__name__ if isinstance(paths, xr.Dataset) else paths!r} "
                                   f"must be a list of run files")
    items = list(paths)
    if not items:
        raise V.SnappingInputError("combine needs at least one run file")
    pieces, names, inputs = [], [], []
    for i, item in enumerate(items):
        name, ds = _run_piece(item, i)
        keys = COMBINE_SAME_INPUTS + ("body",) + _ELASTIC_INPUTS + (
            ("dt0",) if str(ds.attrs["method"]).startswith("euler-richardson") else ())
        inputs.append({k: (ds.attrs[k].item() if isinstance(ds.attrs[k], np.generic) else ds.attrs[k])
                       for k in keys if k in ds.attrs})
        if "problem" in ds.attrs:  # a general problem's chain, held end and gravity: compared and kept too
            inputs[-1]["problem"] = _problem_key(ds.attrs["problem"])
        names.append(name)
        chi, N = float(ds.attrs["chi"]), int(ds.attrs["N"])
        summary = {
            k: ((), float(ds.attrs[k]), {"long_name": {**schema.ELASTIC_RESULT_ATTRS, **schema.RESULT_ATTRS}[k],
                                         "units": schema.result_units(k)})
            for k in _SUMMARY_ATTRS
            if k in ds.attrs and np.isscalar(ds.attrs[k]) and not isinstance(ds.attrs[k], str)
        }
        ds = ds.reset_coords().assign(summary)
        # integer indices on the run dimensions so that runs of different lengths pad with NaN
        ds = ds.assign_coords({d: np.arange(ds.sizes[d]) for d in _RUN_DIMS if d in ds.dims})
        ds = ds.drop_vars([v for v in ds.data_vars if ds[v].dtype.kind in "OUS"])
        ds = ds.expand_dims(chi=[chi], N=[N])
        ds.attrs = {}
        pieces.append(ds)
    # the method first: it decides whether dt0 is compared; body: a line's body (its JSON)
    for k in COMBINE_SAME_INPUTS + ("body",) + _ELASTIC_INPUTS + ("dt0", "problem"):
        ref = next((j for j, d in enumerate(inputs) if k in d), None)
        if ref is None:
            continue
        for j, d in enumerate(inputs):
            if k not in d or not _same(d[k], inputs[ref][k]):
                have = repr(d[k]) if k in d else "missing"
                raise V.SnappingInputError(
                    f"runs with different {k} cannot be combined: {k}={inputs[ref][k]!r} in {names[ref]}, {have} in "
                    f"{names[j]}; combine the runs of one grid (one method and set of options) at a time")
    opts = dict(join="outer", fill_value=np.nan, data_vars="all", coords="minimal", compat="override")
    chis = sorted({float(p["chi"].values[0]) for p in pieces})
    rows = []
    for c in chis:
        row = sorted((p for p in pieces if float(p["chi"].values[0]) == c), key=lambda p: int(p["N"].values[0]))
        Ns = [int(p["N"].values[0]) for p in row]
        if len(set(Ns)) != len(Ns):
            raise V.SnappingInputError(f"two run files have the same chi={c:g} and N: {sorted(Ns)}")
        rows.append(xr.concat(row, dim="N", **opts))
    combined = xr.concat(rows, dim="chi", **opts)
    combined.attrs = dict(inputs[0])
    combined["chi"].attrs.update(long_name="initial end-to-end separation", units="1")
    combined["N"].attrs.update(long_name="number of links", units="1")
    return combined
