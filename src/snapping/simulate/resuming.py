"""Resuming a run from its checkpoint file: :func:`resume`, :func:`is_resumable`, and the
checks that a file is a checkpoint this version continues (:func:`_open_checkpoint`) and that
it is the run the caller expects (``expect``, :class:`ResumeMismatch`).

The checkpoint itself is written by the driver (:mod:`snapping.simulate.driver`, which also
runs the resumed engine to its end); this module only reads it back. It imports the driver,
never the other way round; the driver's names (``_drive``, ``_validate_start``,
``CHECKPOINT_VERSION``, ``METHODS``) are looked up on the driver module when used.
"""

from __future__ import annotations

import os

import numpy as np
import xarray as xr

from .. import _files
from .. import _validate as V
from . import driver as D
from . import methods as M
from .dataset import Run, check_writable, inputs_from_attrs, open_netcdf, verify_digest
from .options import RunOptions, check_checkpoint_every, check_memory, check_progress

__all__ = ["resume", "is_resumable", "ResumeMismatch"]


def _open_checkpoint(path) -> xr.Dataset:
    """Load a run file that :func:`resume` can continue, or raise SnappingInputError saying why not."""
    from .. import schema

    p = os.fspath(path) if isinstance(path, (str, os.PathLike)) else None
    if not p:
        raise V.SnappingInputError(f"path={path!r} is not a file path")
    ds = open_netcdf(p)
    status = str(ds.attrs.get("status", ""))
    if status not in schema.RESUMABLE_STATUS:
        if status in ("completed", "failed"):
            raise V.SnappingInputError(f"path={p!r} is a {status} run (status={status!r}): there is nothing to "
                                       f"resume, only runs with status in {schema.RESUMABLE_STATUS} continue")
        raise V.SnappingInputError(f"path={p!r} is not a snapping run checkpoint (status={status!r}; "
                                   f"expected one of {schema.RESUMABLE_STATUS})")
    ck_vars = M.method(str(ds.attrs.get("method", "euler-richardson"))).CHECKPOINT_VARS \
        if str(ds.attrs.get("method", "")) in D.METHODS else schema.CHECKPOINT_VARS
    missing = [k for k in (*ck_vars, schema.CHECKPOINT_KIND_VAR, *schema.STEP_VARS) if k not in ds.variables]
    missing += [k for k in (*schema.CHECKPOINT_ATTRS, "chi", "N", "method", "tol") if k not in ds.attrs]
    if missing:
        raise V.SnappingInputError(f"path={p!r} is not a complete checkpoint: missing {missing[:5]}")
    if int(ds.attrs["checkpoint_version"]) != D.CHECKPOINT_VERSION:
        raise V.SnappingInputError(f"path={p!r}: checkpoint version {ds.attrs['checkpoint_version']} (written by "
                                   f"another version of snapping) is not supported by this version (expects "
                                   f"{D.CHECKPOINT_VERSION}): start the run again")
    verify_digest(ds, f"path={p!r}")
    return ds


class ResumeMismatch(V.SnappingInputError):
    """An input given to :func:`resume` (``expect``) that differs from the checkpoint's run."""

    def __init__(self, key: str, given, stored, path: str, *, option: str | None = None):
        self.key, self.given, self.stored, self.path = key, given, stored, path
        name = option or key
        shown = f"{option} {given}" if option else f"{key}={given!r}"
        super().__init__(f"{shown} contradicts the checkpoint {path!r}, whose run has {key}={stored!r}: "
                         f"a resumed run continues the stored run; drop {name}, or start a new run")


#: run inputs a file stores only when not their default (``inputs_from_attrs`` leaves them out)
_UNSTORED_DEFAULTS = {"drag_jacobian": "banded"}


def _stored(kw: dict, k: str):
    """The stored run input ``k`` of ``kw`` (an unstored default: its default value)."""
    return kw.get(k, _UNSTORED_DEFAULTS.get(k))


def _mismatch(kw: dict, expected: dict) -> str | None:
    """The first key of ``expected`` whose value differs from the run inputs ``kw`` (None: all agree)."""
    for k, v in expected.items():
        if v is None or k in ("output", "progress", "checkpoint_every", "overwrite"):
            continue
        have = _stored(kw, k)
        if k == "method":  # files name the method it stands for
            v = M.resolve(v) if v in D.METHODS else v
        if k == "snapshot_times":
            try:
                if tuple(float(x) for x in np.atleast_1d(np.asarray(v, dtype=float))) != tuple(have or ()):
                    return k
            except (TypeError, ValueError):
                return k
        elif isinstance(v, float) or isinstance(have, float):
            try:
                if float(v) != float(have):
                    return k
            except (TypeError, ValueError):
                return k
        elif v != have:
            return k
    return None


def _check_start(fresh: np.ndarray, stored: np.ndarray, path: str) -> None:
    """The digest proves only that the file is as sealed: a file whose inputs were edited and
    sealed again would continue the stored state under the new inputs' name. The first recorded
    step of the stored run must be the start that its stored inputs give (``fresh``)."""
    if fresh.ndim != 2 or stored.ndim != 2 or not fresh.shape[0] or not stored.shape[0]:
        return
    a, b = fresh[0], stored[0]
    if a.shape != b.shape or not np.allclose(a, b, rtol=1e-9, atol=1e-12, equal_nan=True):
        raise V.SnappingInputError(f"path={path!r}: the inputs stored in the checkpoint (chi, N, chords, the "
                                   f"problem) do not give the start of its stored run (its first recorded step "
                                   f"differs): the file's attributes were changed after the run was written; "
                                   f"start the run again")


def is_resumable(path, **expected) -> bool:
    """True if ``path`` is a checkpoint :func:`resume` can continue and, for each keyword
    given (``chi``, ``N``, ``tol``, any input of :func:`run`), its input equals that value.

    >>> is_resumable("no/such/run.nc")
    False
    """
    try:
        ds = _open_checkpoint(path)
        kw = inputs_from_attrs(ds)
    except (V.SnappingInputError, KeyError, ValueError, TypeError):
        return False
    return _mismatch(kw, expected) is None


def resume(path, *, output=None, progress: bool | None = False,
           checkpoint_every: float | None = D.CHECKPOINT_EVERY, overwrite: bool = False,
           expect: dict | None = None) -> Run:
    """Continue an interrupted or checkpointed run file to its end.

    The run continues from the complete state stored in the file (positions and
    velocities of every node, t, dt, the stepper's counters, the record so far,
    the snapshots and the peak trackers; :data:`snapping.schema.CHECKPOINT_VARS`),
    and gives the same accepted steps and the same Dataset, bit for bit, as a run
    that was never interrupted (``wall_time`` aside: it adds up the sessions).

    The checkpoint's integrity digest (``schema.DIGEST_ATTR``, over every input
    and the whole state) is checked first: a file whose inputs (say its ``chi``) or
    state were edited, or that is corrupted, is refused. The file is locked while
    the run continues: a second writer is refused, naming this process.

    Parameters
    ----------
    path : path
        A run file with status 'checkpoint' or 'interrupted'.
    output : path, optional
        Where to write the run (default: ``path`` itself, replaced atomically).
    progress, checkpoint_every
        As for :func:`run`.
    overwrite : bool
        Replace ``output`` if it exists and is not ``path`` (default: refuse).
    expect : dict, optional
        Inputs of :func:`run` (``chi``, ``N``, ``method``, ``tol``, ...) the caller expects
        the checkpoint to have: one that differs is refused by name (a resumed run
        continues the stored run; it cannot change its inputs).

    Returns
    -------
    Run

    Raises
    ------
    SnappingInputError
        Not a readable run checkpoint (a completed or failed run, another
        program's file, a truncated, edited or corrupted file), an unwritable or
        existing ``output``, or a file that another process is writing.
    SimulationError, RunInterrupted
        As for :func:`run`.

    Examples
    --------
    >>> import os, tempfile
    >>> p = os.path.join(tempfile.mkdtemp(), "run.nc")
    >>> resume(p)
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: path='...run.nc' does not exist
    """
    p = _files.check_input(path)
    own = output is None or os.path.realpath(os.fspath(output)) == os.path.realpath(p)
    out = check_writable(p if own else output, overwrite=True if own else overwrite)
    checkpoint_every = check_checkpoint_every(checkpoint_every)
    progress = check_progress(progress)
    with _files.locked(p, name="path"):  # nobody else writes the checkpoint while we read and continue it
        ds = _open_checkpoint(p)
        try:
            kw = inputs_from_attrs(ds)
            chi, N = D._validate_start(kw["chi"], kw["N"], kw["method"], kw["chords"], kw.get("initial"),
                                       kw.get("problem"))
            opts = RunOptions.pick(kw)
        except (KeyError, TypeError, ValueError) as exc:
            raise V.SnappingInputError(f"path={p!r}: the inputs stored in the checkpoint are not valid "
                                       f"({type(exc).__name__}: {exc})") from None
        bad = _mismatch(kw, dict(expect or {}))
        if bad is not None:
            raise ResumeMismatch(bad, expect[bad], _stored(kw, bad), p)
        need = check_memory(N, opts, chi=chi, method=kw["method"])
        out = check_writable(out, overwrite=True if own else overwrite, need_bytes=need["file_bytes"])
        inputs, eng = M.method(kw["method"]).setup(chi, N, kw["method"], opts, chords=kw["chords"],
                                                   initial=kw.get("initial"), problem=kw.get("problem"))
        if "method_choice" in ds.attrs:  # (why method='fast' chose it: kept as the run recorded it)
            inputs["method_choice"] = str(ds.attrs["method_choice"])
        fresh = np.array(eng.records(), dtype=float, copy=True)  # the start the stored inputs describe
        try:
            eng.restore(ds)
        except (KeyError, ValueError, TypeError) as exc:
            if isinstance(exc, V.SnappingInputError):
                raise V.SnappingInputError(f"path={p!r}: {exc}") from None
            raise V.SnappingInputError(f"path={p!r}: the checkpoint is damaged ({exc})") from None
        _check_start(fresh, np.asarray(eng.records(), dtype=float), p)
        return D._drive(eng, inputs, output=out, progress=progress, checkpoint_every=checkpoint_every,
                        wall_before=float(ds.attrs["checkpoint_wall_time"]), overwrite=True if own else overwrite)
