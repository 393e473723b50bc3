"""The compiled run loop of the elastic line's RODAS4 with a body (``elastic.solve(problem with a body,
..., method="rodas4")``; branch fastbody): :func:`elastic_advance.advance` with
:func:`elastic_rodas_body.body_accept`'s steps and the body's measures.

Until branch fastbody a body's run took its steps one Python call each (``elastic_solve``'s loop:
``LineBody.measure``, the record row, the peaks; ~0.45 ms a step at N 947, a third of a step once the
body's Jacobian was exact). Here :func:`advance_body` takes them between two returns to Python with
:func:`elastic_advance._book`'s bookkeeping (the same order and arithmetic), the measures
:func:`body_measure` (``LineBody.measure``'s from the step's last evaluation: ``f`` at the new state,
the springs' tensions and strains there, and the body's force on the held end that evaluation left in
its scratch). The peaks are refined by ``elastic_solve._Peaks.refine`` on the kept steps (the body's
stepper; :class:`BodyRun` gives them, :meth:`elastic_advance.RodasRun.segments`), as before. The run's
numbers are the Python loop's (``elastic_solve.COMPILED_LOOP = False``), bit for bit where the clamp is
not a table (a table's spline is evaluated compiled, :func:`elastic_rodas_body.clamp_at`, in the
stepper, by scipy in ``LineBody.measure``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from . import elastic_advance as EA
from . import elastic_kernels as EK
from . import elastic_rodas as ER
from . import elastic_rodas_body as RB
from .elastic_body import bending_energy, compression_energy

__all__ = ["body_measure", "advance_body", "BodyRun"]


@njit(cache=True, error_model="numpy")
def body_measure(N, t, y, pin, h, m, ea, tabe, tabt, tabw, g, snode, f, T, E, bd, bs, mm):
    """``LineBody.measure`` of the state ``y`` at ``t`` from ``f = f(t, y)`` (:func:`RB.body_rhs`'s), the
    springs' ``T, E`` and the body's force on the held end ``bs[5][N], bs[6][N]`` that evaluation left
    (:func:`RB.body_f_and_jacobian`: the Jacobian writes those arrays below index N only) into ``mm``."""
    Bl, K0L, El, CN, CT, KN, KT, sc, cx, cc = bd
    EK.measure_given(N, y, pin, h, m, ea, tabe, tabt, tabw, g, snode, f, T, E, mm)
    mm[10] += bs[5][N]
    mm[11] += bs[6][N]
    ex, ey, _ = RB.clamp_at(t, sc, cx, cc)
    mm[14] += bending_energy(N, y, pin, Bl, K0L, sc[RB.P_CLAMPED] != 0.0, ex, ey, bs[0], bs[1], bs[2], bs[3])
    if sc[RB.P_PUSH] != 0.0:
        mm[14] += compression_energy(N, h, ea, bs[2])
        ns = 0
        for j in range(N):
            if T[j] == 0.0 and E[j] >= 0.0:
                ns += 1
        mm[16] = float(ns)


@njit(cache=True, error_model="numpy")
def advance_body(N, y, St, B5, gW, gD, ab, piv, pins, pinpar, pintab, h, invm, ea, damp, tabe, tabt, g, bd, ytmp,
                 btmp, w, ft, ctl, T, E, ED, FV, J3, gW4, bs, zz, GX, GY, QP, Q, hmin, m, tabw, snode, s_node, s_link,
                 mm, PY0, PY1, PC, PT, ref, keep, nkeep, after, best, sctl, rec, peak_z):
    """:func:`elastic_advance.advance` with the body: accepted steps (:func:`RB.body_accept`) from
    ``(ctl[C_T], y)`` and their bookkeeping until one of the ``R_*`` codes."""
    pin = pins[6]
    while True:
        s = EA._free(ref)
        if RB.body_accept(N, y, St, B5, gW, gD, ab, piv, pins, pinpar, pintab, h, invm, ea, damp, tabe, tabt, g, bd,
                          ytmp, btmp, w, ft, PY1[s], PY0[s], PC[s], ctl, T, E, ED, FV, J3, gW4, bs, zz, GX, GY, QP, Q,
                          hmin) != 0:
            return EA.R_STEP_FAILED
        t = ctl[ER.C_T]
        PT[s, 0] = ctl[ER.C_TOLD]
        PT[s, 1] = t
        body_measure(N, t, y, pin, h, m, ea, tabe, tabt, tabw, g, snode, St[0], T, E, bd, bs, mm)
        code = EA._book(N, t, ctl[ER.C_TOLD], y, mm, s, s_node, s_link, ctl[ER.C_NFEV],
                        ctl[ER.C_STATUS] == ER.FINISHED, ref, keep, nkeep, after, best, sctl, rec, peak_z)
        if code >= 0:
            return code


class BodyRun(EA.RodasRun):
    """:class:`elastic_advance.RodasRun` for a :class:`elastic_rodas_body.RodasBodyStepper`
    (:func:`advance_body`); no checkpoints (a body's run keeps none: ``elastic_body.check_method``)."""

    def advance(self, t_snapshot=np.inf, rows=None) -> int:
        st = self.st
        self.sctl[EA.S_TSNAP] = t_snapshot
        rec = self.rec if rows is None else self.rec[:rows]
        return advance_body(st.N, st.y, st.St, st.B5, st.gW12, st.gDb, st.ab5, st.piv5, st.pins, st.pinpar,
                            st.pintab, *st.bargs(), st.ytmp, st.btmp, st.w, st.ft, st.ctl, *st.work, st.J3, st.gW4,
                            st.bs, st.zz, st.GX, st.GY, st.QP, st.Q, st.hmin, *self.model, self.mm, self.PY0,
                            self.PY1, self.PC, self.PT, self.ref, self.keep, self.nkeep, self.after, self.best,
                            self.sctl, rec, self.peak_z)
