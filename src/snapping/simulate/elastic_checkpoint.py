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
and options, and refuses others by name.
"""

from __future__ import annotations

import json

import numpy as np

from .. import _validate as V
from .dataset import save, seal, verify_digest
from ._netcdf import open_netcdf

__all__ = ["VERSION", "PREFIX", "write", "read", "state_vars"]

#: layout version of the ``ckpt_`` variables
VERSION = 1
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
    if ds.attrs.get("checkpoint_version") != VERSION or "checkpoint_inputs" not in ds.attrs:
        raise V.SnappingInputError(f"{what} is not an extensible-line checkpoint of this version (checkpoint_version="
                                   f"{ds.attrs.get('checkpoint_version')!r}, expected {VERSION})")
    verify_digest(ds, what)
    stored = json.loads(str(ds.attrs["checkpoint_inputs"]))
    given = json.loads(json.dumps(key, sort_keys=True))
    for k in sorted(set(stored) | set(given)):
        if stored.get(k) != given.get(k):
            raise V.SnappingInputError(f"{what}: the run stored there has {k}={stored.get(k)!r}, this call "
                                       f"{k}={given.get(k)!r}: a resumed run continues the stored run with the same "
                                       f"problem, elastic and options")
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
    as :func:`snapping.simulate.driver._drive_locked` does; the handlers are put back on exit."""

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

    def __exit__(self, *exc):
        import signal

        for sig, h in self.handlers.items():
            signal.signal(sig, h)
        return False


def signal_name(signum) -> str:
    import signal

    try:
        return signal.Signals(signum).name
    except ValueError:
        return f"signal {signum}"
