"""Every path option of the command line x every hostile kind of path.

Each case asserts the exit status, one line on stderr that names the input, no traceback,
no hang, and the untouched state of every file involved (kind, mode, size, content), and
that nothing new was left behind (no temporary, no lock file).
"""

import hashlib
import os
import signal
import stat
import subprocess

import pytest

from snapping.cli import main
from snapping.simulate import run

KINDS = ("missing_dir", "directory", "device", "fifo", "symlink_to_file", "existing_file", "readonly_dir",
         "full_disk", "empty")

# (name, argv template with {P} the hostile path and {RUN} a finished run file, role)
OPTIONS = [
    ("simulate -o", ["simulate", "--chi", "0.5", "--N", "6", "--t-end", "0.01", "-o", "{P}"], "output"),
    ("simulate -o (fast)", ["simulate", "--chi", "0.5", "--N", "6", "--t-end", "0.01", "--method", "fast",
                            "-o", "{P}"], "output"),
    ("simulate --resume", ["simulate", "--resume", "{P}"], "input"),
    ("simulate --resume -o", ["simulate", "--resume", "{CK}", "-o", "{P}"], "output"),
    ("simulate --shape", ["simulate", "--shape", "{P}", "--N", "6", "--method", "fast", "--t-end", "0.01"], "input"),
    ("fit FILE", ["fit", "{P}"], "input"),
    ("fit --plot", ["fit", "{RUN}", "--plot", "{P}"], "output"),
    ("sweep -o", ["sweep", "--chi", "0.5", "--N", "6", "--workers", "1", "-o", "{P}"], "dir"),
    ("converge -o", ["converge", "--chi", "0.25", "--levels", "2", "-o", "{P}"], "dir"),
    ("converge --plot", ["converge", "--chi", "0.25", "--levels", "2", "--plot", "{P}"], "output"),
    ("reproduce -o", ["reproduce", "--quick", "-o", "{P}"], "dir"),
    ("animate RUN", ["animate", "{P}", "-o", "anim.gif"], "input"),
    ("animate -o", ["animate", "{RUN}", "-o", "{P}"], "output"),
]


def _state(path):
    """What a path is, for the untouched check."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return None
    if stat.S_ISREG(st.st_mode):
        with open(path, "rb") as fh:
            return ("file", st.st_mode, st.st_size, hashlib.sha256(fh.read()).hexdigest())
    if stat.S_ISLNK(st.st_mode):
        return ("link", os.readlink(path))
    return ("other", st.st_mode)


def _tree(root):
    out = {}
    for d, dirs, files in os.walk(root):
        for n in dirs + files:
            p = os.path.join(d, n)
            out[os.path.relpath(p, root)] = _state(p)
    return out


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("inputs")
    p = d / "run.nc"
    run(0.5, 30, method="fast", output=p)  # to the snap: fit works on it
    from snapping.simulate import driver

    calls = [0]

    def stop(eng):
        calls[0] += 1
        return int(signal.SIGINT) if calls[0] == 2 else None

    driver._chunk_hook = stop
    ck = d / "ck.nc"
    try:
        run(0.5, 12, method="fast", output=ck)
    except KeyboardInterrupt:
        pass
    finally:
        driver._chunk_hook = None
    return p, ck


def _mount(path, opts):
    path.mkdir()
    if os.geteuid() != 0:
        return False
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", opts, "tmpfs", str(path)], capture_output=True)
    return r.returncode == 0


def _make(kind, tmp_path, suffix):
    """The hostile path of ``kind`` (and a cleanup), or None where this machine cannot make it."""
    name = f"target{suffix}"
    if kind == "missing_dir":
        return tmp_path / "no" / "such" / name, None
    if kind == "directory":
        (tmp_path / name).mkdir()
        return tmp_path / name, None
    if kind == "device":
        return "/dev/null", None
    if kind == "fifo":
        os.mkfifo(tmp_path / name)
        return tmp_path / name, None
    if kind == "symlink_to_file":
        (tmp_path / f"real{suffix}").write_bytes(b"precious data")
        (tmp_path / name).symlink_to(tmp_path / f"real{suffix}")
        return tmp_path / name, None
    if kind == "existing_file":
        (tmp_path / name).write_bytes(b"precious data")
        return tmp_path / name, None
    if kind == "empty":
        return "", None
    mnt = tmp_path / "mnt"
    if kind == "readonly_dir":
        if not _mount(mnt, "ro,size=1m"):
            return None, None
    elif kind == "full_disk":
        if not _mount(mnt, "size=64k"):
            return None, None
        with open(mnt / "filler", "wb") as fh:
            try:
                fh.write(b"\0" * (1 << 20))
            except OSError:
                pass
    return mnt / name, lambda: subprocess.run(["umount", "-l", str(mnt)], check=False)


def _expected(role, kind):
    """Exit statuses a case may end with: 2 (refused), 1 (an I/O fault named as such)."""
    if role == "dir" and kind == "missing_dir":
        return None  # a new directory is made (valid): not run here, it would start the work
    if role == "dir" and kind == "directory":
        return None  # an existing directory is the resumable place of a sweep/converge/reproduce
    if role == "input" and kind == "symlink_to_file":
        return {2}  # read through the link: the target is not a run file
    if kind == "full_disk":
        return {1, 2}
    return {2}


CASES = [(o, k) for o in OPTIONS for k in KINDS if _expected(o[2], k) is not None]


class _Hang(Exception):
    pass


def _alarm(signum, frame):
    raise _Hang()


@pytest.mark.parametrize("option, kind", CASES, ids=[f"{o[0]}-{k}" for o, k in CASES])
def test_path_option_hostile(option, kind, tmp_path, finished_run, capsys, monkeypatch):
    name, template, role = option
    monkeypatch.chdir(tmp_path)
    suffix = ".png" if "--plot" in name else ".gif" if name == "animate -o" else (".nc" if role != "dir" else "")
    P, cleanup = _make(kind, tmp_path, suffix)
    if P is None:
        pytest.skip(f"{kind}: this machine cannot mount a tmpfs")
    try:
        before = _tree(tmp_path)
        dev_before = _state("/dev/null")
        argv = [a.format(P=P, RUN=finished_run[0], CK=finished_run[1]) for a in template]
        old = signal.signal(signal.SIGALRM, _alarm)
        signal.alarm(60)
        try:
            status = main(argv)
        except SystemExit as exc:
            status = exc.code
        except _Hang:
            pytest.fail(f"{name} with a {kind} path hangs")
        finally:
            signal.alarm(0)
            signal.signal(signal.SIGALRM, old)
        _, err = capsys.readouterr()
        lines = err.strip().splitlines()
        assert status in _expected(role, kind), err
        assert len(lines) == 1 and "error" in lines[0] and "Traceback" not in err, err
        if kind != "empty":
            shown = os.path.basename(str(P)) or str(P)
            assert shown in lines[0] or str(P) in lines[0] or "directory" in lines[0], lines[0]
        after = _tree(tmp_path)
        if role == "dir":  # a directory it made on the way (empty) is no damage
            made = {k for k in set(after) - set(before) if after[k][0] == "other"
                    and not any(j.startswith(k + os.sep) and after[j][0] != "other" for j in after)}
            after = {k: v for k, v in after.items() if k not in made}
        assert after == before  # nothing replaced, nothing left behind
        assert _state("/dev/null") == dev_before and stat.S_ISCHR(os.stat("/dev/null").st_mode)
    finally:
        if cleanup:
            cleanup()


def test_catalogue_size():
    assert len(CASES) >= 80
