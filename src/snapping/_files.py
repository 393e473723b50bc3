"""Files users can trust: every file snapping writes, and every file it reads, goes through here.

The rules (the same for the Python API and the command line):

- **No silent overwrite.** An existing output is refused unless ``overwrite=True``
  (``--overwrite``) is given, or the caller is continuing that same run (a resume
  writes back into its checkpoint).
- **Only regular files.** An output that exists and is not a regular file (a
  directory, a device such as ``/dev/null``, a FIFO, a socket) is refused; it is
  never replaced. A **symbolic link is written through**: the file it points to is
  the output (checked by the same rules) and the link itself stays a link.
- **The whole path is checked before the work starts**: the directory exists and
  takes a new file, and its filesystem has room for the estimated size.
- **One writer at a time.** While a run or a sweep writes an output it holds an
  exclusive lock (``fcntl.flock`` on a hidden ``.NAME.lock`` file next to it); a
  second writer gets a clear error naming the holder's PID. The lock is the
  kernel's: a killed process releases it, and its lock file is reused.
- **Atomic writes.** A file is written to a hidden temporary ``.NAME.*.part`` next to
  it, flushed to disk and renamed over the output: a reader, or a run killed
  while saving, never sees a half-written file. The temporary is removed on every
  exit path; ones left by a killed process are removed by the next writer that
  takes the lock.
- **I/O faults are named**: a full disk (ENOSPC, EDQUOT, EFBIG, or an HDF error
  with the filesystem full) raises :class:`OutputWriteError` saying so; the
  previous file, if any, is untouched.

>>> import os, tempfile
>>> d = tempfile.mkdtemp()
>>> p = check_output(os.path.join(d, "run.nc"))           # a new path: fine
>>> _ = open(p, "w").write("x")
>>> check_output(p)
Traceback (most recent call last):
...
snapping._validate.SnappingInputError: output='...run.nc' already exists (a regular file of 1 B): pass overwrite=True (--overwrite) to replace it, or choose another path
>>> check_output(p, overwrite=True) == p
True
>>> check_output("/dev/null", overwrite=True)
Traceback (most recent call last):
...
snapping._validate.SnappingInputError: output='/dev/null' is a character device, not a regular file: it is never replaced; choose a file path
"""

from __future__ import annotations

import contextlib
import errno
import glob
import os
import shutil
import stat
import tempfile
import threading

from . import _validate as V

__all__ = ["check_output", "check_output_dir", "output_dir", "check_own_files", "is_foreign_netcdf",
           "check_input", "locked", "write_atomic", "save_figure", "OutputWriteError",
           "OutputBusyError", "lock_path", "describe_kind", "figure_format", "netcdf_suffix", "NETCDF_SUFFIXES"]

#: bytes a write may leave free on the filesystem before it counts as full
FULL_MARGIN = 1 << 20


class OutputWriteError(OSError):
    """An I/O fault while writing an output (a full disk, named as such): exit status 1.

    ``dataset`` is the result that could not be written, when there is one."""

    def __init__(self, message: str, *, path: str | None = None, dataset=None):
        super().__init__(message)
        self.path = path
        self.dataset = dataset

    def __str__(self) -> str:
        return str(self.args[0])


class OutputBusyError(V.SnappingInputError):
    """The output is locked by another process that is writing it."""


def describe_kind(mode: int) -> str:
    """What a file of ``st_mode`` is, in words (``'a character device'``)."""
    for test, words in ((stat.S_ISREG, "a regular file"), (stat.S_ISDIR, "a directory"),
                        (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                        (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return words
    return "not a regular file"


def _size(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if abs(n) < 1000 or unit == "TB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.3g} {unit}"
        n /= 1000.0
    return f"{n:.3g} TB"  # pragma: no cover


def _target(name: str, path) -> str:
    """The path that is written for ``path``: itself, or the file a symbolic link points to."""
    p = V.file_path(name, path)
    if os.path.islink(p):
        return os.path.realpath(p)
    return p


def check_output(path, *, name: str = "output", overwrite: bool = False, need_bytes: float = 0.0) -> str:
    """The path to write for output ``path``, checked before any work; or
    :class:`SnappingInputError` saying why it cannot be written.

    Parameters
    ----------
    path : path
        The output file. A symbolic link is written through (its target is returned).
    name : str
        The parameter's name in messages (``'output'``, ``'plot'``).
    overwrite : bool
        Allow replacing an existing regular file.
    need_bytes : float
        The estimated size of what will be written: refused when the filesystem has
        less free space than that.
    """
    if not isinstance(overwrite, bool):
        raise V.SnappingInputError(f"overwrite={overwrite!r} must be True or False")
    given = V.file_path(name, path)
    p = _target(name, given)
    via = f" (the target of the symbolic link {given!r})" if p != given else ""
    if p.endswith(os.sep) or os.path.basename(p) in ("", ".", ".."):
        raise V.SnappingInputError(f"{name}={given!r} names a directory, not a file path")
    parent = os.path.dirname(os.path.abspath(p))
    if not os.path.isdir(parent):
        what = "is not a directory" if os.path.exists(parent) else "does not exist"
        raise V.SnappingInputError(f"{name}={given!r}{via}: directory {parent!r} {what}")
    try:
        parent.encode("utf-8")
    except UnicodeEncodeError:  # (checked before the work: the file is written in this directory)
        raise V.SnappingInputError(f"{name}={given!r}{via}: directory {parent!r} has a name that is not valid "
                                   f"UTF-8: files cannot be written there (netCDF takes UTF-8 paths)") from None
    if len(os.fsencode(os.path.basename(p))) > 255:
        raise V.SnappingInputError(f"{name}={given!r}: the file name is {len(os.fsencode(os.path.basename(p)))} "
                                   f"bytes long; at most 255")
    try:
        st = os.stat(p)
    except FileNotFoundError:
        st = None
    except OSError as exc:
        raise V.SnappingInputError(f"{name}={given!r}{via} cannot be examined ({exc.strerror or exc})") from None
    if st is not None:
        if not stat.S_ISREG(st.st_mode):
            raise V.SnappingInputError(f"{name}={given!r}{via} is {describe_kind(st.st_mode)}, not a regular file: "
                                       f"it is never replaced; choose a file path")
        if not overwrite:
            raise V.SnappingInputError(f"{name}={given!r}{via} already exists (a regular file of {_size(st.st_size)}): "
                                       f"pass overwrite=True (--overwrite) to replace it, or choose another path")
        if not os.access(p, os.W_OK):
            raise V.SnappingInputError(f"{name}={given!r}{via} is not writable (permission denied)")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise V.SnappingInputError(f"{name}={given!r}{via}: directory {parent!r} is not writable (permission denied)")
    try:  # the file is written next to itself and renamed: the directory must take a new file
        fd, probe = tempfile.mkstemp(prefix=f"{_side(p)}.", suffix=".probe", dir=parent)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise V.SnappingInputError(f"{name}={given!r}{via}: directory {parent!r} does not take a new file "
                                   f"({exc.strerror or exc})") from None
    if need_bytes and need_bytes > 0:
        free = shutil.disk_usage(parent).free
        if free < need_bytes + FULL_MARGIN:
            raise V.SnappingInputError(f"{name}={given!r}{via}: the file needs about {_size(need_bytes)} but the "
                                       f"filesystem of {parent!r} has only {_size(free)} free")
    return p


def check_input(path, *, name: str = "path") -> str:
    """``path`` as a string if it is an existing regular file that can be read (a
    symbolic link to one is fine); else :class:`SnappingInputError` saying why. A FIFO
    or a device is refused before anything opens it (opening a FIFO would block)."""
    p = V.file_path(name, path)
    try:
        st = os.stat(p)
    except FileNotFoundError:
        raise V.SnappingInputError(f"{name}={p!r} does not exist") from None
    except OSError as exc:
        raise V.SnappingInputError(f"{name}={p!r} cannot be examined ({exc.strerror or exc})") from None
    if not stat.S_ISREG(st.st_mode):
        raise V.SnappingInputError(f"{name}={p!r} is {describe_kind(st.st_mode)}, not a regular file")
    if not os.access(p, os.R_OK):
        raise V.SnappingInputError(f"{name}={p!r} is not readable (permission denied)")
    return p


def check_output_dir(path, *, name: str = "output") -> str:
    """Output directory ``path`` (made, with its parents, if missing) that takes new files;
    else :class:`SnappingInputError` saying why (a file, device or FIFO in the way, a
    read-only filesystem, no permission)."""
    p = V.file_path(name, path)
    try:
        st = os.stat(p)
    except FileNotFoundError:
        st = None
    except NotADirectoryError:
        raise V.SnappingInputError(f"{name}={p!r}: the directory cannot be written (a part of its path is a file, "
                                   f"not a directory)") from None
    except OSError as exc:
        raise V.SnappingInputError(f"{name}={p!r} cannot be examined ({exc.strerror or exc})") from None
    if st is not None and not stat.S_ISDIR(st.st_mode):
        raise V.SnappingInputError(f"{name}={p!r} exists and is {describe_kind(st.st_mode)}, not a directory")
    try:
        os.makedirs(p, exist_ok=True)
        fd, probe = tempfile.mkstemp(prefix=".write-test-", suffix=".probe", dir=p)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise V.SnappingInputError(f"{name}={p!r}: the directory cannot be written ({exc.strerror or exc})") from None
    return p


@contextlib.contextmanager
def output_dir(path, *, name: str = "output"):
    """:func:`check_output_dir` for the duration of a piece of work: the directories it makes are
    removed again (when still empty) if the work is refused or fails, so that a refused sweep or
    convergence study leaves nothing behind (no new empty ``-o`` directory)."""
    p = V.file_path(name, path)
    made, d = [], os.path.abspath(p)
    while not os.path.lexists(d) and d != os.path.dirname(d):
        made.append(d)
        d = os.path.dirname(d)
    out = check_output_dir(p, name=name)
    try:
        yield out
    except BaseException:
        for d in made:  # deepest first
            try:
                os.rmdir(d)
            except OSError:
                break
        raise


def is_foreign_netcdf(path) -> bool:
    """Whether ``path`` is a readable netCDF file that snapping did not write (none of the global
    attributes of a run, a combined sweep or a convergence study). An unreadable file (a run
    whose worker died while writing it) is not foreign: its own writer may replace it."""
    try:
        import netCDF4

        with netCDF4.Dataset(path) as nc:
            names = set(nc.ncattrs())
    except Exception:  # noqa: BLE001 - not a readable netCDF file
        return False
    ours = ("status" in names and "snapping_version" in names) or "sweep_grid" in names or \
        ("grading" in names and "ratio" in names)
    return not ours


def check_own_files(paths, *, name: str = "output", overwrite: bool = False) -> None:
    """Refuse, before any work, to replace a file at any of ``paths`` (the files a sweep or a
    convergence study writes into its directory) that is another program's netCDF file
    (:func:`is_foreign_netcdf`): it is never replaced without ``overwrite``."""
    for path in paths:
        p = os.fspath(path)
        if not os.path.lexists(p):
            continue
        check_output(p, name=name, overwrite=True)  # a regular file (not a directory, device, ...)
        if not overwrite and is_foreign_netcdf(p):
            raise V.SnappingInputError(f"{name}={p!r} exists and is another program's netCDF file (not a snapping "
                                       f"run): it is not replaced; move it away, or pass overwrite=True "
                                       f"(--overwrite) to replace it")


# ------------------------------------------------------------------------------- locks
#: longest base name (bytes) whose side files (lock, temporary, probe) are named after it in full
_SIDE_NAME_MAX = 200


def _side(path) -> str:
    """The stem of the hidden side files of output ``path`` (lock, temporary, probe): ``.NAME``; for a
    name too long to take their suffixes (any valid name, up to 255 bytes, is accepted) or one that is
    not UTF-8 (netCDF writes only UTF-8 paths), a shortened UTF-8 name and a hash of the full one."""
    base = os.path.basename(os.path.abspath(os.fspath(path)))
    raw = os.fsencode(base)
    try:
        base.encode("utf-8")
        ok = len(raw) <= _SIDE_NAME_MAX
    except UnicodeEncodeError:
        ok = False
    if ok:
        return f".{base}"
    import hashlib

    short = raw[:120].decode("utf-8", errors="ignore").encode("ascii", errors="ignore").decode()
    return f".{short}~{hashlib.sha1(raw).hexdigest()[:16]}"


def lock_path(path: str) -> str:
    """The lock file of output ``path``: ``.NAME.lock`` in the same directory (:func:`_side`)."""
    d = os.path.dirname(os.path.abspath(path))
    return os.path.join(d, f"{_side(path)}.lock")


_held: dict[str, list] = {}  # realpath of the output -> [fd, depth, thread] (locks held by this process)
_held_guard = threading.Lock()


def _remove_stale_parts(path: str) -> None:
    d, stem = os.path.dirname(os.path.abspath(path)), _side(path)
    for part in glob.glob(os.path.join(glob.escape(d), f"{glob.escape(stem)}.*.part")) + \
            glob.glob(os.path.join(glob.escape(d), f"{glob.escape(stem)}.*.probe")):
        with contextlib.suppress(OSError):
            os.unlink(part)


def _acquire(path: str, name: str) -> int:
    lp = lock_path(path)
    for _ in range(20):  # the lock file may be unlinked by its holder between our open and flock
        import fcntl

        try:
            fd = os.open(lp, os.O_RDWR | os.O_CREAT | getattr(os, "O_CLOEXEC", 0), 0o644)
        except OSError as exc:
            raise V.SnappingInputError(f"{name}={path!r}: its lock file {lp!r} cannot be created "
                                       f"({exc.strerror or exc})") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            holder = ""
            with contextlib.suppress(OSError, ValueError):
                holder = os.pread(fd, 64, 0).decode().strip()
            os.close(fd)
            if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                who = f"process PID {holder}" if holder.isdigit() else "another process"
                raise OutputBusyError(f"{name}={path!r} is being written by {who} (it holds the lock {lp!r}): "
                                      f"wait for it to finish, or choose another path") from None
            raise V.SnappingInputError(f"{name}={path!r}: its lock file {lp!r} cannot be locked "
                                       f"({exc.strerror or exc})") from None
        try:
            same = os.fstat(fd).st_ino == os.stat(lp).st_ino
        except FileNotFoundError:
            same = False
        if not same:  # we locked a lock file its holder had just removed: try again
            os.close(fd)
            continue
        with contextlib.suppress(OSError):  # (a full disk: the lock holds, only its PID is not shown)
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        return fd
    raise V.SnappingInputError(f"{name}={path!r}: its lock file {lp!r} keeps changing")  # pragma: no cover


@contextlib.contextmanager
def locked(path, *, name: str = "output"):
    """Hold the exclusive lock of output ``path`` (re-entrant in the thread that holds it; another
    thread of this process, like another process, gets :class:`OutputBusyError`).

    On taking it, temporary ``.NAME.*.part`` files that a killed writer left are removed.
    A second process gets :class:`OutputBusyError` naming the holder's PID.

    >>> import os, tempfile
    >>> p = os.path.join(tempfile.mkdtemp(), "run.nc")
    >>> with locked(p):
    ...     os.path.exists(lock_path(p))
    True
    >>> os.path.exists(lock_path(p))
    False
    """
    p = os.path.realpath(_target(name, path))
    with _held_guard:
        entry = _held.get(p)
        if entry is not None and entry[2] != threading.get_ident():  # (flock is per process: threads checked here)
            raise OutputBusyError(f"{name}={os.fspath(path)!r} is being written by another thread of this process "
                                  f"(PID {os.getpid()}): wait for it to finish, or choose another path")
        if entry is not None:
            entry[1] += 1
        else:
            _held[p] = [_acquire(p, name), 1, threading.get_ident()]
            _remove_stale_parts(p)
    try:
        yield p
    finally:
        with _held_guard:
            entry = _held[p]
            entry[1] -= 1
            if entry[1] == 0:
                del _held[p]
                with contextlib.suppress(OSError):
                    os.unlink(lock_path(p))  # still holding the lock: nobody else can have it
                os.close(entry[0])


# ------------------------------------------------------------------------------- writing
def _disk_full(exc: BaseException, directory: str) -> bool:
    if getattr(exc, "errno", None) in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG):
        return True
    if isinstance(exc, (OSError, RuntimeError)):  # netCDF4/HDF5 report a full disk as "HDF error"
        with contextlib.suppress(OSError):
            return shutil.disk_usage(directory).free < FULL_MARGIN
    return False


def write_atomic(path, write, *, name: str = "output", overwrite: bool = True, dataset=None) -> str:
    """Write output ``path`` atomically with ``write(tmp_path)``; returns the path written.

    The output is checked (:func:`check_output`, with ``overwrite``) and locked, ``write``
    fills a temporary file next to it, which is flushed and renamed over the output,
    keeping the permissions of the file it replaces (a new file gets 0666 less the
    umask). On any failure the temporary is removed and the previous file is untouched;
    a full disk raises :class:`OutputWriteError` saying so (carrying ``dataset``).
    """
    try:
        p = check_output(path, name=name, overwrite=overwrite)
    except V.SnappingInputError as exc:
        held = os.path.realpath(_target(name, path)) in _held
        if not held:
            raise
        # the output was checked before the work and is locked since: what changed (a directory made
        # read-only, a file put in the way) is an I/O fault, not bad input
        raise OutputWriteError(f"writing {name}={os.fspath(path)!r} failed: {exc}; nothing was replaced",
                               path=os.fspath(path), dataset=dataset) from None
    d = os.path.dirname(os.path.abspath(p))
    with locked(p, name=name):
        fd, tmp = tempfile.mkstemp(prefix=f"{_side(p)}.", suffix=".part", dir=d)
        os.close(fd)
        try:
            write(tmp)
            with open(tmp, "rb+") as fh:
                os.fsync(fh.fileno())
            if os.path.exists(p):
                os.chmod(tmp, os.stat(p).st_mode & 0o7777)
            else:
                umask = os.umask(0)
                os.umask(umask)
                os.chmod(tmp, 0o666 & ~umask)
            os.replace(tmp, p)
        except BaseException as exc:
            full = _disk_full(exc, d)
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            if full:
                raise OutputWriteError(f"writing {name}={p!r} failed: the disk is full (no space left on the "
                                       f"filesystem of {d!r}); nothing was replaced", path=p,
                                       dataset=dataset) from None
            if isinstance(exc, (V.SnappingInputError, OutputWriteError)) or not isinstance(exc, Exception):
                raise
            why = getattr(exc, "strerror", None) or (str(exc).strip().splitlines() or [""])[0][:160]
            raise OutputWriteError(f"writing {name}={p!r} failed ({type(exc).__name__}: {why}); nothing was "
                                   f"replaced", path=p, dataset=dataset) from None
    return p


def figure_format(path, *, name: str = "plot") -> str:
    """The image format of a figure file, from its suffix; refused (naming ``name``, the path and
    the formats) when it has none or matplotlib cannot write it. Checked before the work.

    >>> figure_format("fit.png")
    'png'
    """
    from matplotlib.backend_bases import FigureCanvasBase

    formats = FigureCanvasBase.get_supported_filetypes()
    fmt = os.path.splitext(os.fspath(path))[1].lstrip(".").lower()
    if fmt not in formats:
        what = "has no suffix" if not fmt else f"has the suffix .{fmt}, which is not an image format matplotlib writes"
        raise V.SnappingInputError(f"{name}={os.fspath(path)!r} {what}: give a file name ending in one of "
                                   f"{', '.join('.' + f for f in sorted(formats))}")
    return fmt


#: the suffixes a netCDF file that a command writes may end in (a run, a regime study, the table)
NETCDF_SUFFIXES = (".nc", ".nc4", ".netcdf")


def netcdf_suffix(path, *, name: str = "output") -> str:
    """``path`` of a netCDF output, refused (naming ``name``, the path and
    :data:`NETCDF_SUFFIXES`) when its suffix is not a netCDF file's: a command never writes
    netCDF under a name that says another format (``-o run.txt``). Checked before the work; a
    path that is there and is not a regular file is left to :func:`check_output`, which refuses
    it naming what it is (a directory, a device, a FIFO).

    >>> netcdf_suffix("run.nc")
    'run.nc'
    >>> netcdf_suffix("run.txt", name="--output")
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: --output='run.txt' has the suffix .txt, which is not a netCDF file's: the file is written as netCDF4; give a name ending in .nc, .nc4 or .netcdf
    """
    p = os.fspath(V.file_path(name, path))
    try:
        if not stat.S_ISREG(os.stat(p).st_mode):  # a directory, device, FIFO: check_output names what it is
            return p
    except OSError:  # (nothing there yet, or not reachable: check_output says why)
        pass
    suffix = os.path.splitext(p)[1]
    if suffix.lower() not in NETCDF_SUFFIXES:
        what = "has no suffix" if not suffix else f"has the suffix {suffix}, which is not a netCDF file's"
        raise V.SnappingInputError(f"{name}={p!r} {what}: the file is written as netCDF4; give a name ending in "
                                   f"{', '.join(NETCDF_SUFFIXES[:-1])} or {NETCDF_SUFFIXES[-1]}")
    return p


def save_figure(fig, path, *, overwrite: bool = True, **savefig_kw) -> str:
    """Write a matplotlib figure to ``path`` atomically (:func:`write_atomic`; the format
    from the suffix, :func:`figure_format`). Figures replace an existing file by default: the
    command line refuses one before the work unless ``--overwrite``."""
    fmt = figure_format(path)
    return write_atomic(path, lambda tmp: fig.savefig(tmp, format=fmt, **savefig_kw), name="plot",
                        overwrite=overwrite)
