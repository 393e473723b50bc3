"""Checkpoints of an extensible-line run (:func:`snapping.simulate.elastic.solve`, methods
``"rodas4"`` and ``"rodas4-links"``): the file an interrupted or checkpointed run writes and
``solve(problem, elastic, ..., resume=path)`` continues, bit for bit.

A checkpoint is the run's Dataset so far (:mod:`snapping.simulate.elastic_dataset`: the record,
the snapshots so far with the running peak's state and the current one; ``status``
'checkpoint' or 'interrupted'), plus the arrays of :meth:`elastic_advance.RodasRun.state`
and the snapshots' states as ``ckpt_`` variables (:data:`snapping.schema.ELASTIC_CHECKPOINT_VARS`),
sealed with the rigid runs' integrity digest (:func:`snapping.simulate.dataset.seal`; read back
through :func:`snapping.simulate.dataset.verify_digest`). The inputs the run's numbers depend on
are stored as JSON (``checkpoint_inputs``); resuming needs the same problem and elastic objects
and options, and refuses others by name (:class:`CheckpointMismatch`).

The checkpoint a run writes, and the file it resumes, are locked while the run lasts
(:func:`held`: :func:`snapping._files.locked`, the rigid runs' lock): a second process
resuming or writing the same file is refused, naming the holder's PID. :class:`Poller` is
what the run does between returns of its compiled loop: a due checkpoint, or a noted signal
(saved, then :class:`~snapping.simulate.errors.RunInterrupted`).
"""

from __future__ import annotations

import contextlib
import json
import os
import time

import numpy as np

from .. import _files
from .. import _validate as V
from .dataset import check_writable, save, seal, verify_digest
from .elastic_dataset import dataset as _dataset
from .errors import RunInterrupted, deliver_late
from ._netcdf import open_netcdf

__all__ = ["VERSION", "PREFIX", "METHODS", "write", "read", "state_vars", "check_paths", "held", "Poller",
           "CheckpointMismatch", "Signals"]

#: the elastic methods that keep checkpoints (their compiled loops)
METHODS = ("rodas4", "rodas4-links")


class CheckpointMismatch(V.SnappingInputError):
    """A resumed checkpoint whose stored input ``key`` (``stored``) differs from the call's (``given``)."""

    def __init__(self, message: str, key: str, stored, given, path: str):
        super().__init__(message)
        self.key, self.stored, self.given, self.path = key, stored, given, path


def check_paths(checkpoint, resume):
    """The checkpoint to write (a symbolic link's target) and the file to resume, checked: the
    resumed file exists; the checkpoint is a new path or the resumed file itself (a checkpoint
    is never replaced by another run: SnappingInputError naming it). Returns (checkpoint, resume)."""
    if resume is not None:
        resume = _files.check_input(resume, name="resume")
    if checkpoint is None:
        return None, resume
    own = resume is not None and os.path.realpath(os.fspath(checkpoint)) == os.path.realpath(resume)
    p = check_writable(checkpoint, name="checkpoint", overwrite=True)
    if not own and os.path.exists(p):
        raise V.SnappingInputError(f"checkpoint={str(checkpoint)!r} already exists: a checkpoint is never replaced by "
                                   f"another run; pass resume={str(checkpoint)!r} to continue the run it holds, or "
                                   f"choose another path")
    return p, resume


@contextlib.contextmanager
def held(checkpoint, resume):
    """Hold the locks of ``checkpoint`` and of ``resume`` (either may be None) while a run writes
    and continues them, and check the paths again under them (another process may have made the
    checkpoint since). A file another process holds: :class:`snapping._files.OutputBusyError`."""
    with contextlib.ExitStack() as stack:
        for p, name in ((checkpoint, "checkpoint"), (resume, "resume")):
            if p is not None:
                stack.enter_context(_files.locked(p, name=name))
        check_paths(checkpoint, resume)
        yield

#: layout version of the ``ckpt_`` variables (2: the record's kappa_max, s_kappa_max columns; 3, branch
#: stretchapp: its kappa_max_interior column; an older checkpoint is refused by name)
VERSION = 3
PREFIX = "ckpt_"


def state_vars(state: dict) -> dict:
    """{``ckpt_`` name: (dims, values)} of a run's state arrays (booleans as int8: netCDF)."""
    out = {}
    for k, v in state.items():
        a = np.asarray(v)
        if a.dtype == np.bool_:
            a = a.astype(np.int8)
        out[PREFIX + k] = (tuple(f"{PREFIX}{k}_{i}" for i in range(a.ndim)), a)
    return out


def write(path, base, state: dict, snap_t, snap_z, snap_kind, key: dict, wall: float, n_restep: int = 0):
    """Save the checkpoint: the Dataset ``base`` of the run so far with the run's ``state``
    arrays, the snapshots so far and the inputs ``key``; sealed. Returns (dataset, path)."""
    ds = base.assign(state_vars(state))
    n = len(snap_t)
    ds = ds.assign({f"{PREFIX}snap_t": ((f"{PREFIX}snap",), np.asarray(snap_t, dtype=float)),
                    f"{PREFIX}snap_z": ((f"{PREFIX}snap", f"{PREFIX}snap_z_1"), np.asarray(snap_z, dtype=float)
                                        .reshape(n, -1)),
                    f"{PREFIX}snap_kind": ((f"{PREFIX}snap",), np.asarray(snap_kind).astype(str))})
    ds.attrs.update({"checkpoint_version": VERSION, "checkpoint_wall_time": float(wall),
                     "checkpoint_n_restep": int(n_restep),
                     "checkpoint_inputs": json.dumps(key, sort_keys=True)})
    seal(ds)
    return ds, (save(ds, path, overwrite=True) if path is not None else None)


def read(path, key: dict, names) -> dict:
    """The checkpoint at ``path`` for the run whose inputs are ``key`` and whose state arrays are
    ``names``: {"state", "times", "rows" (record without t), "snap_t", "snap_z", "snap_kind",
    "wall", "n_restep"}. SnappingInputError (naming the file) for a file that is not such a checkpoint, whose
    digest fails, or whose inputs differ from ``key``."""
    from .. import schema
    from .elastic_dataset import STEP_NAMES

    ds = open_netcdf(path)
    what = f"resume={str(path)!r}"
    status = str(ds.attrs.get("status", ""))
    if status not in schema.RESUMABLE_STATUS:
        raise V.SnappingInputError(f"{what} is not an extensible-line checkpoint (status={status!r}; expected one "
                                   f"of {schema.RESUMABLE_STATUS})")
    ver = ds.attrs.get("checkpoint_version")
    if ver != VERSION or "checkpoint_inputs" not in ds.attrs:
        ver = int(ver) if isinstance(ver, (int, np.integer)) else ver  # (netCDF's np.int64 named as a plain number)
        raise V.SnappingInputError(f"{what} is not an extensible-line checkpoint of this version (checkpoint_version="
                                   f"{ver!r}, expected {VERSION})")
    verify_digest(ds, what)
    stored = json.loads(str(ds.attrs["checkpoint_inputs"]))
    given = json.loads(json.dumps(key, sort_keys=True))
    for k in sorted(set(stored) | set(given)):
        if stored.get(k) != given.get(k):
            raise CheckpointMismatch(f"{what}: the run stored there has {k}={stored.get(k)!r}, this call "
                                     f"{k}={given.get(k)!r}: a resumed run continues the stored run with the same "
                                     f"problem, elastic and options", k, stored.get(k), given.get(k), str(path))
    missing = [PREFIX + k for k in names if PREFIX + k not in ds.variables]
    if missing:
        raise V.SnappingInputError(f"{what} is not a complete checkpoint: missing {missing[:5]}")
    return {"state": {k: ds[PREFIX + k].values for k in names},
            "times": ds["t"].values.astype(float),
            "rows": np.stack([ds[k].values.astype(float) for k in STEP_NAMES], axis=1),
            "snap_t": [float(x) for x in ds[f"{PREFIX}snap_t"].values],
            "snap_z": [z.copy() for z in ds[f"{PREFIX}snap_z"].values.astype(float)],
            "snap_kind": [str(x) for x in ds[f"{PREFIX}snap_kind"].values],
            "wall": float(ds.attrs["checkpoint_wall_time"]), "n_restep": int(ds.attrs["checkpoint_n_restep"])}


#: test hook: called with the run after every return of the compiled loop of a checkpointed
#: run; may return a signal number to act as if that signal had arrived (driver._chunk_hook's)
_chunk_hook = None


class Signals:
    """SIGINT and SIGTERM noted (``signum``) instead of raised while a checkpointed run steps,
    as :func:`snapping.simulate.driver._drive_locked` does; the handlers are put back on exit, and
    a signal noted that nothing acted on (the block ended without an exception) is raised then
    (:func:`~snapping.simulate.errors.deliver_late`)."""

    def __init__(self):
        self.signum, self.handlers = None, {}

    def __enter__(self):
        import signal
        import threading

        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                try:
                    self.handlers[sig] = signal.signal(sig, self._on)
                except (ValueError, OSError):  # pragma: no cover - exotic embedding
                    pass
        return self

    def _on(self, signum, frame):
        self.signum = signum

    def poll(self, run):
        """The signal to stop for (None: go on), the test hook asked first."""
        if _chunk_hook is not None:
            r = _chunk_hook(run)
            if r:
                self.signum = int(r)
        return self.signum

    def __exit__(self, exc_type, exc, tb):
        import signal

        for sig, h in self.handlers.items():
            signal.signal(sig, h)
        if exc_type is None and self.signum is not None:  # noted and not acted on (after the last poll): now
            deliver_late(self.signum)
        return False


class Poller:
    """``poll(run, chunks)`` of a checkpointed run's compiled loop (:func:`elastic_solve._run_rodas`),
    called after each of its returns at a step boundary: saves a checkpoint (status 'checkpoint')
    when ``every`` seconds of wall time have passed since the last (None: never), or, once
    ``sigs`` (:class:`Signals`) noted a signal, saves the run so far (status 'interrupted') and
    raises :class:`RunInterrupted`.

    ``rows``, ``times`` (the record before this session's chunks), the snapshot lists, the
    running peak's ``peak_state`` and ``n_restep`` (a one-element list) are the run's own
    objects, read when a checkpoint is taken; ``key`` the inputs stored with it."""

    def __init__(self, sigs, every, path, key, *, solver, line, inputs, rows, times, snaps, peak_state, n_restep,
                 wall_before, wall0):
        self.sigs, self.every, self.path, self.key = sigs, every, path, key
        self.solver, self.line, self.inputs, self.rows, self.times = solver, line, inputs, rows, times
        self.snap_t, self.snap_z, self.snap_kind = snaps
        self.peak_state, self.n_restep, self.wall_before, self.wall0 = peak_state, n_restep, wall_before, wall0
        self.last = time.monotonic()

    def __call__(self, run, chunks):
        from . import elastic_advance as EA

        signum = self.sigs.poll(run)
        if signum is None and (self.every is None or time.monotonic() - self.last < self.every):
            return
        solver = self.solver
        t = float(solver.t)
        rec = np.concatenate([np.asarray(self.rows, dtype=float)] + [c[:, 1:] for c in chunks])
        tt = np.concatenate([np.asarray(self.times, dtype=float)] + [c[:, 0] for c in chunks])
        sc = run.sctl
        pk = (float(sc[EA.S_PEAKT]), run.peak_z.copy()) if sc[EA.S_RUN] > 0.0 else self.peak_state
        wall = self.wall_before + time.perf_counter() - self.wall0
        how = f"continue with solve(..., resume={self.path!r})"
        status = "checkpoint" if signum is None else "interrupted"
        reason = f"running; checkpoint at t={t:.9g}, step {len(tt) - 1}; if the run was killed, {how}" \
            if signum is None else f"interrupted by {signal_name(signum)} at t={t:.9g}, step {len(tt) - 1}; {how}"
        base = _dataset(self.line, tt, rec, self.snap_t + [pk[0], t], self.snap_z + [pk[1], solver.y.copy()],
                        self.snap_kind + ["peak", "final"], {**self.inputs, "status": status, "stop_reason": reason,
                                                             "t_final": t, "n_steps": len(tt) - 1, "wall_time": wall})
        ds, path = write(self.path, base, run.state(), self.snap_t, self.snap_z, self.snap_kind, self.key, wall,
                         self.n_restep[0])
        self.last = time.monotonic()
        if signum is not None:
            raise RunInterrupted(f"{reason} (saved in {path})", int(signum), dataset=ds, path=path)


def signal_name(signum) -> str:
    import signal

    try:
        return signal.Signals(signum).name
    except ValueError:
        return f"signal {signum}"
