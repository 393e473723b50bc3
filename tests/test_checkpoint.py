"""Long runs that survive (#7): checkpoint and resume, signals, numerical failures, the memory guard."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from snapping import SnappingInputError, schema
from snapping import sweep as S
from snapping.simulate import (
    memory_need,
    DriftError,
    EnergyDriftError,
    NonFiniteError,
    RejectionError,
    RunInterrupted,
    SimulationError,
    StepSizeError,
    is_resumable,
    load_run,
    resume,
    run,
)
from snapping.simulate import kernels as K
from snapping.simulate import driver as stepper
from snapping.simulate.methods import euler_richardson as ER


def assert_same_run(a, b):
    """Every variable, coordinate and attribute equal (NaN == NaN), except the wall time."""
    assert set(a.variables) == set(b.variables)
    for name in a.variables:
        x, y = a[name].values, b[name].values
        assert x.dtype == y.dtype and x.shape == y.shape, name
        assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), name
    assert set(a.attrs) == set(b.attrs)
    for k in a.attrs:
        if k in ("wall_time", "integrity_sha256"):  # the digest covers the wall time
            continue
        x, y = np.asarray(a.attrs[k]), np.asarray(b.attrs[k])
        assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), k


class _StopAt:
    """Test hook: after the k-th return of the compiled loop, act as if ``what`` happened."""

    def __init__(self, k, what=signal.SIGINT):
        self.k, self.what, self.n = k, what, 0

    def __call__(self, eng):
        self.n += 1
        if self.n == self.k:
            if isinstance(self.what, int):
                return self.what
            raise self.what
        return None


class _Killed(Exception):
    """Stands for SIGKILL / power loss: the run dies without saving."""


@pytest.fixture
def small_chunks(monkeypatch):
    # about 400 steps per return of the compiled loop at N = 50
    monkeypatch.setattr(ER, "NODE_STEPS_PER_CALL", 50 * 400)
    yield
    stepper._chunk_hook = None


#: the paper's method and chain: this file checks the Euler-Richardson checkpoints (dop853's:
#: test_checkpoint_dop853.py)
PAPER = dict(method="euler-richardson", chords="arclength")
CASE = dict(chi=0.3, N=50, snapshot_times=[0.2, 0.9], tol=1e-7, **PAPER)


def test_resume_after_interrupt_is_bit_for_bit(tmp_path, small_chunks, monkeypatch):
    ref = run(**CASE).dataset
    path = tmp_path / "run.nc"
    monkeypatch.setattr(stepper, "_chunk_hook", _StopAt(9))
    with pytest.raises(RunInterrupted) as info:
        run(**CASE, output=path, checkpoint_every=0)
    assert info.value.exit_status == 130 and info.value.path == str(path)
    monkeypatch.setattr(stepper, "_chunk_hook", None)
    ck = load_run(path)
    assert ck.attrs["status"] == "interrupted" and "--resume" in ck.attrs["stop_reason"]
    assert 0 < ck.sizes["step"] < ref.sizes["step"]
    assert all(k in ck.variables for k in schema.CHECKPOINT_VARS)
    assert is_resumable(path, chi=0.3, N=50) and not is_resumable(path, chi=0.3, N=51)
    # the partial record is the same as the beginning of the uninterrupted one
    n = ck.sizes["step"]
    np.testing.assert_array_equal(ck["v_max"].values, ref["v_max"].values[:n])
    r = resume(path)
    assert_same_run(r.dataset, ref)
    on_disk = load_run(path)
    assert on_disk.attrs["status"] == "completed"
    assert not any(v.startswith("checkpoint") for v in on_disk.variables)
    assert_same_run(on_disk, load_run(run(**CASE, output=tmp_path / "ref.nc").path))
    with pytest.raises(SnappingInputError, match="nothing to resume"):
        resume(path)


def test_resume_from_a_periodic_checkpoint_after_a_crash(tmp_path, small_chunks, monkeypatch):
    """A run killed without warning (no save at exit) continues from its last periodic checkpoint."""
    case = dict(CASE, record_thin=1e-3)
    ref = run(**case).dataset
    path = tmp_path / "run.nc"
    monkeypatch.setattr(stepper, "_chunk_hook", _StopAt(14, _Killed()))
    with pytest.raises(_Killed):
        run(**case, output=path, checkpoint_every=0)
    monkeypatch.setattr(stepper, "_chunk_hook", None)
    assert load_run(path).attrs["status"] == "checkpoint"
    # interrupt the resumed run too, and resume again, into another file
    monkeypatch.setattr(stepper, "_chunk_hook", _StopAt(3, signal.SIGTERM))
    with pytest.raises(RunInterrupted) as info:
        resume(path, checkpoint_every=None)
    assert info.value.exit_status == 143
    monkeypatch.setattr(stepper, "_chunk_hook", None)
    out = tmp_path / "continued.nc"
    r = resume(path, output=out)
    assert r.path == str(out)
    assert_same_run(r.dataset, ref)
    assert r.dataset.attrs["wall_time"] > 0


def _wait_for(path, proc, timeout=300.0):  # (a hang guard: a cold start under load takes minutes)
    t0 = time.monotonic()
    while not os.path.exists(path):
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() - t0 < timeout
        time.sleep(0.02)


SIG_CASE = ["--chi", "0.25", "--N", "400", "--method", "euler-richardson", "--chords", "arclength"]


@pytest.fixture(scope="module")
def sig_reference():
    return run(0.25, 400, **PAPER).dataset


@pytest.mark.parametrize("sig, status", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_cli_signal_stops_saves_and_resumes(tmp_path, sig, status, sig_reference):
    path = tmp_path / "run.nc"
    cmd = [sys.executable, "-m", "snapping.cli", "simulate", *SIG_CASE, "-o", str(path),
           "--checkpoint-every", "0", "--no-progress"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    _wait_for(path, proc)  # the first checkpoint: the run has started
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=300)  # (hang guards, not timings: a loaded machine)
    assert proc.returncode == status, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err
    assert f"resume with: snapping simulate --resume {path}" in lines[0]
    ck = load_run(path)
    assert ck.attrs["status"] == "interrupted"
    assert ck.attrs["n_steps"] < sig_reference.attrs["n_steps"]
    if sig == signal.SIGINT:  # resume on the command line
        done = subprocess.run([sys.executable, "-m", "snapping.cli", "simulate", "--resume", str(path), "--json",
                               "--no-progress"], capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, done.stderr
        result = load_run(path)
    else:  # resume from Python
        result = resume(path).dataset
    assert_same_run(result, sig_reference)


# ---------------------------------------------------------------- sweeps
def test_sweep_resumes_checkpointed_runs_and_restarts_broken_ones(tmp_path, small_chunks, monkeypatch):
    opts = {"tol": 1e-7, **PAPER}
    grid = S.Grid(chi=[0.4, 0.6], N=[30], options=opts)
    p_int, p_bad = grid.path(tmp_path, 0.4, 30), grid.path(tmp_path, 0.6, 30)
    # a worker interrupted half way through its run
    monkeypatch.setattr(stepper, "_chunk_hook", _StopAt(6))
    with pytest.raises(RunInterrupted):
        run(0.4, 30, output=p_int, **opts)
    monkeypatch.setattr(stepper, "_chunk_hook", None)
    # a worker killed while writing (a truncated file), next to a checkpoint of another run
    p_bad.write_bytes(b"\x89HDF\r\n\x1a\n truncated")
    assert is_resumable(p_int, chi=0.4, N=30, tol=1e-7) and not is_resumable(p_bad)
    calls = []
    real_resume, real_run = resume, run  # (snapping.simulate's, the names the sweep calls)
    monkeypatch.setattr("snapping.simulate.resume", lambda *a, **k: calls.append("resume") or real_resume(*a, **k))
    monkeypatch.setattr("snapping.simulate.run", lambda *a, **k: calls.append("run") or real_run(*a, **k))
    paths = S.run_sweep(grid, tmp_path, workers=1, progress=False)
    assert sorted(calls) == ["resume", "run"]
    for p, chi in zip(paths, (0.4, 0.6)):
        assert S.is_complete_run(p)
        assert_same_run(load_run(p), run(chi, 30, **opts).dataset)
    # a checkpoint of a different run under a sweep's file name is restarted, not resumed
    monkeypatch.setattr(stepper, "_chunk_hook", _StopAt(2))
    with pytest.raises(RunInterrupted):
        run(0.6, 30, output=p_bad, tol=1e-6, overwrite=True, **PAPER)
    monkeypatch.setattr(stepper, "_chunk_hook", None)
    assert not is_resumable(p_bad, chi=0.6, N=30, tol=1e-7)
    before = os.stat(p_int).st_mtime_ns
    calls.clear()
    S.run_sweep(grid, tmp_path, workers=1, progress=False)
    assert calls == ["run"] and os.stat(p_int).st_mtime_ns == before
    assert load_run(p_bad).attrs["tol"] == 1e-7


# ---------------------------------------------------------------- numerical failures
def _check_failure(info, path, kind, cls):
    exc = info.value
    assert type(exc) is cls and isinstance(exc, SimulationError)
    assert exc.kind == kind and exc.path == str(path)
    assert math.isfinite(exc.t) and exc.step >= 0
    ds = load_run(path)
    assert ds.attrs["status"] == "failed" and ds.attrs["failure"] == kind
    assert ds.attrs["stop_reason"] in str(exc)
    assert int(ds.attrs["failure_node"]) == exc.node and 0 <= exc.node <= int(ds.attrs["N"])
    assert f"step {exc.step}" in str(exc) and f"worst node {exc.node}" in str(exc)
    assert ds.sizes["step"] >= 1 and ds["snapshot_kind"].values[-1] == "final"
    assert not any(v.startswith("checkpoint") for v in ds.variables)
    return exc, ds


def test_step_size_floor(tmp_path):
    path = tmp_path / "f.nc"
    with pytest.raises(StepSizeError, match="dt_min") as info:
        run(0.5, 10, dt_min=1e-3, dt0=1e-2, output=path, **PAPER)  # (dt0 = sqrt(tol) would be below dt_min)
    _check_failure(info, path, "step_size", StepSizeError)


def test_too_many_rejections(tmp_path):
    path = tmp_path / "f.nc"
    with pytest.raises(RejectionError, match="consecutive rejected") as info:
        run(0.5, 10, dt0=0.5, max_rejections=0, output=path, **PAPER)
    exc, ds = _check_failure(info, path, "rejections", RejectionError)
    assert exc.step == 0 and ds.attrs["n_rejected"] == 1


def test_energy_drift_bound(tmp_path):
    path = tmp_path / "f.nc"
    with pytest.raises(EnergyDriftError, match="energy drift") as info:
        run(0.5, 10, max_energy_drift=1e-300, output=path, **PAPER)
    exc, ds = _check_failure(info, path, "energy_drift", EnergyDriftError)
    assert isinstance(exc, DriftError) and ds.attrs["energy_drift"] > 1e-300


def test_link_drift_bound(tmp_path):
    path = tmp_path / "f.nc"
    with pytest.raises(DriftError, match="link-length drift") as info:
        run(0.5, 10, method="euler-richardson-fixed", dt0=0.05, max_link_error=1e-3, output=path)
    exc, ds = _check_failure(info, path, "link_drift", DriftError)
    # the worst node starts the worst link
    Z = np.stack([ds[v].isel(snapshot=-1).values for v in ("x", "y")])
    err = np.abs(10 * np.hypot(*np.diff(Z, axis=1)) - 1)
    assert exc.node == int(np.argmax(err))


def test_non_finite_state(tmp_path, small_chunks, monkeypatch):
    def inject(eng):
        eng.S[int(eng.ctl[K.C_CUR])][K.RVX, 7] = np.nan
        return None

    monkeypatch.setattr(stepper, "_chunk_hook", inject)
    path = tmp_path / "f.nc"
    with pytest.raises(NonFiniteError, match="non-finite") as info:
        run(0.5, 50, output=path, **PAPER)
    exc, _ = _check_failure(info, path, "non_finite", NonFiniteError)
    assert exc.node == 7


# ---------------------------------------------------------------- resource guard
def test_memory_guard_refuses_with_numbers(monkeypatch):
    from snapping.simulate import options

    monkeypatch.setattr(options, "_available_memory", lambda: 10 * 2**20)
    with pytest.raises(SnappingInputError, match=r"GiB.*available.*record_thin") as info:
        run(0.25, 100, **PAPER)
    msg = str(info.value)
    assert "0.00977 GiB is available" in msg and "steps" in msg
    # thinning the record makes it fit
    r = run(0.25, 100, record_thin=1e-2, t_end=0.05, **PAPER)
    assert r.dataset.attrs["status"] == "completed"


def test_memory_guard_against_the_real_machine():
    with pytest.raises(SnappingInputError, match="would need about"):
        run(0.5, 10, method="euler-richardson-fixed", dt0=1e-12, t_end=10.0)
    with pytest.raises(SnappingInputError, match="would need about"):
        run(0.5, 10**10)
    with pytest.raises(SnappingInputError, match="would need about"):  # every method has the guard
        run(0.5, 10**9, method="fast")
    need = memory_need(10, chi=0.5, method="euler-richardson-fixed", dt0=1e-12, t_end=10.0, record_thin=1e-3)
    assert need["records"] < 10**6
