"""``snapping simulate --stretching ... --method rodas4 --checkpoint FILE [--resume]``: a run
stopped by a real SIGINT (sent from outside, to a subprocess, while its compiled loop runs) saves
its checkpoint, exits 130 and prints the command that continues it; that command's run writes
the same -o file, every variable and attribute (``wall_time`` aside), bit for bit, as the
uninterrupted run of the command without --checkpoint (the reference: a different code path,
no checkpoint at all). Misdirected commands are refused (exit 2) before anything is written,
naming the option: an existing checkpoint without --resume, a checkpoint of other options,
--checkpoint with a method that keeps none (Radau, DOP853) or with the rigid chain, -o the
checkpoint itself, --checkpoint-every without a checkpoint. And one checkpoint is never
continued by two processes: a resume is refused while another process holds its lock (naming
that PID), and a resuming run holds it from its first chunk (another process finds it busy)."""

from __future__ import annotations

import hashlib
import os
import shlex
import shutil
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import xarray as xr

from snapping import _files
from snapping.cli import main
from snapping.simulate import elastic_checkpoint as ECK

HERE = os.path.dirname(os.path.abspath(__file__))
RUN = ["simulate", "--chi", "0.25", "--N", "12", "--stretching", "20", "--method", "rodas4",
       "--snapshot-times", "0.1,0.5", "--no-progress"]


def _sigint_default():  # (a subprocess of a background job inherits SIGINT ignored)
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _digest(p) -> str:
    return hashlib.sha256(open(p, "rb").read()).hexdigest()


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The command run in a subprocess with --checkpoint, SIGINT sent to it at its loop's 2nd
    return; meanwhile (while the subprocess starts) the uninterrupted run of the same command,
    no checkpoint, in this process: its -o file, the reference."""
    d = tmp_path_factory.mktemp("interrupted")
    marker, go, ck, out = d / "marker", d / "go", d / "ck.nc", d / "run.nc"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    proc = subprocess.Popen([sys.executable, os.path.join(HERE, "elastic_cli_child.py"), str(marker), str(go), "2",
                             *RUN, "--checkpoint", str(ck), "-o", str(out)], cwd=d, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=_sigint_default)
    try:
        ref = tmp_path_factory.mktemp("ref") / "ref.nc"
        assert main([*RUN, "-o", str(ref)]) == 0
        t0 = time.monotonic()
        while not marker.exists() and proc.poll() is None and time.monotonic() - t0 < 120:
            time.sleep(0.01)
        assert marker.exists(), proc.communicate()
        proc.send_signal(signal.SIGINT)  # (the run notes it; its loop stops at the next step boundary)
        time.sleep(0.2)
        go.touch()
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    return {"rc": proc.returncode, "err": err, "ck": ck, "out": out, "dir": d, "ref": xr.load_dataset(ref)}


@pytest.fixture
def interrupted(runs):
    return runs


@pytest.fixture
def reference(runs):
    return runs["ref"]


def test_sigint_saves_and_the_printed_command_resumes_bit_for_bit(interrupted, reference, tmp_path, capsys):
    assert interrupted["rc"] == 130, interrupted["err"]
    err = interrupted["err"].strip().splitlines()[-1]
    assert err.startswith("snapping simulate: interrupted by SIGINT at t="), err
    assert not interrupted["out"].exists()  # (-o is the finished run: nothing written yet)
    ck = xr.load_dataset(interrupted["ck"])
    assert ck.attrs["status"] == "interrupted"
    assert 0.0 < ck.attrs["t_final"] < reference.attrs["t_final"]
    cmd = err.split("resume with: ", 1)[1]
    argv = shlex.split(cmd)
    assert argv[0] == "snapping" and argv[-3:] == ["--checkpoint", str(interrupted["ck"]), "--resume"], cmd
    # the printed command, run where the interrupted one ran
    cwd = os.getcwd()
    os.chdir(interrupted["dir"])
    try:
        shutil.copy(interrupted["ck"], tmp_path / "kept.nc")
        assert main(argv[1:]) == 0
    finally:
        os.chdir(cwd)
    got = xr.load_dataset(interrupted["out"])
    assert set(got.variables) == set(reference.variables)
    for k in reference.variables:
        assert np.array_equal(got[k].values, reference[k].values), k
    assert set(got.attrs) == set(reference.attrs)
    for k in reference.attrs:
        if k != "wall_time":
            assert str(got.attrs[k]) == str(reference.attrs[k]), k
    assert got.attrs["status"] == "completed"
    # a second resume of the saved checkpoint, to a second -o: the same run again
    out2 = tmp_path / "again.nc"
    assert main([*RUN, "--resume", str(tmp_path / "kept.nc"), "-o", str(out2)]) == 0
    assert np.array_equal(xr.load_dataset(out2)["v_max"].values, reference["v_max"].values)
    capsys.readouterr()


def _with(opt, value):
    """RUN with the value of ``opt`` replaced."""
    i = RUN.index(opt)
    return [*RUN[:i + 1], value, *RUN[i + 2:]]


def _refused(argv, capsys, *words):
    rc = main(argv)
    err = capsys.readouterr().err
    assert rc == 2, err
    for w in words:
        assert w in err, (w, err)
    return err


def test_misdirected_commands_refused_and_nothing_written(interrupted, tmp_path, capsys):
    ck = tmp_path / "ck.nc"
    shutil.copy(interrupted["ck"], ck)
    before = _digest(ck)
    out = tmp_path / "run.nc"
    # an existing checkpoint, without --resume: never replaced
    _refused([*RUN, "--checkpoint", str(ck), "-o", str(out)], capsys, "--checkpoint", "already exists",
             "--resume")
    # a checkpoint of other options: the option that differs is named
    _refused([*_with("--stretching", "21"), "--checkpoint", str(ck), "--resume", "-o", str(out)], capsys,
             "--stretching", "contradicts the checkpoint", "441.0")
    _refused([*RUN, "--tol", "1e-7", "--checkpoint", str(ck), "--resume", "-o", str(out)], capsys,
             "--tol contradicts the checkpoint", "1e-07")
    _refused([*_with("--method", "rodas4-links"), "--resume", str(ck), "-o", str(out)], capsys,
             "--method contradicts the checkpoint", "rodas4-links")
    _refused([*_with("--N", "13"), "--resume", str(ck), "-o", str(out)], capsys, "--N contradicts")
    # methods that keep no checkpoint: the option, its value and the methods that do
    for m, name in (("fast", "radau"), ("dop853", "dop853")):
        _refused([*_with("--method", m), "--checkpoint", str(tmp_path / "new.nc"), "-o", str(out)], capsys,
                 f"--checkpoint {tmp_path / 'new.nc'} with --method {m}", name, "rodas4 (or stiff) and rodas4-links")
    _refused([*_with("--method", "fast"), "--resume", str(ck), "-o", str(out)], capsys, f"--resume {ck} with --method fast")
    # the rigid chain's run checkpoints to -o: --checkpoint is refused, naming it
    _refused(["simulate", "--chi", "0.25", "--N", "12", "--checkpoint", str(tmp_path / "new.nc")], capsys,
             "--checkpoint", "the extensible line's")
    _refused([*RUN, "--resume", "-o", str(out)], capsys, "--resume without a file", "--checkpoint FILE")
    _refused([*RUN, "--checkpoint-every", "5", "-o", str(out)], capsys, "--checkpoint-every 5.0 needs --checkpoint")
    _refused([*RUN, "--checkpoint", str(ck), "--resume", "-o", str(ck)], capsys, "name the same file")
    _refused([*RUN, "--checkpoint", str(tmp_path / "ck.txt"), "-o", str(out)], capsys,
             "--checkpoint=", "ck.txt' has the suffix .txt")
    # -o existing, without --overwrite: refused before the run (no checkpoint started)
    assert not out.exists()
    out.write_bytes(b"x")
    _refused([*RUN, "--checkpoint", str(tmp_path / "new.nc"), "-o", str(out)], capsys, "already exists")
    assert not (tmp_path / "new.nc").exists() and out.read_bytes() == b"x"
    assert _digest(ck) == before
    assert sorted(os.listdir(tmp_path)) == ["ck.nc", "run.nc"]  # (no lock or partial files left)
    # the library refuses it too, naming the parameter, its value and the methods that keep checkpoints
    from snapping._validate import SnappingInputError
    from snapping.simulate.elastic import Elastic, solve
    from snapping.simulate.problem import Links, Problem

    P, E = Problem.catenary(0.25, links=Links.uniform(12, lumping="shared")), Elastic.from_wave_speed(20.0)
    for m in ("radau", "dop853"):
        with pytest.raises(SnappingInputError, match=f"checkpoint='.*new.nc' with method='{m}': only the methods "
                                                     r"\('rodas4', 'rodas4-links'\)"):
            solve(P, E, method=m, checkpoint=tmp_path / "new.nc")
    with pytest.raises(SnappingInputError, match="checkpoint_every=5.0 with method='radau'"):
        solve(P, E, method="radau", checkpoint_every=5.0)
    assert not (tmp_path / "new.nc").exists()


LOCKER = """
import sys, time
from snapping._files import OutputBusyError, locked
if sys.argv[2] == "hold":
    with locked(sys.argv[1], name="checkpoint"):
        print("held", flush=True)
        sys.stdin.read()
else:
    try:
        with locked(sys.argv[1], name="checkpoint"):
            print("free")
    except OutputBusyError as exc:
        print(exc)
"""


def test_checkpoint_locked_while_a_run_resumes_it(interrupted, reference, tmp_path, capsys):
    """Two processes never both continue one checkpoint: one holding its lock (as a resuming run
    does) makes a second resume exit 2 naming its PID, the file untouched; and a resuming run
    holds the lock from its first chunk to its end (another process finds it busy)."""
    ck, out = tmp_path / "ck.nc", tmp_path / "run.nc"
    shutil.copy(interrupted["ck"], ck)
    before = _digest(ck)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    holder = subprocess.Popen([sys.executable, "-c", LOCKER, str(ck), "hold"], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True, env=env)
    try:
        assert holder.stdout.readline().strip() == "held"
        _refused([*RUN, "--checkpoint", str(ck), "--resume", "-o", str(out)], capsys,
                 f"--checkpoint={str(ck)!r} is being written by process PID {holder.pid}")
    finally:
        holder.communicate("", timeout=30)
    assert _digest(ck) == before and not out.exists()
    seen = []

    def probe(run):  # (inside the resumed run: is its checkpoint locked for another process?)
        if not seen:
            seen.append(subprocess.run([sys.executable, "-c", LOCKER, str(ck), "try"], capture_output=True,
                                       text=True, env=env, timeout=60).stdout)
        return None

    ECK._chunk_hook = probe
    try:
        assert main([*RUN, "--checkpoint", str(ck), "--resume", "-o", str(out)]) == 0
    finally:
        ECK._chunk_hook = None
    assert f"is being written by process PID {os.getpid()}" in seen[0], seen
    assert np.array_equal(xr.load_dataset(out)["a_max"].values, reference["a_max"].values)
    assert not os.path.exists(_files.lock_path(str(ck)))  # (released at the end)
    capsys.readouterr()
