"""Sweeps: parallel, resumable, atomic, combined over (chi, N), on local processes and on Dask."""

import os
from pathlib import Path

import numpy as np
import pytest

from snapping import SnappingInputError, simulate
from snapping import sweep as S

OPTS = {"tol": 1e-7}


def test_sweep_runs_combines_and_skips_finished(tmp_path):
    grid = S.Grid(chi=[0.4, 0.7], N=[8, 12], options=OPTS)
    # the direct run first: its kernels compiled here once, the two workers load them from numba's
    # cache (a cold cache: else each worker compiles them, ~40 s of CPU each)
    direct = simulate.run(0.7, 12, **OPTS).dataset
    paths = S.run_sweep(grid, tmp_path, workers=2, progress=False)
    assert len(paths) == 4 and all(S.is_complete_run(p) for p in paths)
    # each file is the same run as a direct call (runs are deterministic)
    ds = simulate.load_run(grid.path(tmp_path, 0.7, 12))
    assert ds.attrs["v_peak"] == direct.attrs["v_peak"]
    np.testing.assert_array_equal(ds["v_max"].values, direct["v_max"].values)
    # combined over chi and N, with the per-run results as (chi, N) variables
    comb = S.combine(paths)
    assert dict(comb.sizes)["chi"] == 2 and dict(comb.sizes)["N"] == 2
    assert float(comb["v_peak"].sel(chi=0.7, N=12)) == direct.attrs["v_peak"]
    n = int(direct.sizes["step"])
    np.testing.assert_array_equal(comb["v_max"].sel(chi=0.7, N=12).values[:n], direct["v_max"].values)
    assert comb["v_max"].attrs["units"] == "1"
    assert comb["wall_time"].attrs["units"] == "s" and comb["v_peak"].attrs["units"] == "1"
    # a rerun does nothing to finished runs; a removed run is redone
    mtimes = {p: os.stat(p).st_mtime_ns for p in paths}
    os.remove(paths[0])
    S.run_sweep(grid, tmp_path, workers=1, progress=False)
    assert S.is_complete_run(paths[0])
    assert all(os.stat(p).st_mtime_ns == mtimes[p] for p in paths[1:])


def test_a_failed_write_leaves_no_file(tmp_path, monkeypatch):
    ds = simulate.run(0.5, 4, t_end=0.01).dataset
    target = tmp_path / "run.nc"

    def boom(*a, **k):
        raise OSError("disk full")

    monkeypatch.setattr("snapping.simulate.dataset.save", boom)
    with pytest.raises(OSError):
        S.atomic_to_netcdf(ds, target)
    assert not target.exists() and list(tmp_path.iterdir()) == []


def test_a_truncated_file_is_not_complete_and_is_redone(tmp_path):
    grid = S.Grid(chi=[0.5], N=[5], options=OPTS)
    path = grid.path(tmp_path, 0.5, 5)
    path.write_bytes(b"CDF\x01 truncated")
    assert not S.is_complete_run(path)
    S.run_sweep(grid, tmp_path, workers=1, progress=False)
    assert S.is_complete_run(path)


def test_sweep_on_a_local_dask_cluster(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None) as cl:
        with distributed.Client(cl) as client:
            grid = S.Grid(chi=[0.4, 0.7], N=[5], options=OPTS)
            paths = S.run_sweep(grid, tmp_path, scheduler=client, progress=False)
    assert all(S.is_complete_run(p) for p in paths)
    comb = S.combine(paths)
    assert list(comb["chi"].values) == [0.4, 0.7]


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(chi=[], N=[5]), "chi grid is empty"),
        (dict(chi=[0.2], N=[]), "N grid is empty"),
        (dict(chi=[0.2, 0.2], N=[5]), r"chi grid has duplicate values \[0.2\]"),
        (dict(chi=[0.2], N=[5, 5]), r"N grid has duplicate values \[5\]"),
        (dict(chi=[1.2], N=[5]), r"chi=1.2"),
        (dict(chi=[0.2], N=[0]), r"N=0"),
    ],
)
def test_bad_grids(kwargs, match):
    with pytest.raises(SnappingInputError, match=match):
        S.Grid(**kwargs)


def test_unwritable_directory_and_unreachable_scheduler(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    grid = S.Grid(chi=[0.5], N=[4], options=OPTS)
    with pytest.raises(SnappingInputError, match="cannot be written"):
        S.run_sweep(grid, blocker / "sub", progress=False)
    pytest.importorskip("dask.distributed")
    with pytest.raises(SnappingInputError, match="cannot be reached"):
        S.run_sweep(grid, tmp_path / "ok", scheduler="tcp://127.0.0.1:1", progress=False)
    assert not any(Path(tmp_path / "ok").glob("*.nc"))


def test_cli_sweep(tmp_path, capsys):
    import json

    from snapping.cli import main

    assert main(["sweep", "--chi", "0.5", "--N", "6,9", "--tol", "1e-7", "-o", str(tmp_path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [r["N"] for r in out["runs"]] == [6, 9]
    assert (tmp_path / "sweep.nc").is_file()
    assert main(["sweep", "--chi", "0.5,0.5", "--N", "6", "-o", str(tmp_path)]) == 2
    assert "duplicate" in capsys.readouterr().err


def test_sweep_in_ensembles_matches_single_runs(tmp_path):
    """--ensemble K: several chi of one N in one kernel; each member's peaks as its single run's."""
    opts = {"method": "fast", "chords": "exact", "tol": 1e-8}
    grid = S.Grid(chi=[0.3, 0.4, 0.5], N=[20, 30], options=opts)
    # one ensemble here first, its members checked as the sweep's below: the ensemble kernel compiled
    # here once, the two workers load it from numba's cache (cold: else each compiles it, ~40 s of CPU)
    here = simulate.run_ensemble([0.3, 0.5], 20, **opts)
    paths = S.run_sweep(grid, tmp_path / "ens", workers=2, progress=False, ensemble=2)
    assert all(S.is_complete_run(p) for p in paths)
    for chi in grid.chi:
        for N in grid.N:
            ens = simulate.load_run(grid.path(tmp_path / "ens", chi, N)).attrs
            single = simulate.run(chi, N, **opts).dataset.attrs
            for q in ("v_peak", "a_peak", "sigma_peak", "t_snap_v"):
                assert ens[q] == pytest.approx(single[q], rel=1e-8), (chi, N, q)
                if N == 20 and chi != 0.4:
                    assert here[[0.3, 0.5].index(chi)].attrs[q] == pytest.approx(single[q], rel=1e-8), (chi, q)
            assert ens["link_drift"] < 1e-14
    # a rerun redoes only the missing member, alone
    os.remove(paths[1])
    mtimes = {p: os.stat(p).st_mtime_ns for p in paths if p != paths[1]}
    S.run_sweep(grid, tmp_path / "ens", workers=1, progress=False, ensemble=2)
    assert S.is_complete_run(paths[1]) and all(os.stat(p).st_mtime_ns == m for p, m in mtimes.items())
    # groups hold one N each, at most K members
    todo = [({"chi": c, "N": n}, "") for c in (0.3, 0.4, 0.5) for n in (20, 30)]
    assert [len(t) for t in S._groups(todo, 2)] == [2, 1, 2, 1]
    assert all(len({p["N"] for p, _ in t}) == 1 for t in S._groups(todo, 2))


def test_ensemble_sweep_bad_options(tmp_path):
    grid = S.Grid(chi=[0.3, 0.4], N=[10], options={"tol": 1e-6, "method": "euler-richardson"})
    with pytest.raises(SnappingInputError, match="ensemble=2 needs an angle-form method"):
        S.run_sweep(grid, tmp_path, ensemble=2, progress=False)
    grid = S.Grid(chi=[0.3, 0.4], N=[10], options={"method": "fast", "checkpoint_every": 10.0})
    with pytest.raises(SnappingInputError, match=r"options \['checkpoint_every'\] are not supported"):
        S.run_sweep(grid, tmp_path, ensemble=2, progress=False)
    with pytest.raises(SnappingInputError, match="ensemble"):
        S.run_sweep(grid, tmp_path, ensemble=0, progress=False)


def test_ensemble_sweep_with_a_failing_member_keeps_the_other(tmp_path):
    # chi = 0.1 needs steps below dt_min = 3e-4 at N = 40, chi = 0.5 does not
    grid = S.Grid(chi=[0.1, 0.5], N=[40], options={"method": "fast", "tol": 1e-8, "dt_min": 3e-4})
    with pytest.raises(RuntimeError, match=r"1 of 2 runs failed \(chi=0.1 N=40: step_size: time-step underflow") as info:
        S.run_sweep(grid, tmp_path, workers=1, ensemble=2, progress=False)
    _check_one_step_size_failure(info.value, grid, tmp_path)  # each member named, with its own failure
    assert S.is_complete_run(grid.path(tmp_path, 0.5, 40)) and not S.is_complete_run(grid.path(tmp_path, 0.1, 40))


# ---------------------------------------------------------------- failed runs, killed sweeps, combine
FAILING = {"method": "fast", "tol": 1e-8, "dt_min": 3e-4}  # chi = 0.1 needs steps below 3e-4 at N = 40 (tol 1e-8), chi = 0.5 does not


def _check_one_step_size_failure(exc, grid, out):
    assert isinstance(exc, S.SweepFailed) and isinstance(exc, RuntimeError)
    assert exc.n_runs == 2 and len(exc.failures) == 1
    f = exc.failures[0]
    assert (f.chi, f.N, f.kind) == (0.1, 40, "step_size") and f.options == grid.options
    assert "time-step underflow" in f.message and "\n" not in f.message
    # the failed run's partial file is named, and is what was computed until the failure
    assert f.file == str(grid.path(out, 0.1, 40)) and simulate.load_run(f.file).attrs["status"] == "failed"
    # every other run completed and was saved; they combine
    assert exc.paths == [grid.path(out, 0.5, 40)] and S.is_complete_run(exc.paths[0])
    comb = S.combine(exc.paths)
    assert list(comb["chi"].values) == [0.5] and comb.attrs["method"] == "dop853"
    table = exc.table()
    assert "step_size" in table and f.file in table and "dt_min=0.0003" in table and "0.1" in table


def test_failed_runs_on_local_workers_are_reported_and_the_others_saved(tmp_path):
    grid = S.Grid(chi=[0.1, 0.5], N=[40], options=FAILING)
    with pytest.raises(S.SweepFailed, match=r"1 of 2 runs failed \(chi=0.1 N=40: step_size: time-step underflow") as info:
        S.run_sweep(grid, tmp_path, workers=2, progress=False)
    _check_one_step_size_failure(info.value, grid, tmp_path)


def test_failed_runs_on_dask_are_reported_and_the_others_saved(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    grid = S.Grid(chi=[0.1, 0.5], N=[40], options=FAILING)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None) as cl:
        with distributed.Client(cl) as client:
            with pytest.raises(S.SweepFailed) as info:
                S.run_sweep(grid, tmp_path, scheduler=client, progress=False)
    _check_one_step_size_failure(info.value, grid, tmp_path)


def test_a_run_time_refusal_and_a_crash_are_reported_with_their_kind(tmp_path, monkeypatch):
    grid = S.Grid(chi=[0.3, 0.4, 0.5], N=[6], options=OPTS)
    real = S._run_one

    def fake(params, path):
        if params["chi"] == 0.3:
            raise SnappingInputError("tol=1e-07 is refused at run time\nsecond line")
        if params["chi"] == 0.4:
            raise MemoryError("out of memory")
        return real(params, path)

    monkeypatch.setattr("snapping.sweep_run._run_one", fake)  # (patched where _run_task uses it)
    with pytest.raises(S.SweepFailed) as info:
        S.run_sweep(grid, tmp_path, workers=1, progress=False)
    kinds = [(f.chi, f.kind, f.message, f.file) for f in info.value.failures]
    assert kinds == [(0.3, "SnappingInputError", "tol=1e-07 is refused at run time", None),
                     (0.4, "MemoryError", "out of memory", None)]
    assert info.value.paths == [grid.path(tmp_path, 0.5, 6)]


def test_cli_sweep_with_a_failed_run_prints_the_table_and_exits_1(tmp_path, capsys, monkeypatch):
    from snapping.cli import main

    real = S._run_one
    monkeypatch.setattr("snapping.sweep_run._run_one", lambda params, path: real({**params, "dt_min": 3e-4}, path))
    argv = ["sweep", "--chi", "0.1,0.5", "--N", "40", "--method", "fast", "--tol", "1e-8", "--workers", "1", "-o",
            str(tmp_path)]
    assert main(argv) == 1
    cap = capsys.readouterr()
    assert "Traceback" not in cap.err and "1 of 2 runs failed" in cap.err
    assert "step_size" in cap.err and "run_chi0.1_N40" in cap.err and "time-step underflow" in cap.err
    assert "1 runs in" in cap.out and "0.5" in cap.out  # the finished run is combined and shown
    import xarray as xr

    with xr.open_dataset(tmp_path / "sweep.nc") as sw:
        assert list(sw["chi"].values) == [0.5]
    assert main(argv + ["--json"]) == 1
    import json

    out = json.loads(capsys.readouterr().out)
    assert [r["chi"] for r in out["runs"]] == [0.5]
    assert out["failed"][0]["kind"] == "step_size" and out["failed"][0]["chi"] == 0.1


def test_cli_sweep_sigint_prints_a_message_and_exits_130(tmp_path, capsys, monkeypatch):
    from snapping.cli import main

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(S, "run_sweep", interrupted)
    assert main(["sweep", "--chi", "0.5", "--N", "6", "-o", str(tmp_path)]) == 130
    err = capsys.readouterr().err
    assert "interrupted" in err and "resume" in err and "Traceback" not in err


def _alive(pid: int) -> bool:
    """pid is a live (not zombie) process."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def _children(pid: int) -> list[int]:
    """Pids of the live child processes of pid (scanning /proc)."""
    out = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                stat = (d / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(stat[1]) == pid and stat[0] != "Z":
                out.append(int(d.name))
    return out


def _worker_env(pid_file):
    """The environment of a sweep subprocess: this checkout's snapping, worker pids written to ``pid_file``."""
    import snapping

    return {**os.environ, S._workers.WORKER_PID_FILE_ENV: str(pid_file),
            "PYTHONPATH": os.pathsep.join([str(Path(snapping.__file__).parents[1]), os.environ.get("PYTHONPATH", "")])}


def _wait_for_workers(proc, pid_file, deadline, n=2) -> list[int]:
    """The pids of the sweep's ``n`` local workers once they have started (fewer if the deadline passes)."""
    import time

    pids = []
    while len(pids) < n and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.1)
        pids = [int(x) for x in pid_file.read_text().split()] if pid_file.exists() else []
    return pids


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc (Linux)")
def test_a_killed_sweep_leaves_no_worker_processes(tmp_path):
    """SIGKILL the sweep's process while 2 workers run: the workers notice and end."""
    import signal
    import subprocess
    import sys
    import time

    pid_file = tmp_path / "pids"
    out = tmp_path / "out"
    script = ("from snapping import sweep as S\n"
              "g = S.Grid(chi=[0.3, 0.4, 0.5, 0.6], N=[200], options={'method': 'fast', 't_end': 60.0})\n"
              f"S.run_sweep(g, {str(out)!r}, workers=2, progress=False)\n")
    proc = subprocess.Popen([sys.executable, "-c", script], env=_worker_env(pid_file))
    pids = []
    try:
        deadline = time.monotonic() + 120
        pids = _wait_for_workers(proc, pid_file, deadline)
        assert len(pids) == 2, f"the workers did not start ({pids}, sweep exit {proc.poll()})"
        time.sleep(3.0)  # the runs are under way
        assert proc.poll() is None, "the sweep ended before it could be killed"
        children = _children(proc.pid)  # the workers and multiprocessing's resource tracker
        assert set(pids) <= set(children)
        pids = sorted(set(pids) | set(children))
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
        t0 = time.monotonic()
        while any(_alive(p) for p in pids) and time.monotonic() - t0 < 30.0:
            time.sleep(0.1)  # (they end within ~3 s: a margin for a loaded machine)
        left = [p for p in pids if _alive(p)]
        assert not left, f"processes {left} of the sweep outlived it by 30 s"
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        for p in pids:  # never leave them behind, even when the test fails
            if _alive(p):
                os.kill(p, signal.SIGKILL)


def test_combine_refuses_what_is_not_a_run(tmp_path):
    import xarray as xr

    grid = S.Grid(chi=[0.5], N=[6], options=OPTS)
    paths = S.run_sweep(grid, tmp_path, workers=1, progress=False)
    with pytest.raises(SnappingInputError, match=r"paths\[0\] \(a Dataset\) is not a snapping run"):
        S.combine([xr.Dataset({"x": ("a", [1.0, 2.0])})])
    with pytest.raises(SnappingInputError, match="must be a list of run files"):
        S.combine(simulate.load_run(paths[0]))
    sweep_file = S.atomic_to_netcdf(S.combine(paths), tmp_path / "sweep.nc")
    with pytest.raises(SnappingInputError, match="not a snapping run file"):
        S.combine([sweep_file])
    ds = simulate.load_run(paths[0])
    ds.attrs["status"] = "failed"
    with pytest.raises(SnappingInputError, match=r"not a completed run \(status='failed'"):
        S.combine([ds])
    del ds.attrs["chi"]
    with pytest.raises(SnappingInputError, match="attribute 'chi' is missing"):
        S.combine([ds])
    assert float(S.combine([simulate.load_run(paths[0])])["v_peak"].squeeze()) > 0  # a run Dataset itself is fine


def test_combine_refuses_runs_of_different_methods_or_tolerances(tmp_path):
    a = S.run_sweep(S.Grid(chi=[0.5], N=[6], options={"tol": 1e-7, "method": "euler-richardson"}), tmp_path, workers=1,
                    progress=False)
    b = S.run_sweep(S.Grid(chi=[0.4], N=[6], options={"tol": 1e-7, "method": "fast"}), tmp_path, workers=1,
                    progress=False)
    c = S.run_sweep(S.Grid(chi=[0.5], N=[8], options={"tol": 1e-6, "method": "euler-richardson"}), tmp_path,
                    workers=1, progress=False)
    with pytest.raises(SnappingInputError, match=r"different method.*'euler-richardson'.*'dop853'"):
        S.combine(a + b)
    with pytest.raises(SnappingInputError, match=r"different tol"):
        S.combine(a + c)
    comb = S.combine(a)
    assert comb.attrs["method"] == "euler-richardson" and comb.attrs["tol"] == 1e-7


def test_combined_runs_that_ended_before_the_snap_say_so(tmp_path, capsys):
    grid = S.Grid(chi=[0.5], N=[6, 8], options={"tol": 1e-6, "t_end": 0.05})
    comb = S.combine(S.run_sweep(grid, tmp_path, workers=1, progress=False))
    assert (comb["snap_reached"] == 0).all() and comb["t_snap_v"].isnull().all()
    assert (comb["v_peak"] > 0).all()  # the maxima over the run are kept


def _interrupted_or_stopped(what):
    """A task for a local worker: a run interrupted there (a big Dataset with it), or whether
    the worker was told to stop (after a SIGINT to itself, or after clearing the flag)."""
    import time

    if what == "sigint":  # (between runs: the worker's own handler)
        import signal

        os.kill(os.getpid(), signal.SIGINT)
        t0 = time.monotonic()
        while not S._workers.stopped() and time.monotonic() - t0 < 2.0:
            time.sleep(0.01)
    elif what == "clear":
        S._workers._STOP._value.value = 0
    elif what == "interrupt":
        import xarray as xr

        from snapping.simulate.errors import RunInterrupted

        raise RunInterrupted("interrupted by SIGINT at t=1", 2, dataset=xr.Dataset({"x": ("a", np.zeros(50_000))}),
                             path="run.nc")
    return S._workers.stopped()


def test_a_run_interrupted_in_a_worker_reaches_the_sweep_and_no_queued_task_starts():
    """A SIGINT to a worker between its runs stops the sweep (no traceback). A run interrupted in
    a worker (SIGINT or SIGTERM reached it) comes back as such (not as a broken pool: it
    unpickles, and without its 400 kB Dataset, which is in its file), and the worker starts no
    queued task even before the sweep itself acts on it (here it never does)."""
    from snapping.simulate.errors import RunInterrupted

    got = {}

    def collect(args, result):
        try:
            got[args[0]] = result()
        except KeyboardInterrupt as exc:
            got[args[0]] = exc

    calls = [("sigint",), ("clear",), ("interrupt",), ("next",)]
    S._workers.run_all(1, _interrupted_or_stopped, calls, collect)  # one worker: in order
    assert got["sigint"] is True and got["clear"] is False  # a SIGINT to a worker stops the sweep, no traceback
    exc = got["interrupt"]
    assert type(exc) is RunInterrupted and exc.signum == 2 and exc.exit_status == 130
    assert exc.path == "run.nc" and exc.dataset is None and "interrupted by SIGINT" in str(exc)
    assert got["next"] is True  # the worker's own stop


def test_an_interrupted_run_pickles_with_its_signal_and_path():
    """RunInterrupted rebuilds from its own pickle reduction (a worker's interrupted run reaches
    the sweep as such: without it, unpickling wants ``signum`` and breaks the worker pool;
    dask's tblib, when imported, hides that in this venv)."""
    from snapping.simulate.errors import RunInterrupted

    exc = RunInterrupted("interrupted by SIGTERM at t=2", 15, None, "run.nc")
    exc.note = "kept"
    cls, args, state = exc.__reduce__()
    back = cls(*args)
    back.__dict__.update(state)
    assert type(back) is RunInterrupted and str(back) == "interrupted by SIGTERM at t=2"
    assert (back.signum, back.exit_status, back.path, back.dataset, back.note) == (15, 143, "run.nc", None, "kept")


def _sigint_default():
    """``preexec_fn`` of a sweep subprocess that the test interrupts: SIGINT at its default, as in a
    command typed at a terminal. (A process started in the background by a non-interactive shell,
    e.g. a CI script's ``cmd &``, inherits SIGINT ignored, and Python then keeps it ignored: such a
    sweep, as any program there, does not react to SIGINT sent to it alone.)"""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _env_with_worker_hook(tmp_path, pid_file, body: str) -> dict:
    """The environment of a sweep subprocess (:func:`_worker_env`) whose worker processes only run
    ``body`` (source lines indented by 4, ``os`` and ``time`` imported) at start: a ``sitecustomize``."""
    site = tmp_path / "site"
    site.mkdir()
    (site / "sitecustomize.py").write_text("import sys\nif '--multiprocessing-fork' in sys.orig_argv:\n"
                                           "    import os, time\n" + body)
    env = _worker_env(pid_file)
    env["PYTHONPATH"] = os.pathsep.join([str(site), env["PYTHONPATH"]])
    return env


def _until_both_workers_marked(proc, pid_file, tmp_path, marker: str) -> list[int]:
    """The pids of the sweep's two workers once each has left a file ``marker.PID`` in ``tmp_path``
    (its run under way: a ``sitecustomize`` hook of the test's); the sweep killed if they do not."""
    import time

    pids = []
    try:
        deadline = time.monotonic() + 300
        pids = _wait_for_workers(proc, pid_file, deadline)
        assert len(pids) == 2, f"the workers did not start ({pids}, sweep exit {proc.poll()})"
        while len(list(tmp_path.glob(f"{marker}.*"))) < 2 and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.1)
        assert proc.poll() is None, f"the sweep ended before it could be interrupted: {proc.communicate()[1]}"
        assert len(list(tmp_path.glob(f"{marker}.*"))) == 2, "the runs did not start"
    except BaseException:
        _kill_all(proc, pids)
        raise
    return pids


def _cli_sweep(tmp_path, env, options: str):
    """A ``snapping sweep`` of 4 runs on 2 workers in its own process group, the grid's options
    updated with ``options`` (a dict's source)."""
    import subprocess
    import sys

    out = tmp_path / "out"
    script = ("import sys\nfrom snapping import sweep as S\nfrom snapping.cli import main\nG = S.Grid\n"
              f"S.Grid = lambda chi, N, options: G(chi, N, {{**options, **{options}}})\n"
              f"sys.exit(main(['sweep', '--chi', '0.3,0.4,0.5,0.6', '--N', '200', '--method', 'fast', '--workers', "
              f"'2', '-o', {str(out)!r}]))\n")
    return subprocess.Popen([sys.executable, "-c", script], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True, preexec_fn=_sigint_default), out


def _kill_all(proc, pids):
    """SIGKILL the sweep and any of its workers still alive (a failed test leaves no process)."""
    proc.kill()
    proc.wait()
    for p in pids:
        if _alive(p):
            os.kill(p, 9)


def _interrupt(proc, pids, to_group, timeout=60.0):
    """SIGINT to the sweep's process group (Ctrl-C) or to the sweep alone; its stderr once it
    ended (within ``timeout`` s: what "promptly" means under load), and no worker left."""
    import signal
    import subprocess

    try:
        (os.killpg if to_group else os.kill)(proc.pid, signal.SIGINT)
        try:
            _, err = proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            pytest.fail(f"the sweep did not end within {timeout:g} s of the SIGINT")
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        left = [p for p in pids if _alive(p)]
        for p in left:
            os.kill(p, signal.SIGKILL)
    assert not left, f"workers {left} outlived the interrupted sweep"
    assert proc.returncode == 130, err
    assert "Traceback" not in err and err.strip().count("\n") == 0 and "interrupted" in err
    return err


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc (Linux)")
@pytest.mark.parametrize("to_group", [True, False], ids=["ctrl-c", "sigint-to-the-sweep-alone"])
def test_cli_sweep_sigint_with_workers_stops_promptly_and_saves_the_runs(tmp_path, to_group):
    """SIGINT to the process group (Ctrl-C) or to the sweep alone, once the first two runs are
    under way: exit 130 with one line, no traceback, the two runs saved resumable, the queued
    runs not started, no worker left. The runs cannot end (t_end 1e4: hours), so that a third
    run file can only come from a queued run started after the interrupt."""
    import time

    pid_file = tmp_path / "pids"
    # runs that checkpoint every 0.5 s (to see them under way) and last hours (t_end 1e4; a thin record)
    proc, out = _cli_sweep(tmp_path, _worker_env(pid_file), "{'t_end': 1e4, 'record_thin': 1e-2, 'checkpoint_every': 0.5}")
    pids, under_way = [], {}
    try:
        deadline = time.monotonic() + 300  # (a cold numba cache under load: minutes; idle: ~10 s)
        pids = _wait_for_workers(proc, pid_file, deadline)
        assert len(pids) == 2, f"the workers did not start ({pids}, sweep exit {proc.poll()})"
        while len(under_way) < 2 and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.1)  # until both runs are under way: a checkpoint of each saved
            for p in out.glob("run_*.nc"):
                if p.name not in under_way:
                    under_way[p.name] = str(simulate.load_run(p).attrs["status"])
        assert proc.poll() is None, f"the sweep ended before it could be interrupted: {proc.communicate()[1]}"
        assert sorted(under_way.values()) == ["checkpoint", "checkpoint"], f"the runs are not under way: {under_way}"
    except BaseException:
        _kill_all(proc, pids)
        raise
    _interrupt(proc, pids, to_group)
    statuses = {p.name: str(simulate.load_run(p).attrs["status"]) for p in out.glob("run_*.nc")}
    assert statuses == dict.fromkeys(under_way, "interrupted")  # the two in progress, resumable; the others not started


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc (Linux)")
def test_cli_sweep_sigint_while_its_runs_are_starting_ends_at_once(tmp_path):
    """SIGINT to the sweep alone while its workers' runs are still starting (a slow start, as a
    cold numba compilation under load: here a sleep of 10 min before the first steps, in the
    workers only): the sweep ends promptly (nothing of those runs to save), exit 130, no file."""
    pid_file = tmp_path / "pids"
    # in the sweep's worker processes only: each run's first chunk of steps starts after 600 s
    env = _env_with_worker_hook(tmp_path, pid_file,
        "    from snapping.simulate import driver\n"
        "    drive = driver._drive_locked\n"
        "    def slow(eng, *a, **k):\n"
        "        loop = eng.loop\n"
        "        def slow_loop(*la, **lk):\n"
        f"            open(os.path.join({str(tmp_path)!r}, f'starting.{{os.getpid()}}'), 'w').close()\n"
        "            time.sleep(600)\n"
        "            return loop(*la, **lk)\n"
        "        eng.loop = slow_loop\n"
        "        return drive(eng, *a, **k)\n"
        "    driver._drive_locked = slow\n")
    proc, out = _cli_sweep(tmp_path, env, "{'t_end': 1e4, 'record_thin': 1e-2}")
    pids = _until_both_workers_marked(proc, pid_file, tmp_path, "starting")
    _interrupt(proc, pids, to_group=False)
    assert list(out.glob("run_*.nc")) == []  # nothing was computed, nothing saved; nothing started after


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc (Linux)")
def test_cli_elastic_sweep_sigint_ends_at_once_without_waiting_for_its_runs(tmp_path):
    """An extensible line's runs keep no checkpoint: SIGINT to the sweep alone while they are
    under way (here each worker's solve takes 10 min) ends it promptly, exit 130, no run file
    and no worker left (the runs would be run again: nothing of them to save)."""
    import subprocess
    import sys

    pid_file = tmp_path / "pids"
    # in the sweep's worker processes only: each elastic run takes 600 s after saying it started
    env = _env_with_worker_hook(tmp_path, pid_file,
        "    import snapping.simulate.elastic as E\n"
        "    def slow(*a, **k):\n"
        f"        open(os.path.join({str(tmp_path)!r}, f'solving.{{os.getpid()}}'), 'w').close()\n"
        "        time.sleep(600)\n"
        "    E.solve = slow\n")
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "snapping", "sweep", "--chi", "0.3,0.4,0.5,0.6", "--N", "4",
                             "--stretching", "30", "--workers", "2", "-o", str(out)], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=_sigint_default)
    pids = _until_both_workers_marked(proc, pid_file, tmp_path, "solving")
    _interrupt(proc, pids, to_group=False)
    assert list(out.glob("run_*.nc")) == []  # nothing saved; no queued run started


def test_cli_reproduce_with_failed_runs_prints_the_table_and_exits_1(tmp_path, capsys, monkeypatch):
    import snapping.reproduce as R
    from snapping.cli import main

    def failing(*a, **k):
        raise S.SweepFailed([S.RunFailure(0.1, 2000, {"tol": 1e-8}, "step_size", "time-step underflow at t=1.2",
                                          str(tmp_path / "run.nc"))], [], 5)

    monkeypatch.setattr(R, "reproduce", failing)
    assert main(["reproduce", "--quick", "-o", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err and "1 of the runs failed" in err and "step_size" in err and "2000" in err
