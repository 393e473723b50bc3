"""Long runs that survive, for the angle-form DOP853 path (method 'dop853' / 'fast'):
checkpoints and resume bit for bit, signals, numerical failures (parity with tests/test_checkpoint.py)."""

from __future__ import annotations

import signal
import subprocess
import sys

import numpy as np
import pytest

from snapping import schema
from snapping.simulate import (
    EnergyDriftError,
    NonFiniteError,
    RejectionError,
    RunInterrupted,
    StepSizeError,
    is_resumable,
    load_run,
    resume,
    run,
)
from snapping.simulate.methods import dop853 as HO
from snapping.simulate import rk as R
from snapping.simulate import driver as stepper
from test_checkpoint import _check_failure, _Killed, _StopAt, _wait_for, assert_same_run

CASE = dict(chi=0.3, N=50, snapshot_times=[0.2, 0.9], tol=1e-7, method="dop853")


@pytest.fixture
def small_chunks(monkeypatch):
    # 5 steps per return of the compiled loop at N = 50 (the floor is 20 steps: lower it too)
    monkeypatch.setattr(HO, "NODE_EVALS_PER_CALL", R.NS * 50 * 5)
    yield
    stepper._chunk_hook = None


@pytest.fixture(scope="module")
def reference():
    return run(**CASE).dataset


def _steps_per_call_floor(monkeypatch):
    real = HO.Engine.__init__

    def init(self, *a, **k):
        real(self, *a, **k)
        self.ctl[R.Q_STEPS_PER_CALL] = max(1.0, HO.NODE_EVALS_PER_CALL // (R.NS * self.N))

    monkeypatch.setattr(HO.Engine, "__init__", init)


def test_dop853_files_have_the_failure_attrs(reference):
    a = reference.attrs
    assert a["method"] == "dop853" and a["status"] == "completed"
    assert a["failure"] == "" and int(a["failure_node"]) == -1
    assert a["dt_min"] == 1e-14 and a["max_energy_drift"] == 0.0 and a["max_rejections"] == 100
    assert not any(str(v).startswith("checkpoint") for v in reference.variables)


def test_dop853_resume_after_interrupt_at_every_boundary_is_bit_for_bit(tmp_path, small_chunks, monkeypatch,
                                                                        reference):
    """Stopped at many step boundaries (before, around and after the peak: pending peak
    searches, the located peak state, requested and automatic snapshots), each resumed
    run is the uninterrupted one, bit for bit."""
    _steps_per_call_floor(monkeypatch)
    n_ret = []
    monkeypatch.setattr(stepper, "_chunk_hook", lambda eng: n_ret.append(eng.t) and None)
    assert_same_run(run(**CASE).dataset, reference)  # small calls change nothing
    assert len(n_ret) > 20
    path = tmp_path / "run.nc"
    for k in sorted({1, 2, *range(3, len(n_ret), max(1, len(n_ret) // 8)), len(n_ret) - 1}):
        monkeypatch.setattr(stepper, "_chunk_hook", _StopAt(k))
        with pytest.raises(RunInterrupted) as info:
            run(**CASE, output=path, checkpoint_every=None, overwrite=True)
        assert info.value.exit_status == 130 and info.value.path == str(path)
        monkeypatch.setattr(stepper, "_chunk_hook", None)
        ck = load_run(path)
        assert ck.attrs["status"] == "interrupted" and "--resume" in ck.attrs["stop_reason"]
        assert all(v in ck.variables for v in schema.CHECKPOINT_VARS_DOP853)
        n = ck.sizes["step"]
        assert 0 < n < reference.sizes["step"]
        np.testing.assert_array_equal(ck["v_max"].values, reference["v_max"].values[:n])
        assert is_resumable(path, chi=0.3, N=50, method="fast") and not is_resumable(path, N=51)
        r = resume(path)
        assert_same_run(r.dataset, reference)
        assert r.state is not None and r.state.t == reference.attrs["t_final"]
        on_disk = load_run(path)
        assert on_disk.attrs["status"] == "completed"
        assert not any(str(v).startswith("checkpoint") for v in on_disk.variables)


def test_dop853_resume_from_a_periodic_checkpoint_after_a_crash(tmp_path, small_chunks, monkeypatch):
    case = dict(CASE, record_thin=1e-3, method="fast")
    ref = run(**case).dataset
    path = tmp_path / "run.nc"
    monkeypatch.setattr(stepper, "_chunk_hook", _StopAt(4, _Killed()))
    with pytest.raises(_Killed):
        run(**case, output=path, checkpoint_every=0)
    monkeypatch.setattr(stepper, "_chunk_hook", None)
    ck = load_run(path)
    assert ck.attrs["status"] == "checkpoint" and ck.attrs["method"] == "dop853"
    # interrupt the resumed run too (SIGTERM), and resume again, into another file
    monkeypatch.setattr(stepper, "_chunk_hook", _StopAt(2, signal.SIGTERM))
    with pytest.raises(RunInterrupted) as info:
        resume(path, checkpoint_every=None)
    assert info.value.exit_status == 143
    monkeypatch.setattr(stepper, "_chunk_hook", None)
    assert load_run(path).attrs["n_steps"] > ck.attrs["n_steps"]
    out = tmp_path / "continued.nc"
    r = resume(path, output=out)
    assert r.path == str(out)
    assert_same_run(r.dataset, ref)
    assert_same_run(load_run(out), load_run(run(**case, output=tmp_path / "ref.nc").path))


def test_dop853_cli_sigint_stops_saves_and_resumes(tmp_path):
    case = ["--chi", "0.25", "--N", "1000", "--method", "dop853", "--tol", "1e-9"]
    path = tmp_path / "run.nc"
    cmd = [sys.executable, "-m", "snapping.cli", "simulate", *case, "-o", str(path), "--checkpoint-every", "0",
           "--no-progress"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    _wait_for(path, proc)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=300)  # (hang guards, not timings: a loaded machine)
    assert proc.returncode == 130, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err
    assert f"resume with: snapping simulate --resume {path}" in lines[0]
    ck = load_run(path)
    assert ck.attrs["status"] == "interrupted" and ck.attrs["method"] == "dop853"
    done = subprocess.run([sys.executable, "-m", "snapping.cli", "simulate", "--resume", str(path), "--json",
                           "--no-progress"], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert_same_run(load_run(path), run(0.25, 1000, method="dop853", tol=1e-9).dataset)


# ---------------------------------------------------------------- numerical failures
def test_dop853_step_size_floor(tmp_path):
    path = tmp_path / "f.nc"
    with pytest.raises(StepSizeError, match="dt_min") as info:
        run(0.5, 10, method="dop853", dt_min=0.5, output=path)
    _check_failure(info, path, "step_size", StepSizeError)


def test_dop853_too_many_rejections(tmp_path):
    path = tmp_path / "f.nc"
    with pytest.raises(RejectionError, match="consecutive rejected") as info:
        run(0.5, 10, method="dop853", dt0=0.5, max_rejections=0, output=path)
    exc, ds = _check_failure(info, path, "rejections", RejectionError)
    assert exc.step == 0 and ds.attrs["n_rejected"] == 1 and ds.attrs["max_rejections"] == 0


def test_dop853_energy_drift_bound(tmp_path):
    path = tmp_path / "f.nc"
    with pytest.raises(EnergyDriftError, match="energy drift") as info:
        run(0.5, 10, method="dop853", max_energy_drift=1e-300, output=path)
    _, ds = _check_failure(info, path, "energy_drift", EnergyDriftError)
    assert ds.attrs["energy_drift"] > 1e-300 and ds.attrs["max_energy_drift"] == 1e-300


def test_dop853_non_finite_state(tmp_path, small_chunks, monkeypatch):
    def inject(eng):
        eng.Y1[int(eng.ctl[R.Q_SLOT])][50 + 7] = np.nan  # angular velocity of link 7
        return None

    monkeypatch.setattr(stepper, "_chunk_hook", inject)
    path = tmp_path / "f.nc"
    with pytest.raises(NonFiniteError, match="non-finite") as info:
        run(0.5, 50, method="dop853", output=path)
    exc, _ = _check_failure(info, path, "non_finite", NonFiniteError)
    assert 0 <= exc.node <= 50
