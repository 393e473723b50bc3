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
>>> grid = Grid(chi=[0.25, 0.5], N=[50])       # run()'s defaults: method fast, chords exact
>>> [p.name for p in grid.paths("out")]         # (options, when given, add their hash to the names)
['run_chi0.25_N50.nc', 'run_chi0.5_N50.nc']
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from . import _validate as V
from . import _workers
from . import schema

if TYPE_CHECKING:  # annotations only
    import xarray as xr

__all__ = ["Grid", "run_sweep", "combine", "atomic_to_netcdf", "is_complete_run", "SweepFailed", "RunFailure",
           "failure_table"]


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
    (any other keyword of :func:`snapping.simulate.run`, e.g. ``tol``, ``method``); what
    ``options`` leaves out takes :func:`snapping.simulate.run`'s default (method ``fast``,
    chords ``exact``, the method's tol). ``options["body"]``: a line's body
    (:class:`snapping.simulate.Body` with numbers, not per-node profiles), the same at every
    point: each run is ``Problem.catenary(chi, N, chords=..., body=...)``; it is kept as its
    description (:meth:`~snapping.simulate.Body.describe`), which names the run files.
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
        if "body" in self.options:  # a line's body, the same at every grid point: kept as its description
            self.options = {**self.options, "body": _body_description(self.options["body"])}

        for chi in self.chi:  # every run's inputs, checked before any starts
            for N in self.N:
                check_inputs(**_run_kwargs(dict(chi=chi, N=N, **self.options)))

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


def _body_description(body, name: str = "options['body']") -> dict:
    """The description (:meth:`snapping.simulate.Body.describe`) of a sweep's body (a Body or
    a description), checked to be one that every chain of the grid can take."""
    from .simulate import Body

    if isinstance(body, dict):
        body = Body.from_describe(body)
    if not isinstance(body, Body):
        raise V.SnappingInputError(f"{name}={type(body).__name__} is not a snapping.simulate.Body")
    d = body.describe()
    if any(isinstance(v, (list, dict)) for k, v in d.items() if k not in ("wind", "clamp")):
        raise V.SnappingInputError(f"{name}: a body refined or swept over N takes numbers (the same at every N), "
                                   f"not per-node arrays or functions of s; run such bodies one by one")
    return d


def _run_kwargs(params: dict) -> dict:
    """The keywords of :func:`snapping.simulate.run` for one grid point: with a ``body``, the
    problem ``Problem.catenary(chi, N, chords=..., body=...)`` in place of chi, N and chords."""
    if "body" not in params:
        return params
    from .simulate import Body, Problem

    kw = dict(params)
    body = Body.from_describe(kw.pop("body"))
    chi, N, chords = kw.pop("chi"), kw.pop("N"), kw.pop("chords", None)
    kw["problem"] = Problem.catenary(chi, N, chords=chords or "exact", body=body)
    return kw


def _run_one(params: dict, path: str) -> str:
    """Worker: run one simulation, checkpointed to ``path`` and saved there atomically.

    A checkpoint of the same run already at ``path`` (a sweep that was
    interrupted, or whose worker was killed) is resumed; anything else there (a
    truncated file, another run, a failed run) is replaced by a fresh run.
    Returns the path.
    """
    from . import simulate

    if simulate.is_resumable(path, **{k: v for k, v in params.items() if k != "body"}):
        simulate.resume(path, **{k: params[k] for k in ("checkpoint_every",) if k in params})
    else:
        simulate.run(**_run_kwargs(params), output=path, overwrite=True)  # the sweep owns its run files
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

    from .simulate.driver import DEFAULT_METHOD

    method = grid.options.get("method", DEFAULT_METHOD)
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


def _one_line(text) -> str:
    """The first line of a message, at most 300 characters."""
    line = (str(text).strip().splitlines() or [""])[0]
    return line if len(line) <= 300 else line[:297] + "..."


def _existing(path) -> str | None:
    return str(path) if path is not None and Path(path).is_file() else None


def _failure_of(exc: BaseException, path: str) -> dict:
    """What a worker reports of a run that raised ``exc``: its failure kind, one-line
    message and the file it left (if any). Plain values: they cross process boundaries."""
    from .simulate.errors import SimulationError

    if isinstance(exc, SimulationError):
        ds = exc.dataset
        msg = ds.attrs.get("stop_reason") if ds is not None and ds.attrs.get("stop_reason") else str(exc)
        return {"kind": exc.kind or "simulation", "message": _one_line(msg), "file": _existing(exc.path or path)}
    msg = _one_line(exc) or type(exc).__name__
    if type(exc).__name__ == "BrokenProcessPool" and not str(exc).startswith("a worker process could not run"):
        msg = ("a worker process died (killed, out of memory, or, in a script, a sweep not started under "
               "`if __name__ == \"__main__\":`, whose workers re-run the script)")
    return {"kind": type(exc).__name__, "message": msg, "file": _existing(path)}


def _run_task(task: list) -> list:
    """Worker: one run (:func:`_run_one`), or several runs of one N as one ensemble
    (:func:`snapping.simulate.run_ensemble`; each member saved atomically to its file).

    Returns one outcome per run of the task, in its order: ``None`` for a run that
    completed, else a dict (``kind``, ``message``, ``file``, see :func:`_failure_of`).
    A run that fails numerically, or on an input that is only refused at run time,
    does not end the task: every other member is still run and saved."""
    if _workers.stopped():  # the sweep was interrupted: start nothing new
        return [{"kind": "cancelled", "message": "not started: the sweep was interrupted", "file": None}
                for _ in task]
    if len(task) == 1:
        params, path = task[0]
        try:
            _run_one(params, path)
        except Exception as exc:  # numerical failures and run-time refusals are reported, not raised
            return [_failure_of(exc, path)]
        return [None]
    import warnings

    from .simulate import run_ensemble

    params = [p for p, _ in task]
    opts = {k: v for k, v in params[0].items() if k not in ("chi", "N")}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # failed members are reported below
            dss = run_ensemble([p["chi"] for p in params], params[0]["N"], outputs=[path for _, path in task],
                               overwrite=True, **opts)  # the sweep owns its run files
    except Exception as exc:  # the ensemble as a whole failed: every member with it
        return [_failure_of(exc, path) for _, path in task]
    out = []
    for (_, path), ds in zip(task, dss):
        if ds.attrs["status"] == "completed":
            out.append(None)
        else:
            out.append({"kind": str(ds.attrs.get("failure") or ds.attrs["status"]),
                        "message": _one_line(ds.attrs.get("stop_reason", "")), "file": _existing(path)})
    return out


def grid_key(grid: Grid) -> str:
    """The grid as a JSON string (chi, N, options), stored in a combined sweep file as
    attribute ``sweep_grid``."""
    return json.dumps({"chi": [float(c) for c in grid.chi], "N": [int(n) for n in grid.N],
                       "options": grid.options}, sort_keys=True, default=str)


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


def _check_room(out: Path, todo: list) -> None:
    """Refuse a sweep whose run files (estimated sizes) do not fit on the filesystem of ``out``."""
    import shutil

    from ._files import _size
    from .simulate.driver import check_inputs

    need = sum(check_inputs(**_run_kwargs(p))["file_bytes"] for p, _ in todo)
    free = shutil.disk_usage(out).free
    if need > free:
        raise V.SnappingInputError(f"out_dir={str(out)!r}: the {len(todo)} run files to write need about "
                                   f"{_size(need)} but its filesystem has only {_size(free)} free")


def _check_out_dir(out_dir) -> Path:
    from ._files import check_output_dir

    return Path(check_output_dir(out_dir, name="out_dir"))


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


@dataclass
class RunFailure:
    """One run of a sweep that did not complete.

    Attributes
    ----------
    chi, N : float, int
        The grid point.
    options : dict
        The grid's run options (the same for every run of the grid).
    kind : str
        Why: the failure kind of a numerical failure (``SimulationError.kind``:
        'step_size', 'rejections', 'non_finite', 'link_drift', 'energy_drift'), or
        the exception's type name for anything else (e.g. 'SnappingInputError' for an
        option that is only refused at run time, 'BrokenProcessPool' for a worker that died).
    message : str
        One line saying what happened (the run's ``stop_reason`` for a numerical failure).
    file : str or None
        The run's file as it was left (status 'failed', what was computed until the
        failure), or None when there is none.
    """

    chi: float
    N: int
    options: dict
    kind: str
    message: str
    file: str | None = None

    def to_dict(self) -> dict:
        return {"chi": self.chi, "N": self.N, "options": dict(self.options), "kind": self.kind,
                "message": self.message, "file": self.file}


def failure_table(failures) -> str:
    """The failed runs of a sweep as an aligned text table (one row per run)."""
    rows = [("chi", "N", "options", "failure", "file", "message")]
    for f in failures:
        opts = ", ".join(f"{k}={v!r}" for k, v in sorted(f.options.items())) or "-"
        rows.append((f"{f.chi:g}", str(f.N), opts, f.kind, f.file or "(none)", f.message))
    widths = [max(len(r[i]) for r in rows) for i in range(5)]
    return "\n".join("  " + "  ".join(c.ljust(w) for c, w in zip(r[:5], widths)) + "  " + r[5] for r in rows).rstrip()


class SweepFailed(RuntimeError):
    """Some runs of a sweep failed; every other run completed and was saved.

    Raised by :func:`run_sweep` after all runs have been tried (it is a
    ``RuntimeError``, as the sweep's failures always were).

    Attributes
    ----------
    failures : list of RunFailure
        The runs that did not complete: which (chi, N, options), the failure kind, a
        one-line message and the run's partial file, if any (:func:`failure_table`
        prints them).
    paths : list of Path
        The files of the runs that completed (every grid point but the failed ones),
        ready for :func:`combine`.
    n_runs : int
        The runs of the grid.
    """

    def __init__(self, failures: list, paths: list, n_runs: int):
        self.failures = list(failures)
        self.paths = list(paths)
        self.n_runs = int(n_runs)
        first = "; ".join(f"chi={f.chi:g} N={f.N}: {f.kind}: {f.message}" for f in self.failures[:3])
        more = f"; and {len(self.failures) - 3} more" if len(self.failures) > 3 else ""
        super().__init__(f"{len(self.failures)} of {self.n_runs} runs failed ({first}{more}); the other runs are "
                         f"saved; rerun the sweep to retry only the failed ones")

    def table(self) -> str:
        """The failed runs as text (:func:`failure_table`)."""
        return failure_table(self.failures)


def run_sweep(grid: Grid, out_dir, *, workers: int | None = None, scheduler=None, progress: bool = True,
              ensemble: int | None = None, log=None, overwrite: bool = False) -> list[Path]:
    """Run every point of ``grid`` not yet done in ``out_dir``; return all run paths.

    Parameters
    ----------
    grid : Grid
        The runs.
    out_dir : path
        Directory of the run files (created if missing; checked writable first).
    workers : int, optional
        Local worker processes (default: the number of cores, at most the runs to do).
        Each watches this process and ends itself (after letting a run in progress
        save its checkpoint) if this process dies, e.g. is killed with SIGKILL.
    scheduler : str or dask.distributed.Client, optional
        Run on this Dask cluster instead of local processes.
    progress : bool
        Show a progress bar counting finished runs.
    log : callable, optional
        Called with one line per finished run (``"run 3/20 done: chi=0.25 N=400 (12 s)"``):
        progress where there is no terminal for a bar (a log file, CI).
    ensemble : int, optional
        Run up to this many chi of one N together in one ensemble kernel
        (:func:`snapping.simulate.run_ensemble`; the grid's ``method`` must be
        ``"fast"``/``"dop853"``). Each member's file holds its single run's Dataset,
        bit for bit but ``wall_time``. Ensembles are not checkpointed: an interrupted
        one restarts. They save processes, not time (measured 1.1-1.2x the cost of
        single runs).
    overwrite : bool
        Replace files in ``out_dir`` named like a run of the grid that snapping did not write
        (default: refuse them before any run; snapping's own, failed or checkpointed runs are
        rerun or resumed).

    Returns
    -------
    list of Path
        The files of every run of the grid (all complete).

    Raises
    ------
    SweepFailed
        Some runs failed (numerically, e.g. a step below ``dt_min``, or on an option
        only refused at run time, or their worker died): raised once every other run
        has completed and been saved; ``.failures`` says which and why, ``.paths``
        lists the completed runs (for :func:`combine`). A rerun retries only the
        failed runs.
    SnappingInputError
        Bad grid, ``out_dir``, ``workers``, ``ensemble`` or scheduler, before any run.
    KeyboardInterrupt
        SIGINT: the finished and checkpointed runs are kept; a rerun resumes.

    Examples
    --------
    >>> paths = run_sweep(Grid(chi=[0.5], N=[8], options={"tol": 1e-6}), "/tmp/sw", progress=False)  # doctest: +SKIP
    """
    import multiprocessing as mp

    from ._files import locked

    if getattr(mp.current_process(), "_inheriting", False):  # a spawned worker importing the main script
        raise V.SnappingInputError("run_sweep was called inside one of its own worker processes: a script that runs "
                                   "a sweep must start it under `if __name__ == \"__main__\":` (the workers import "
                                   "the script)")
    from ._files import output_dir

    if not all(hasattr(grid, a) for a in ("points", "path", "paths", "options")):  # (checked before the directory)
        raise V.SnappingInputError(f"grid={V._short(grid)} is not a snapping.sweep.Grid (use Grid(chi=[...], "
                                   f"N=[...], options={{...}}))")
    if workers is not None:
        workers = V.integer("workers", workers, 1)
    size = _check_ensemble(grid, ensemble)
    if not isinstance(overwrite, bool):
        raise V.SnappingInputError(f"overwrite={overwrite!r} must be True or False")
    if scheduler is not None and not isinstance(scheduler, str) and type(scheduler).__name__ != "Client":
        raise V.SnappingInputError(f"scheduler={V._short(scheduler)} is not a Dask scheduler address or a "
                                   f"dask.distributed.Client")
    with output_dir(out_dir, name="out_dir") as out:  # (a new directory is removed again if the sweep is refused)
        out = Path(out)
        with locked(out / "sweep.nc", name="out_dir"):  # one sweep at a time in a directory
            return _run_sweep(grid, out, workers=workers, scheduler=scheduler, progress=progress, size=size,
                              log=log, overwrite=overwrite)


def _run_sweep(grid: Grid, out_dir, *, workers, scheduler, progress, size, log, overwrite=False) -> list[Path]:
    """:func:`run_sweep` once its inputs are checked and its directory made and locked."""
    from tqdm.auto import tqdm

    from ._files import check_own_files

    out = Path(out_dir)
    todo = [(p, str(grid.path(out, p["chi"], p["N"]))) for p in grid.points()]
    todo = [(p, path) for p, path in todo if not is_complete_run(path)]
    check_own_files([path for _, path in todo], name="output", overwrite=overwrite)  # another program's: kept
    _check_room(out, todo)
    tasks = _groups(todo, size)
    bar = tqdm(total=len(grid.points()), initial=len(grid.points()) - len(todo), desc="runs", unit="run", disable=not progress)
    failures: list[RunFailure] = []
    done, t_start = [0], time.perf_counter()

    def collect(task, result) -> None:  # keep going: the other runs are independent
        try:
            outcomes = result()
        except Exception as exc:  # the task itself could not run (its worker died, ...): all its runs
            outcomes = [_failure_of(exc, path) for _, path in task]
        for (params, _), outcome in zip(task, outcomes):
            if outcome is not None:
                failures.append(RunFailure(chi=params["chi"], N=params["N"], options=dict(grid.options), **outcome))
            done[0] += 1
            if log is not None:
                what = "done" if outcome is None else f"FAILED ({outcome['kind']})"
                log(f"  run {done[0]}/{len(todo)} {what}: chi={params['chi']:g} N={params['N']} "
                    f"({time.perf_counter() - t_start:.0f} s since the start)")
        bar.update(len(task))

    try:
        if scheduler is not None:
            from dask.distributed import as_completed as dask_completed

            client, owned = _client_for(scheduler)
            futures = {}
            try:
                futures = {client.submit(_run_task, task, pure=False): task for task in tasks}
                for fut in dask_completed(futures):
                    collect(futures[fut], fut.result)
            except BaseException:  # interrupted: the runs not done are not left running on the cluster
                client.cancel(list(futures))
                raise
            finally:
                if owned:
                    client.close()
        elif tasks:
            n = min(workers or os.cpu_count() or 1, len(tasks))
            if n == 1:
                for task in tasks:
                    collect(task, lambda task=task: _run_task(task))
            else:  # (SIGINT: stops promptly, the runs in progress saved)
                _workers.run_all(n, _run_task, [(task,) for task in tasks], lambda args, res: collect(args[0], res))
    finally:
        bar.close()
    paths = grid.paths(out)
    if failures:
        order = {(p["chi"], p["N"]): i for i, p in enumerate(grid.points())}
        failures.sort(key=lambda f: order[(f.chi, f.N)])
        bad = {str(grid.path(out, f.chi, f.N)) for f in failures}
        raise SweepFailed(failures, [p for p in paths if str(p) not in bad], len(paths))
    return paths


_RUN_DIMS = (schema.STEP_DIM, schema.SNAPSHOT_DIM, schema.NODE_DIM, schema.LINK_DIM)

#: Global result attributes that become (chi, N) variables of a combined sweep.
_SUMMARY_ATTRS = [k for k in schema.RESULT_ATTRS if k not in ("status", "stop_reason", "snapping_version")]


#: Inputs that must agree between the runs of one combined sweep (``dt0`` too for the
#: Euler-Richardson methods, where it is the step the user chose; the angle-form methods
#: compute their own per run). The combined Dataset keeps them as attributes.
COMBINE_SAME_INPUTS = ("method", "tol", "t_end", "stop_fraction", "t_end_max", "record_thin", "chords", "initial",
                       "max_link_error", "max_energy_drift", "dt_min", "max_rejections")


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
        keys = COMBINE_SAME_INPUTS + ("body",) + (
            ("dt0",) if str(ds.attrs["method"]).startswith("euler-richardson") else ())
        inputs.append({k: (ds.attrs[k].item() if isinstance(ds.attrs[k], np.generic) else ds.attrs[k])
                       for k in keys if k in ds.attrs})
        if "problem" in ds.attrs:  # a general problem's chain, held end and gravity: compared and kept too
            inputs[-1]["problem"] = _problem_key(ds.attrs["problem"])
        names.append(name)
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
        ds.attrs = {}
        pieces.append(ds)
    # the method first: it decides whether dt0 is compared; body: a line's body (its JSON)
    for k in COMBINE_SAME_INPUTS + ("body", "dt0", "problem"):
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
