"""Sweeps: a grid of runs over (chi, N, any run option), in parallel, resumable.

Each run is saved to its own netCDF file as soon as it finishes, written
atomically (to a temporary file in the same directory, then renamed), so a
killed sweep never leaves a corrupt file. Long runs checkpoint into the same
file while they run. Rerunning the same sweep skips every run whose file is
already there and complete, resumes every checkpointed or interrupted one, and
starts the others afresh. The finished runs combine into one
Dataset with ``chi`` and ``N`` dimensions (:func:`combine`).

Runs go to local worker processes by default; give a Dask scheduler address (or
a ``dask.distributed.Client``) to run the same sweep on an existing cluster.

Example
-------
>>> from snapping.sweep import Grid
>>> grid = Grid(chi=[0.25, 0.5], N=[50], options={"tol": 1e-6})
>>> [p.name for p in grid.paths("out")]
['run_chi0.25_N50.nc', 'run_chi0.5_N50.nc']
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from . import _validate as V
from . import schema

if TYPE_CHECKING:  # annotations only
    import xarray as xr

__all__ = ["Grid", "run_sweep", "combine", "atomic_to_netcdf", "is_complete_run"]


def atomic_to_netcdf(ds, path) -> Path:
    """Write ``ds`` to ``path`` as netCDF4 atomically: a temporary file in the same
    directory, flushed and renamed over ``path``. A reader never sees a half-written file.
    """
    from .simulate.dataset import check_writable

    path = Path(V.file_path("path", path))
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise V.SnappingInputError(f"path={str(path)!r}: directory cannot be created ({exc.strerror or exc})") from None
    check_writable(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    os.close(fd)
    try:
        from .simulate.dataset import save

        save(ds, tmp)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


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


def _check_values(name: str, values, check) -> list:
    if values is None:
        raise V.SnappingInputError(f"{name} grid is empty: give at least one value")
    if isinstance(values, (int, float, np.number)):
        values = [values]
    if isinstance(values, (str, bytes, dict)) or not hasattr(values, "__iter__"):
        raise V.SnappingInputError(f"{name}={values!r} is not a list of values")
    values = [check(name, v) for v in values]
    if not values:
        raise V.SnappingInputError(f"{name} grid is empty: give at least one value")
    dup = sorted({v for v in values if values.count(v) > 1})
    if dup:
        raise V.SnappingInputError(f"{name} grid has duplicate values {dup}: give each value once")
    return values


@dataclass
class Grid:
    """A grid of runs: every combination of ``chi`` and ``N``, with the same ``options``
    (any other keyword of :func:`snapping.simulate.run`, e.g. ``tol``, ``method``).
    """

    chi: list
    N: list
    options: dict = field(default_factory=dict)

    def __post_init__(self):
        from .estimates import check_chi

        self.chi = _check_values("chi", self.chi, lambda n, v: check_chi(v, n))
        self.N = _check_values("N", self.N, lambda n, v: V.integer(n, v, 1))
        if not isinstance(self.options, dict):
            raise V.SnappingInputError(f"options={self.options!r} must be a dict of keywords of simulate.run")
        json.dumps(self.options, default=str)  # options must be describable in a file name hash
        from .simulate.driver import check_inputs

        if "output" in self.options:
            raise V.SnappingInputError("options must not contain 'output': the sweep names each run's file")

        for chi in self.chi:  # every run's inputs, checked before any starts
            for N in self.N:
                check_inputs(chi, N, **self.options)

    def points(self) -> list[dict]:
        """One dict of run keywords per grid point."""
        return [dict(chi=c, N=n, **self.options) for c in self.chi for n in self.N]

    def _tag(self) -> str:
        if not self.options:
            return ""
        blob = json.dumps(self.options, sort_keys=True, default=str).encode()
        return "_" + hashlib.sha1(blob).hexdigest()[:8]

    def path(self, out_dir, chi: float, N: int) -> Path:
        """The file of the run (chi, N) in ``out_dir``."""
        return Path(out_dir) / f"run_chi{chi:g}_N{N}{self._tag()}.nc"

    def paths(self, out_dir) -> list[Path]:
        return [self.path(out_dir, p["chi"], p["N"]) for p in self.points()]


def _run_one(params: dict, path: str) -> str:
    """Worker: run one simulation, checkpointed to ``path`` and saved there atomically.

    A checkpoint of the same run already at ``path`` (a sweep that was
    interrupted, or whose worker was killed) is resumed; anything else there (a
    truncated file, another run, a failed run) is replaced by a fresh run.
    Returns the path.
    """
    from . import simulate

    if simulate.is_resumable(path, **params):
        simulate.resume(path, **{k: params[k] for k in ("checkpoint_every",) if k in params})
    else:
        simulate.run(**params, output=path)
    return path


#: Grid options an ensemble task passes on to :func:`snapping.simulate.run_ensemble`.
ENSEMBLE_OPTIONS = ("tol", "method", "t_end", "stop_fraction", "t_end_max", "snapshot_times", "record_thin",
                    "max_link_error", "chords", "dt_min")


def _check_ensemble(grid: Grid, ensemble) -> int:
    """The ensemble size (0: single runs), checked against the grid's options."""
    if ensemble is None or ensemble is False:
        return 0
    size = V.integer("ensemble", ensemble, 1)
    if size == 1:
        return 0
    from .simulate.methods.dop853 import NAMES as HIGH_ORDER_METHODS

    method = grid.options.get("method", "euler-richardson")
    if method not in HIGH_ORDER_METHODS:
        raise V.SnappingInputError(f"ensemble={size} needs an angle-form method {HIGH_ORDER_METHODS} in the grid "
                                   f"options (method={method!r})")
    other = sorted(k for k in grid.options if k not in ENSEMBLE_OPTIONS)
    if other:
        raise V.SnappingInputError(f"ensemble={size}: options {other} are not supported by ensembles "
                                   f"(supported: {list(ENSEMBLE_OPTIONS)}); run single runs instead")
    return size


def _groups(todo: list, size: int) -> list[list]:
    """The runs to do as tasks: one run each, or up to ``size`` runs of one N together."""
    if not size:
        return [[t] for t in todo]
    tasks = []
    for N in sorted({p["N"] for p, _ in todo}):
        same = [t for t in todo if t[0]["N"] == N]
        tasks += [same[i:i + size] for i in range(0, len(same), size)]
    return tasks


def _label(task: list) -> str:
    chis = ",".join(format(p["chi"], "g") for p, _ in task)
    return f"chi={chis} N={task[0][0]['N']}"


def _run_task(task: list) -> list[str]:
    """Worker: one run (:func:`_run_one`), or several runs of one N as one ensemble
    (:func:`snapping.simulate.run_ensemble`; each member saved atomically to its file).
    A failed member raises (naming it) after every member is saved."""
    if len(task) == 1:
        return [_run_one(*task[0])]
    import warnings

    from .simulate import run_ensemble

    params = [p for p, _ in task]
    opts = {k: v for k, v in params[0].items() if k not in ("chi", "N")}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # failed members are reported below
        dss = run_ensemble([p["chi"] for p in params], params[0]["N"], outputs=[path for _, path in task], **opts)
    bad = [f"chi={p['chi']:g}: {ds.attrs['stop_reason']}" for p, ds in zip(params, dss)
           if ds.attrs["status"] != "completed"]
    if bad:
        raise RuntimeError("ensemble members failed: " + "; ".join(bad))
    return [path for _, path in task]


def _check_out_dir(out_dir) -> Path:
    out = Path(V.file_path("out_dir", out_dir))
    try:
        out.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=out, prefix=".write-test-"):
            pass
    except OSError as exc:
        raise V.SnappingInputError(f"output directory {str(out)!r} cannot be written: {exc.strerror}") from None
    return out


def _client_for(scheduler):
    try:
        from dask.distributed import Client
    except ImportError:  # pragma: no cover - depends on the install
        raise V.SnappingInputError(
            "scheduler given but dask.distributed is not installed: pip install 'snapping[distributed]'"
        ) from None
    if isinstance(scheduler, Client):
        return scheduler, False
    try:
        return Client(scheduler, timeout="10s"), True
    except (OSError, TimeoutError) as exc:
        raise V.SnappingInputError(f"scheduler={scheduler!r} cannot be reached: {exc}") from None


def run_sweep(grid: Grid, out_dir, *, workers: int | None = None, scheduler=None, progress: bool = True,
              ensemble: int | None = None) -> list[Path]:
    """Run every point of ``grid`` not yet done in ``out_dir``; return all run paths.

    Parameters
    ----------
    grid : Grid
        The runs.
    out_dir : path
        Directory of the run files (created if missing; checked writable first).
    workers : int, optional
        Local worker processes (default: the number of cores, at most the runs to do).
    scheduler : str or dask.distributed.Client, optional
        Run on this Dask cluster instead of local processes.
    progress : bool
        Show a progress bar counting finished runs.
    ensemble : int, optional
        Run up to this many chi of one N together in one ensemble kernel
        (:func:`snapping.simulate.run_ensemble`; the grid's ``method`` must be
        ``"fast"``/``"dop853"``). Each member's file holds its single run's Dataset,
        bit for bit but ``wall_time``. Ensembles are not checkpointed: an interrupted
        one restarts. They save processes, not time (measured 1.1-1.2x the cost of
        single runs).

    Examples
    --------
    >>> paths = run_sweep(Grid(chi=[0.5], N=[8], options={"tol": 1e-6}), "/tmp/sw", progress=False)  # doctest: +SKIP
    """
    from tqdm.auto import tqdm

    out = _check_out_dir(out_dir)
    if workers is not None:
        workers = V.integer("workers", workers, 1)
    size = _check_ensemble(grid, ensemble)
    todo = [(p, str(grid.path(out, p["chi"], p["N"]))) for p in grid.points()]
    todo = [(p, path) for p, path in todo if not is_complete_run(path)]
    tasks = _groups(todo, size)
    bar = tqdm(total=len(grid.points()), initial=len(grid.points()) - len(todo), desc="runs", unit="run", disable=not progress)
    failures = []

    def collect(task, result) -> None:  # keep going: the other runs are independent
        try:
            result()
        except Exception as exc:
            failures.append((task, exc))
        bar.update(len(task))

    try:
        if scheduler is not None:
            from dask.distributed import as_completed as dask_completed

            client, owned = _client_for(scheduler)
            try:
                futures = {client.submit(_run_task, task, pure=False): task for task in tasks}
                for fut in dask_completed(futures):
                    collect(futures[fut], fut.result)
            finally:
                if owned:
                    client.close()
        elif tasks:
            n = min(workers or os.cpu_count() or 1, len(tasks))
            if n == 1:
                for task in tasks:
                    collect(task, lambda task=task: _run_task(task))
            else:
                import multiprocessing as mp

                with ProcessPoolExecutor(max_workers=n, mp_context=mp.get_context("spawn")) as pool:
                    futures = {pool.submit(_run_task, task): task for task in tasks}
                    for fut in as_completed(futures):
                        collect(futures[fut], fut.result)
    finally:
        bar.close()
    if failures:
        lines = "; ".join(f"{_label(task)}: {exc}" for task, exc in failures)
        n_failed = sum(not is_complete_run(path) for task, _ in failures for _, path in task)
        raise RuntimeError(f"{n_failed} of {len(todo)} runs failed ({lines}); rerun to retry only those")
    return grid.paths(out)


_RUN_DIMS = (schema.STEP_DIM, schema.SNAPSHOT_DIM, schema.NODE_DIM, schema.LINK_DIM)

#: Global result attributes that become (chi, N) variables of a combined sweep.
_SUMMARY_ATTRS = [k for k in schema.RESULT_ATTRS if k not in ("status", "stop_reason", "snapping_version")]


def combine(paths) -> "xr.Dataset":
    """Combine run files into one Dataset with ``chi`` and ``N`` dimensions.

    Per-step and profile variables keep their ``step``/``snapshot``/``node``/``link``
    dimensions (padded with NaN where runs differ in length); the numeric result
    attributes of each run (``v_peak``, ``t_snap_v``, ...) become variables over
    (chi, N).
    """
    import xarray as xr

    if isinstance(paths, (str, os.PathLike)) or not hasattr(paths, "__iter__"):
        raise V.SnappingInputError(f"paths={paths!r} must be a list of run files")
    paths = [Path(V.file_path("paths", p)) for p in paths]
    if not paths:
        raise V.SnappingInputError("combine needs at least one run file")
    pieces = []
    for path in paths:
        from .simulate.dataset import load_run

        ds = load_run(path)
        for key in ("chi", "N"):
            if key not in ds.attrs:
                raise V.SnappingInputError(f"{str(path)!r} is not a run file: attribute {key!r} is missing")
        chi, N = float(ds.attrs["chi"]), int(ds.attrs["N"])
        summary = {
            k: ((), float(ds.attrs[k]), {"long_name": schema.RESULT_ATTRS[k], "units": schema.result_units(k)})
            for k in _SUMMARY_ATTRS
            if k in ds.attrs and np.isscalar(ds.attrs[k]) and not isinstance(ds.attrs[k], str)
        }
        ds = ds.reset_coords().assign(summary)
        # integer indices on the run dimensions so that runs of different lengths pad with NaN
        ds = ds.assign_coords({d: np.arange(ds.sizes[d]) for d in _RUN_DIMS if d in ds.dims})
        ds = ds.drop_vars([v for v in ds.data_vars if ds[v].dtype.kind in "OUS"])
        ds = ds.expand_dims(chi=[chi], N=[N])
        keep = {k: ds.attrs[k] for k in ("method", "tol") if k in ds.attrs}
        ds.attrs = keep
        pieces.append(ds)
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
    combined.attrs = {k: v for k, v in pieces[0].attrs.items() if all(p.attrs.get(k) == v for p in pieces)}
    combined["chi"].attrs.update(long_name="initial end-to-end separation", units="1")
    combined["N"].attrs.update(long_name="number of links", units="1")
    return combined
