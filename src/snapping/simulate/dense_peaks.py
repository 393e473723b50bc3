"""Peaks located between steps on the dense output of the last two accepted steps.

The mixin of :class:`snapping.simulate.methods.dop853.Engine` (and, through it, of RODAS4's engine, which
brings its own continuous extension by overriding :meth:`DenseOutputPeaks.state_at`): the compiled step
loop flags a peak quantity whose maximum lies inside the last steps (bits of ``ctl[Q_REFINE]``, the
bracket in ``pk``); :meth:`DenseOutputPeaks.refine` locates it there with a bounded scalar search on the
dense output, each evaluation one compiled call (:func:`snapping.simulate.dense_measure.measure_at`) for
DOP853, the state and the right side through :meth:`DenseOutputPeaks.Z_at` for an engine with its own
interpolant. The engine holds the arrays (``Y0, Y1, KK, F, TS, HS, DOK`` of both step slots, ``ctl``,
``pk``, ``rw``, ``mdl``, ``rinv0``, ``nmeas``).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize_scalar

from . import dense_measure as DM
from . import general as G
from . import kernels as K
from . import models as MD
from . import rk as R

__all__ = ["DenseOutputPeaks", "PEAK_XTOL"]

#: relative width (of the bracketing interval) to which peaks are located
PEAK_XTOL = 1e-10
_PEAK_MEAS = (K.M_VMAX, K.M_AMAX, K.M_SIGMAX, K.M_KMAX)
#: a general chain's peaks: + kappa_max_interior on the approach (``kappa_peak_approach``)
_PEAK_MEAS_G = _PEAK_MEAS + (G.M_KIN,)


class DenseOutputPeaks:
    """State, diagnostics and peaks at any time within the last two accepted steps."""

    def _dense_slot(self, t: float) -> tuple[int, float]:
        """The step slot holding time t (its dense output built) and t's fraction of it."""
        for slot in (int(self.ctl[R.Q_SLOT]), 1 - int(self.ctl[R.Q_SLOT])):
            t0, h = self.TS[slot], self.HS[slot]
            if h > 0.0 and t0 - 1e-14 * max(1.0, abs(t0)) <= t <= t0 + h * (1 + 1e-12) + 1e-300:
                if self.DOK[slot] == 0.0:
                    w = self.rw
                    R.dense_build(self.N, t0, h, self.Y0[slot], self.Y1[slot], self.KK[slot], self.F[slot],
                                  self.ytmp, w.c, w.s, w.S, w.cp, w.dp, w.sig, self.mdl)
                    self.ctl[R.Q_NRHS] += R.NSX - R.NS - 1
                    self.DOK[slot] = 1.0
                return slot, min(1.0, max(0.0, (t - t0) / h))
        raise RuntimeError(f"t={t!r} is outside the stored steps")  # pragma: no cover - internal

    def state_at(self, t: float) -> np.ndarray:
        """The angle state at time t within the last two accepted steps (dense output)."""
        slot, x = self._dense_slot(t)
        out = np.empty(self.Y0.shape[1])
        R.dense_eval(self.N, x, self.Y0[slot], self.F[slot], out)
        return out

    def meas_at(self, t: float) -> np.ndarray:
        """:meth:`Z_at`'s diagnostics at time t in one compiled call (:func:`dense_measure.measure_at`:
        the same floats); a scratch array, overwritten by the next call. DOP853's dense output only
        (an engine that overrides :meth:`state_at` is refined by :meth:`Z_at`)."""
        slot, x = self._dense_slot(t)
        if getattr(self, "_mscratch", None) is None:
            n = self.Y0.shape[1]
            self._mscratch = (np.empty(n), np.empty(n), np.zeros((K.NROWS, self.N + 1)), np.zeros(self.nmeas))
        y, f, Z, meas = self._mscratch
        w = self.rw
        DM.measure_at(self.N, t, x, self.Y0[slot], self.F[slot], y, f, w.c, w.s, w.S, w.cp, w.dp, w.sig, Z,
                      self.rinv0, meas, self.mdl)
        self.ctl[R.Q_NRHS] += 1
        return meas

    def Z_at(self, t: float):
        """The position-form state Z and its diagnostics at time t (one evaluation)."""
        y = self.state_at(t)
        w = self.rw
        f = np.empty_like(y)
        MD.model_rhs(self.N, t, y, f, w.c, w.s, w.S, w.cp, w.dp, w.sig, self.mdl)
        self.ctl[R.Q_NRHS] += 1
        Z = np.zeros((K.NROWS, self.N + 1))
        meas = np.zeros(self.nmeas)
        MD.model_measure(self.N, t, y, w.c, w.s, w.sig, Z, self.rinv0, meas, self.mdl)
        return Z, meas

    def refine(self) -> None:
        """Locate the peaks flagged by the compiled loop on the dense output."""
        bits = int(self.ctl[R.Q_REFINE])
        self.ctl[R.Q_REFINE] = 0.0
        pk = self.pk
        # DOP853's dense output in one compiled call; an engine with its own (RODAS4's) by Z_at
        # DOP853's dense output in one compiled call; an engine with its own (RODAS4's) by Z_at
        measure = self.meas_at if type(self).state_at is DenseOutputPeaks.state_at else (lambda tt: self.Z_at(tt)[1])
        for qi in range(pk.shape[0]):
            if not bits & (1 << qi):
                continue
            ta, tb = float(pk[qi, R.PK_TA]), float(pk[qi, R.PK_TB])
            m = _PEAK_MEAS_G[qi]
            if not tb > ta:
                continue
            res = minimize_scalar(lambda tt: -measure(tt)[m], bounds=(ta, tb), method="bounded",
                                  options={"xatol": PEAK_XTOL * (tb - ta) + 1e-15 * abs(tb)})
            tq = float(res.x)
            q = float(-res.fun)
            if q > pk[qi, R.PK_BEST]:
                pk[qi, R.PK_BEST] = q
                pk[qi, R.PK_TBEST] = tq
            if qi == 0 and (self.peak_state is None or self.peak_state[0] != pk[0, R.PK_TBEST]):
                tq = float(pk[0, R.PK_TBEST])
                self.peak_state = (tq, self.Z_at(tq)[0])
