"""What the engines of every method share: the automatic-snapshot and record constants,
and the checkpoint bookkeeping.

:class:`snapping.simulate.methods.euler_richardson.Engine` and
:class:`snapping.simulate.methods.dop853.Engine` keep the same run state
besides their method-specific arrays: the control vector ``ctl``, the peak table
``pk``, the measures ``meas``/``meas0``, ``rinv0``, the snapshots so far and the
pending snapshot requests. :class:`CheckpointMixin` writes and restores that
shared part (schema names and layout as in :mod:`snapping.schema`); each engine
adds only its own variables.
"""
from __future__ import annotations

import numpy as np

from .. import _validate as V
from . import kernels as K
from ._netcdf import records_from_dataset
from .options import RECORD_CHUNK  # noqa: F401 (the engines take it from here)

#: automatic snapshots when v_max first reaches SPEED_LEVEL_0 * SPEED_LEVEL_FACTOR**n
SPEED_LEVEL_0 = 1.0
SPEED_LEVEL_FACTOR = 1.5
#: automatic snapshots after the peak, when v_max falls below these fractions of it
AFTER_PEAK_FRACTIONS = (0.9, 0.7)


def _pad(vals) -> np.ndarray:
    """A list of pending values as a float array, NaN-terminated (never empty)."""
    return np.asarray(list(vals) + [np.nan], dtype=float)


def checkpoint_getter(ds):
    """``get(name, shape)``: checkpoint variable ``name`` of ``ds`` as a float array,
    checked against ``shape`` (None: not checked)."""
    def get(name, shape):
        a = np.array(ds[name].values, dtype=float)
        if shape is not None and a.shape != shape:
            raise V.SnappingInputError(f"checkpoint variable {name!r} has shape {a.shape}, expected {shape}")
        return a
    return get


class CheckpointMixin:
    """Shared checkpoint write/restore; the engine provides ``ctl``, ``pk``, ``meas``,
    ``meas0``, ``rinv0``, ``N``, ``snapshots``, ``requested``, ``after_fracs``."""

    def _checkpoint_vars(self, own: dict, specs: dict) -> dict:
        """The engine's own checkpoint variables ``own`` ({name: (dims, values)}), followed by
        the shared ones, with the attributes of ``specs`` (a schema.CHECKPOINT_VARS* table)."""
        from .. import schema

        nd, ld = schema.NODE_DIM, schema.LINK_DIM
        row = "checkpoint_row"
        snaps = self.snapshots
        out = dict(own)
        out.update({
            "checkpoint_ctl": (("checkpoint_ctl",), self.ctl.copy()),
            "checkpoint_pk": (("checkpoint_peak", "checkpoint_peak_col"), self.pk.copy()),
            "checkpoint_meas": (("checkpoint_meas",), self.meas.copy()),
            "checkpoint_meas0": (("checkpoint_meas",), self.meas0.copy()),
            "checkpoint_rinv0": ((ld,), self.rinv0.copy()),
            "checkpoint_snapshot_state": (("checkpoint_snapshot", row, nd), np.stack([z for _, _, z in snaps])),
            "checkpoint_snapshot_t": (("checkpoint_snapshot",), np.array([t for t, _, _ in snaps], dtype=float)),
            "checkpoint_requested": (("checkpoint_pending",), _pad(self.requested)),
            "checkpoint_after_fractions": (("checkpoint_pending_after",), _pad(self.after_fracs)),
        })
        out = {k: (dims, v, dict(specs[k])) for k, (dims, v) in out.items()}
        out[schema.CHECKPOINT_KIND_VAR] = (("checkpoint_snapshot",), np.array([k for _, k, _ in snaps], dtype=str),
                                           {"long_name": "kinds of the snapshots so far"})
        return out

    def _restore_ctl(self, get, nctl: int) -> None:
        """Restore the control vector (``nctl`` entries) from a checkpoint."""
        ctl = get("checkpoint_ctl", None)
        if ctl.shape != (nctl,):
            raise V.SnappingInputError(f"checkpoint_ctl has {ctl.size} entries, this version needs {nctl}")
        self.ctl[...] = ctl

    def _restore_scales(self, ds, get) -> None:
        """Restore ``rinv0`` and the initial link error from a checkpoint."""
        self.rinv0 = get("checkpoint_rinv0", (self.N,))
        self.link_error_initial = float(ds.attrs["checkpoint_link_error_initial"])

    def _restore_history(self, ds, get, i_nrec: int) -> None:
        """Restore the snapshots, the pending requests and the step records from a
        checkpoint; ``ctl[i_nrec]`` (records in the buffer) is reset to 0."""
        from .. import schema

        N = self.N
        st = get("checkpoint_snapshot_state", None)
        ts = get("checkpoint_snapshot_t", None)
        kinds = [str(k) for k in np.asarray(ds[schema.CHECKPOINT_KIND_VAR].values)]
        if st.ndim != 3 or st.shape[1:] != (K.NROWS, N + 1) or not (len(ts) == len(kinds) == st.shape[0]):
            raise V.SnappingInputError("checkpoint snapshots are inconsistent")
        self.snapshots = [(float(t), k, z.copy()) for t, k, z in zip(ts, kinds, st)]
        self.requested = [float(v) for v in get("checkpoint_requested", None) if np.isfinite(v)]
        self.after_fracs = [float(v) for v in get("checkpoint_after_fractions", None) if np.isfinite(v)]
        recs = records_from_dataset(ds)
        self.chunks = [recs] if len(recs) else []
        self.ctl[i_nrec] = 0
