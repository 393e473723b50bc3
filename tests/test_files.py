"""Files users can trust (snapping._files): no silent overwrite, only regular files, symbolic
links written through, one writer at a time, atomic writes, temporaries cleaned up, a full disk
named as such, checkpoints that carry an integrity digest, resumes that cannot change the run.

Fault tests run the CLI in subprocesses: SIGKILL in the middle of a checkpoint write, two
concurrent writers of one file.
"""

import hashlib
import os
import signal
import subprocess
import sys
import textwrap
import time

import netCDF4
import numpy as np
import pytest

from snapping import _files, schema
from snapping._validate import SnappingInputError
from snapping.cli import main
from snapping.simulate import driver, load_run, resume, run, save
from snapping.simulate.errors import RunInterrupted

PY = sys.executable
SMALL = dict(chi=0.5, N=12, t_end=0.2, method="fast")


def _digest(path):
    with open(path, "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()


def _cli(argv, capsys):
    try:
        status = main([str(a) for a in argv])
    except SystemExit as exc:
        status = exc.code
    out, err = capsys.readouterr()
    return status, out, err


def _one_line_error(err):
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "error" in lines[0] and "Traceback" not in err, err
    return lines[0]


# ------------------------------------------------------------------ existing outputs
def test_existing_output_is_refused_and_untouched(tmp_path, capsys):
    p = tmp_path / "run.nc"
    run(**SMALL, output=p)
    before = _digest(p)
    with pytest.raises(SnappingInputError, match="already exists.*overwrite=True"):
        run(**SMALL, output=p)
    status, _, err = _cli(["simulate", "--chi", "0.4", "--N", "12", "--t-end", "0.1", "-o", p], capsys)
    assert status == 2 and "--overwrite" in _one_line_error(err)
    assert _digest(p) == before
    r = run(chi=0.4, N=12, t_end=0.1, method="fast", output=p, overwrite=True)
    assert float(load_run(p).attrs["chi"]) == 0.4 and r.path == str(p)
    with pytest.raises(SnappingInputError, match="already exists"):
        r.save(p)
    assert r.save(p, overwrite=True) == str(p)


@pytest.mark.parametrize("kind", ["device", "fifo", "directory"])
def test_non_regular_outputs_are_never_replaced(tmp_path, kind, capsys):
    if kind == "device":
        p = "/dev/null"
    elif kind == "fifo":
        p = tmp_path / "pipe"
        os.mkfifo(p)
    else:
        p = tmp_path / "dir"
        p.mkdir()
    mode = os.stat(p).st_mode
    for overwrite in (False, True):
        with pytest.raises(SnappingInputError, match="not a regular file|names a directory|is a directory"):
            run(**SMALL, output=p, overwrite=overwrite)
    status, _, err = _cli(["simulate", "--chi", "0.5", "--N", "12", "--t-end", "0.1", "-o", p, "--overwrite"], capsys)
    assert status == 2 and "regular file" in _one_line_error(err)
    assert os.stat(p).st_mode == mode  # still a device / FIFO / directory
    if kind == "fifo":  # reading one is refused before anything opens it (that would block)
        with pytest.raises(SnappingInputError, match="FIFO"):
            resume(p)
        status, _, err = _cli(["fit", p], capsys)
        assert status == 2


def test_symbolic_link_is_written_through(tmp_path):
    target = tmp_path / "target.nc"
    link = tmp_path / "link.nc"
    link.symlink_to(target)  # dangling: the run creates the target
    run(**SMALL, output=link)
    assert link.is_symlink() and target.is_file()
    with pytest.raises(SnappingInputError, match="symbolic link"):
        run(**SMALL, output=link)  # the target exists now
    run(chi=0.3, N=12, t_end=0.1, method="fast", output=link, overwrite=True)
    assert link.is_symlink() and float(load_run(target).attrs["chi"]) == 0.3
    dev = tmp_path / "devlink"
    dev.symlink_to("/dev/null")
    with pytest.raises(SnappingInputError, match="character device"):
        run(**SMALL, output=dev, overwrite=True)
    assert dev.is_symlink() and os.path.realpath(dev) == "/dev/null"


def test_whole_output_path_checked_before_the_run(tmp_path, monkeypatch):
    calls = []
    monkeypatch.setattr(driver, "_drive", lambda *a, **k: calls.append(1))
    with pytest.raises(SnappingInputError, match="does not exist"):
        run(**SMALL, output=tmp_path / "missing" / "run.nc")
    with pytest.raises(SnappingInputError, match="is not a directory"):
        (tmp_path / "file").write_text("x")
        run(**SMALL, output=tmp_path / "file" / "run.nc")
    with pytest.raises(SnappingInputError, match="has only .* free"):
        _files.check_output(tmp_path / "big.nc", need_bytes=1e18)
    assert calls == []


def test_free_space_is_checked_with_the_run_estimate(tmp_path, monkeypatch):
    import shutil
    from collections import namedtuple

    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(shutil, "disk_usage", lambda d: usage(10**9, 10**9 - 10**4, 10**4))
    with pytest.raises(SnappingInputError, match="the file needs about .* has only 10 kB free"):
        run(0.25, 2000, method="fast", output=tmp_path / "run.nc")
    assert not (tmp_path / "run.nc").exists()


# ------------------------------------------------------------------ full disk
def _mount_tiny_tmpfs(path, size="2m"):
    path.mkdir()
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(path)], capture_output=True)
    return r.returncode == 0


def test_full_disk_is_named_and_nothing_is_replaced(tmp_path, monkeypatch):
    ds = run(0.5, 40, method="fast").dataset
    mnt = tmp_path / "tiny"
    mounted = os.geteuid() == 0 and _mount_tiny_tmpfs(mnt)
    try:
        if mounted:  # a real full filesystem
            p = mnt / "run.nc"
            run(**SMALL, output=p)
            before = _digest(p)
            with open(mnt / "filler", "wb") as fh:  # leave ~20 kB free
                free = os.statvfs(mnt).f_bavail * os.statvfs(mnt).f_frsize
                fh.write(b"\0" * max(0, free - 20_000))
        else:  # a simulated ENOSPC
            mnt.mkdir(exist_ok=True)
            p = mnt / "run.nc"
            run(**SMALL, output=p)
            before = _digest(p)
            import xarray as xr

            def enospc(self, tmp, **kw):
                with open(tmp, "wb") as fh:
                    fh.write(b"\0" * 1000)
                raise OSError(28, "No space left on device")

            monkeypatch.setattr(xr.Dataset, "to_netcdf", enospc)
        with pytest.raises(_files.OutputWriteError, match="the disk is full") as info:
            save(ds, p, overwrite=True)
        assert info.value.dataset is ds  # the result is not lost
        assert _digest(p) == before
        assert sorted(f.name for f in mnt.iterdir() if f.name.startswith(".")) == []  # no .part, no lock left
    finally:
        if mounted:
            import gc

            gc.collect()  # a failed netCDF write may leave its handle to be collected
            subprocess.run(["umount", "-l", str(mnt)], check=False)


def test_full_disk_in_the_cli_is_one_line_and_exit_1(tmp_path, monkeypatch, capsys):
    import xarray as xr

    def hdf_error(self, tmp, **kw):
        raise RuntimeError("NetCDF: HDF error")

    import shutil
    from collections import namedtuple

    real = shutil.disk_usage
    usage = namedtuple("usage", "total used free")
    state = {"full": False}
    monkeypatch.setattr(shutil, "disk_usage", lambda d: usage(10**9, 10**9, 0) if state["full"] else real(d))

    def full_then_error(self, tmp, **kw):
        state["full"] = True
        hdf_error(self, tmp, **kw)

    monkeypatch.setattr(xr.Dataset, "to_netcdf", full_then_error)
    status, _, err = _cli(["simulate", "--chi", "0.5", "--N", "12", "--t-end", "0.1", "--method", "fast",
                           "-o", tmp_path / "r.nc"], capsys)
    assert status == 1 and "the disk is full" in _one_line_error(err)
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------ locks, temporaries
HOLD = textwrap.dedent("""
    import sys, time
    from snapping import _files
    with _files.locked(sys.argv[1]):
        print("locked", flush=True)
        time.sleep(60)
""")


def test_a_second_writer_is_refused_naming_the_holder(tmp_path):
    p = tmp_path / "run.nc"
    holder = subprocess.Popen([PY, "-c", HOLD, str(p)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(_files.OutputBusyError, match=f"process PID {holder.pid}"):
            run(**SMALL, output=p)
        (tmp_path / f".{p.name}.abc123.part").write_bytes(b"half a file")  # as if it was killed mid-write
        with pytest.raises(_files.OutputBusyError):
            save(run(**SMALL).dataset, p)
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
    assert not p.exists()
    run(**SMALL, output=p)  # the kernel released the dead holder's lock; its stale temporary is removed
    assert sorted(f.name for f in tmp_path.iterdir()) == ["run.nc"]


def test_two_concurrent_cli_writers(tmp_path):
    p = tmp_path / "run.nc"
    cmd = [PY, "-m", "snapping.cli", "simulate", "--chi", "0.3", "--N", "400", "--method", "fast", "-o", str(p),
           "--no-progress", "--json"]
    a = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(0.3)
    b = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    res = [(x.wait(timeout=300), *x.communicate()) for x in (a, b)]
    codes = sorted(r[0] for r in res)
    assert codes == [0, 2], res
    loser = next(r for r in res if r[0] == 2)
    line = _one_line_error(loser[2])
    assert "being written by process PID" in line or "already exists" in line
    ds = load_run(p)
    assert ds.attrs["status"] == "completed" and float(ds.attrs["chi"]) == 0.3
    assert sorted(f.name for f in tmp_path.iterdir()) == ["run.nc"]


KILL_IN_CHECKPOINT = textwrap.dedent("""
    import os, signal, sys
    import xarray as xr
    from snapping.simulate import run
    real = xr.Dataset.to_netcdf
    calls = [0]
    def dying(self, path, **kw):
        calls[0] += 1
        if calls[0] == 3:  # the third checkpoint: half its temporary written, then SIGKILL
            with open(path, "wb") as fh:
                fh.write(b"CDF half a file")
            os.kill(os.getpid(), signal.SIGKILL)
        return real(self, path, **kw)
    xr.Dataset.to_netcdf = dying
    run(0.5, 40, method="fast", output=sys.argv[1], checkpoint_every=0)
""")


def test_sigkill_during_a_checkpoint_write(tmp_path):
    p = tmp_path / "run.nc"
    r = subprocess.run([PY, "-c", KILL_IN_CHECKPOINT, str(p)], capture_output=True, text=True, timeout=300)
    assert r.returncode == -signal.SIGKILL, r.stderr
    names = sorted(f.name for f in tmp_path.iterdir())
    assert "run.nc" in names and any(n.endswith(".part") for n in names)  # the last complete checkpoint
    ck = load_run(p)
    assert ck.attrs["status"] == "checkpoint"
    done = resume(p)
    assert sorted(f.name for f in tmp_path.iterdir()) == ["run.nc"]  # the stale temporary is gone
    ref = run(0.5, 40, method="fast").dataset
    for k in ("t", "v_max", "a_max", "sigma_max"):
        np.testing.assert_array_equal(done.dataset[k].values, ref[k].values)
    assert done.dataset.attrs["t_snap_v"] == ref.attrs["t_snap_v"]


# ------------------------------------------------------------------ checkpoints: integrity and resume options
@pytest.fixture
def checkpoint(tmp_path, monkeypatch):
    p = tmp_path / "ck.nc"
    calls = [0]

    def stop(eng):
        calls[0] += 1
        return int(signal.SIGINT) if calls[0] == 3 else None

    monkeypatch.setattr(driver, "_chunk_hook", stop)
    with pytest.raises(RunInterrupted):
        run(0.5, 30, method="fast", tol=1e-8, chords="arclength", output=p)  # (not the defaults: the edits and
    monkeypatch.setattr(driver, "_chunk_hook", None)                           # contradicting options change them)
    return p


def _edit(path, fn):
    with netCDF4.Dataset(path, "a") as nc:
        fn(nc)


@pytest.mark.parametrize("edit", ["chi_attr", "tol_attr", "state", "record", "digest_removed"])
def test_edited_checkpoint_is_refused(checkpoint, edit, capsys):
    before = _digest(checkpoint)
    if edit == "chi_attr":
        _edit(checkpoint, lambda nc: nc.setncattr("chi", 0.3))
    elif edit == "tol_attr":
        _edit(checkpoint, lambda nc: nc.setncattr("tol", 1e-6))
    elif edit == "state":
        def bump(nc):
            v = nc.variables["checkpoint_Y1"]
            a = v[:]
            a.flat[5] += 1e-12
            v[:] = a
        _edit(checkpoint, bump)
    elif edit == "record":
        def bump(nc):
            v = nc.variables["v_max"]
            v[2] = v[2] * (1 + 1e-9)
        _edit(checkpoint, bump)
    else:
        _edit(checkpoint, lambda nc: nc.delncattr(schema.DIGEST_ATTR))
    assert _digest(checkpoint) != before
    edited = _digest(checkpoint)
    with pytest.raises(SnappingInputError, match="integrity"):
        resume(checkpoint)
    status, _, err = _cli(["simulate", "--resume", checkpoint], capsys)
    assert status == 2 and "integrity" in _one_line_error(err)
    assert _digest(checkpoint) == edited  # refused, not touched


def test_intact_checkpoint_resumes(checkpoint):
    assert load_run(checkpoint).attrs[schema.DIGEST_ATTR]
    assert resume(checkpoint).dataset.attrs["status"] == "completed"


@pytest.mark.parametrize("argv, option", [
    (["--chi", "0.4"], "--chi"),
    (["--N", "31"], "--N"),
    (["--method", "euler-richardson"], "--method"),
    (["--tol", "1e-6"], "--tol"),
    (["--t-end", "0.5"], "--t-end"),
    (["--stop-fraction", "0.3"], "--stop-fraction"),
    (["--snapshot-times", "0.1"], "--snapshot-times"),
    (["--chords", "exact"], "--chords"),
    (["--taper", "0.2"], "--taper"),
    (["--tip-mass", "0.1"], "--tip-mass"),
    (["--gravity", "2"], "--gravity"),
    (["--pin-motion", "pull:1,0"], "--pin-motion"),
])
def test_resume_options_that_contradict_the_checkpoint_are_refused(checkpoint, argv, option, capsys):
    before = _digest(checkpoint)
    status, _, err = _cli(["simulate", "--resume", checkpoint, *argv], capsys)
    line = _one_line_error(err)
    assert status == 2 and option in line and ("--resume" in line or "checkpoint" in line), line
    keyword = "--" + option[2:].replace("-", "_")
    assert keyword == option or keyword not in line  # the option as typed, not as a keyword (--t_end)
    assert _digest(checkpoint) == before


def test_resume_options_that_agree_are_accepted(checkpoint, capsys):
    status, _, err = _cli(["simulate", "--resume", checkpoint, "--chi", "0.5", "--N", "30", "--method", "fast",
                           "--no-progress", "--json"], capsys)
    assert status == 0, err
    assert load_run(checkpoint).attrs["status"] == "completed"


def test_resume_to_an_existing_other_file_needs_overwrite(checkpoint, tmp_path):
    other = tmp_path / "other.nc"
    other.write_bytes(b"precious")
    with pytest.raises(SnappingInputError, match="already exists"):
        resume(checkpoint, output=other)
    assert other.read_bytes() == b"precious"
    assert resume(checkpoint, output=other, overwrite=True).dataset.attrs["status"] == "completed"


# ------------------------------------------------------------------ sweeps: one writer per directory, no swapped sweep.nc
def test_a_second_sweep_in_the_same_directory_is_refused(tmp_path):
    from snapping import sweep

    holder = subprocess.Popen([PY, "-c", HOLD, str(tmp_path / "sweep.nc")], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(_files.OutputBusyError, match=f"PID {holder.pid}"):
            sweep.run_sweep(sweep.Grid(chi=[0.5], N=[6]), tmp_path, workers=1, progress=False)
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
    assert [f.name for f in tmp_path.iterdir() if f.suffix == ".nc"] == []


def test_sweep_nc_of_another_grid_is_not_replaced(tmp_path, capsys):
    base = ["sweep", "--N", "6", "--method", "fast", "--workers", "1", "-o", tmp_path]
    status, _, err = _cli([*base, "--chi", "0.5"], capsys)
    assert status == 0, err
    first = _digest(tmp_path / "sweep.nc")
    status, _, err = _cli([*base, "--chi", "0.4"], capsys)
    assert status == 2 and "another grid" in _one_line_error(err) and "chi=[0.5]" in err
    assert _digest(tmp_path / "sweep.nc") == first
    status, _, err = _cli([*base, "--chi", "0.5"], capsys)  # the same grid again: its own file, updated
    assert status == 0, err
    status, _, err = _cli([*base, "--chi", "0.4", "--overwrite"], capsys)
    assert status == 0, err
    import xarray as xr

    with xr.open_dataset(tmp_path / "sweep.nc") as ds:
        assert list(ds["chi"].values) == [0.4]
