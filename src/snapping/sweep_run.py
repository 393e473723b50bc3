"""Running a sweep: the runs not yet done, one a task or several of one N as an ensemble, on
local worker processes or a Dask cluster, each saved (or resumed) in its own file
(:func:`run_sweep`); failed runs are collected, not raised, until every other run is done."""

from __future__ import annotations

import os
import time
from pathlib import Path

from . import _validate as V
from . import _workers
from .sweep_failures import RunFailure, SweepFailed, _existing, _failure_of, _one_line
from .sweep_files import is_complete_run
from .sweep_grid import Grid, _run_kwargs


def _run_one(params: dict, path: str) -> str:
    """Worker: run one simulation, checkpointed to ``path`` and saved there atomically.

    A checkpoint of the same run already at ``path`` (a sweep that was
    interrupted, or whose worker was killed) is resumed; anything else there (a
    truncated file, another run, a failed run) is replaced by a fresh run.
    Returns the path.
    """
    from . import simulate

    if "elastic" in params:  # the extensible line: its own solver, not checkpointed
        from .sweep_elastic import run_point

        return run_point(params, path)
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

    if "elastic" in grid.options:
        raise V.SnappingInputError(f"ensemble={size}: the extensible line (elastic) runs one run a task")
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
            if "elastic" in params:
                _run_one(params, path)
            else:  # (a sweep interrupted while the run is still starting does not wait for it to start)
                with _workers.until_first_step():
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


def _check_room(out: Path, todo: list) -> None:
    """Refuse a sweep whose run files (estimated sizes) do not fit on the filesystem of ``out``."""
    import shutil

    from ._files import _size
    from .simulate.driver import check_inputs

    from .sweep_elastic import file_bytes

    need = sum(file_bytes(p) if "elastic" in p else check_inputs(**_run_kwargs(p))["file_bytes"] for p, _ in todo)
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
        if any(o is not None and o["kind"] == "cancelled" for o in outcomes):
            raise KeyboardInterrupt  # a worker got SIGINT between its runs: the sweep was interrupted
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
