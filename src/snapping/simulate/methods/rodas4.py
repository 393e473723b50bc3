"""Runs with the stiff method (``method="rodas4"``, alias ``"stiff"``): chains with a body.

Bending stiffness makes the chain stiff: an explicit method (DOP853) is stable only for
steps below ~3.5 over the frequency of the shortest bending wave, ``omega_max = 4 N^2
sqrt(B/lambda)`` on a chain of N equal links (:mod:`snapping.simulate.stiffness`). RODAS4
is L-stable: its steps are set by accuracy alone. The compiled loop is
:func:`snapping.simulate.rosenbrock.advance_rodas` (banded O(N) stage solves,
banded Jacobian by forward-mode derivatives of the rows of
:mod:`snapping.simulate.stiff_system`); everything after a
step -- records (``models.model_measure``, the columns of every method), peaks, the stop
rules (including the moving held end's), invariants -- is DOP853's
(:func:`snapping.simulate.rk.after_attempt_with`), and so is the engine's interface
(:class:`snapping.simulate.methods.dop853.Engine`, which this one extends): snapshots,
progress, checkpoints (:data:`snapping.schema.CHECKPOINT_VARS_RODAS4`), resume bit for bit.

Differences from DOP853: the step-size rule of an order-3 error estimate (``err^(-1/4)``,
at most 6x larger); peaks located on RODAS4's continuous extension of order 3
(:func:`snapping.simulate.rosenbrock.dense_eval`, no extra evaluation); ``n_rhs`` counts
every real evaluation (5 per attempted step, 1 per accepted step, the W/D rows'
differences and ``f_t`` where there are any, peak location), and the Jacobians
(``n_jacobians``: ten real forward-mode derivatives of the compiled rows each) and banded
factorisations (``n_factorizations``) are counted apart.

Only problems with an active body (:class:`snapping.simulate.Body`) are taken: without
bending nothing is stiff, and ``method="fast"`` (DOP853) is the method for them.
"""

from __future__ import annotations

import numpy as np

from ... import _validate as V
from .. import forced as FR
from .. import general as G
from .. import models as MD
from .. import rk as R
from .. import rosenbrock as RB
from ..stiff_system import NCOL
from . import dop853 as DP

__all__ = ["Engine", "setup", "complete", "NAMES", "CHECKPOINT_VARS", "DEFAULT_TOL"]

#: the names this method answers to
NAMES = ("rodas4", "stiff")
#: tolerance of a run that gives none (max norm, relative and absolute, per step): the peaks
#: v, a, sigma were within 0.02-3.7 tol of dop853 at tol 1e-8 .. 1e-11 for tol 1e-4 .. 1e-7
#: (chi 0.25, N 100, 300, 1000, beta 1e-6 .. 1e-2, damping ratio 0 and 1; the worst, 3.7 tol,
#: at N 1000, beta 1e-6), so 2e-7 keeps them within 1e-6 (benchmarks/bench_stiff.py)
DEFAULT_TOL = 2e-7


def _checkpoint_names():
    from ... import schema

    return schema.CHECKPOINT_VARS_RODAS4


#: the checkpoint variables of this method's run files
CHECKPOINT_VARS = _checkpoint_names()
#: node-evaluations per call into the compiled loop (a step costs about 40 evaluations)
NODE_EVALS_PER_CALL = 20_000_000


class Engine(DP.Engine):
    """State and buffers of a RODAS4 run (see :func:`rosenbrock.advance_rodas`)."""

    def __init__(self, y0, t0, *, mdl, **kw):
        if mdl is None or mdl[0][G.P_KIND] != G.KIND_BODY:
            raise ValueError("the stiff engine takes a body model")  # pragma: no cover - setup checks
        self.cnt = np.zeros(RB.NCNT)
        super().__init__(y0, t0, mdl=mdl, **kw)
        N = self.N
        n = y0.size
        f0 = self.KK[0, R.NS].copy()
        self.KK = np.zeros((2, RB.NSTG, n))
        self.KK[0, RB.S_F1] = f0
        self.F = np.zeros((2, 1, n))
        par, h, invm, invh, snode, tab = self.mdl
        o = int(par[FR.P_BOFF])
        n1 = N + 1
        self.barr = np.zeros((4, n1))
        for r, b in enumerate((FR.B_BL, FR.B_K0L, FR.B_EL)):
            self.barr[r] = tab[o + b * n1:o + (b + 1) * n1]
        self.barr[3, :N - 1] = invm[1:]
        clamped = par[FR.P_CLAMP] != 0.0
        auto = par[G.P_PIN] == G.PIN_FIXED and int(par[FR.P_CNK]) == 0
        quad = (not auto) or clamped or bool(np.any(self.barr[2] != 0.0)) or par[FR.P_HASDRAG] != 0.0
        qfd = quad and not auto  # (a fixed held end and clamp: W' = 0, D' = 2R - p exact, drag's p too)
        self.rp = np.array([clamped, par[FR.P_HASBEND] != 0.0, quad, qfd, auto, par[FR.P_HASDRAG] != 0.0, False],
                           dtype=float)
        self.Dj = np.zeros((4, NCOL, 2 * N))
        self.ab = np.zeros((2 * N, RB.WROW))
        self.piv = np.zeros(2 * N, dtype=np.int64)
        self.btmp = np.zeros(n)
        self.rhs = np.zeros(2 * N)
        self.tmp = np.zeros(n)
        self.ft = np.zeros(n)
        t_eval = float(np.nextafter(t0, np.inf)) if t0 in G.breakpoints(self.mdl) else t0
        w = self.w
        MD.model_rhs(N, t_eval, y0, f0, w.c, w.s, w.S, w.cp, w.dp, w.sig, self.mdl)  # (its tensions; not counted:
        RB.jacobian_at(N, t_eval, y0, f0, w.sig, self.Dj, self.mdl, self.barr, self.rp)  # the same f as above)
        self.cnt[RB.CN_JAC] += 1.0
        self.ctl[R.Q_STEPS_PER_CALL] = max(20, NODE_EVALS_PER_CALL // (40 * N))

    def _initial_step(self, y0, f0, t0) -> float:
        """Hairer's starting step for an order-4 method (the exponent 1/5)."""
        sc = self.tol * (1.0 + np.abs(y0))
        d0 = np.max(np.abs(y0) / sc)
        d1 = np.max(np.abs(f0) / sc)
        h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
        f1 = np.empty_like(y0)
        w = self.rw
        MD.model_rhs(self.N, t0 + h0, y0 + h0 * f0, f1, w.c, w.s, w.S, w.cp, w.dp, w.sig, self.mdl)
        self.n_extra += 1
        d2 = np.max(np.abs(f1 - f0) / sc) / h0
        h1 = max(1e-6, h0 * 1e-3) if max(d1, d2) <= 1e-15 else (0.01 / max(d1, d2)) ** 0.2
        return float(min(100.0 * h0, h1))

    def state_at(self, t: float) -> np.ndarray:
        """The state at time t within the last two accepted steps (the continuous extension)."""
        for slot in (int(self.ctl[R.Q_SLOT]), 1 - int(self.ctl[R.Q_SLOT])):
            t0, h = self.TS[slot], self.HS[slot]
            if h > 0.0 and t0 - 1e-14 * max(1.0, abs(t0)) <= t <= t0 + h * (1 + 1e-12) + 1e-300:
                out = np.empty(self.Y0.shape[1])
                RB.dense_eval(min(1.0, max(0.0, (t - t0) / h)), self.Y0[slot], self.Y1[slot], self.KK[slot], out)
                return out
        raise RuntimeError(f"t={t!r} is outside the stored steps")  # pragma: no cover - internal

    def loop(self, bar, poll=None) -> int:
        """Run the compiled loop until a stop or failure code (as :meth:`DP.Engine.loop`)."""
        self.start()
        w = self.w
        while True:
            code = RB.advance_rodas(self.N, self.Y0, self.Y1, self.KK, self.TS, self.HS, self.DOK, self.ytmp,
                                    w.c, w.s, w.S, w.cp, w.dp, w.sig, self.Z, self.rinv0, self.ctl, self.rec,
                                    self.pk, self.meas, self.mdl, self.Dj, self.ab, self.piv, self.btmp, self.rhs,
                                    self.tmp, self.ft, self.barr, self.rp, self.cnt)
            final = self.handle(code, bar)
            if final is not None:
                return final
            if poll is not None:
                stop = poll()
                if stop is not None:
                    return stop

    def results(self, status: str, reason: str, wall: float, failure: str = "", node: int = -1) -> dict:
        out = super().results(status, reason, wall, failure, node)
        out["n_jacobians"] = int(self.cnt[RB.CN_JAC])
        out["n_factorizations"] = int(self.cnt[RB.CN_LU])
        return out

    def checkpoint_vars(self) -> dict:
        """The checkpoint variables (schema.CHECKPOINT_VARS_RODAS4)."""
        from ... import schema

        nd = schema.NODE_DIM
        row, slot, ang = "checkpoint_row", "checkpoint_slot", "checkpoint_angle"
        peak_t, peak_Z = (np.nan, np.full_like(self.Z, np.nan)) if self.peak_state is None else self.peak_state
        return self._checkpoint_vars({
            "checkpoint_Y0": ((slot, ang), self.Y0.copy()),
            "checkpoint_Y1": ((slot, ang), self.Y1.copy()),
            "checkpoint_stages": ((slot, "checkpoint_rodas_stage", ang), self.KK.copy()),
            "checkpoint_step_t": ((slot,), self.TS.copy()),
            "checkpoint_step_h": ((slot,), self.HS.copy()),
            "checkpoint_jacobian": (("checkpoint_jacobian_var", "checkpoint_jacobian_colour",
                                     "checkpoint_jacobian_row"), self.Dj.copy()),
            "checkpoint_counts": (("checkpoint_count",), self.cnt.copy()),
            "checkpoint_Z": ((row, nd), self.Z.copy()),
            "checkpoint_peak_t": ((), np.float64(peak_t)),
            "checkpoint_peak_state": ((row, nd), np.array(peak_Z, dtype=float)),
        }, schema.CHECKPOINT_VARS_RODAS4)

    def restore(self, ds) -> None:
        """Continue from the checkpoint in run Dataset ``ds`` (the inverse of :meth:`checkpoint_vars`)."""
        self._restore_from(ds, (("checkpoint_jacobian", self.Dj), ("checkpoint_counts", self.cnt)))


_compiled = False


def _warm_up() -> None:
    """Compile (or load from the numba cache) the loop on a tiny problem with a body."""
    global _compiled
    if _compiled:
        return
    from ..body import Body
    from ..problem import Problem

    p = Problem.catenary(0.5, 6, body=Body(bending=1e-3, damping=1e-4))
    eng = Engine(p.initial_angles(), 0.0, mdl=p.model(), tol=1e-6, dt0=None, t_end=0.02, stop_fraction=0.0,
                 thin=0.0, max_link_error=0.5, snapshot_times=(0.01,))
    eng.loop(None)
    _compiled = True


def complete(opts, method: str):
    """The options with this method's defaults filled in (none)."""
    return opts


def check_problem(problem) -> None:
    """SnappingInputError unless ``problem`` is a Problem with an active body."""
    why = None
    if problem is None:
        why = "the paper's chain (no body)"
    elif problem.model()[0][G.P_KIND] != G.KIND_BODY:
        why = "a chain without a body (no bending stiffness, damping, drag or clamp)"
    if why is not None:
        raise V.SnappingInputError(f"method='rodas4' (stiff) solves chains with a body (Problem(..., body=Body(...)): "
                                   f"bending, damping, drag or a clamp); this run is {why}, which is not stiff: "
                                   f"use method='fast' (dop853)")


def setup(chi, N, method: str, opts, *, chords: str = "exact", initial=None, problem=None):
    """The input attributes and the engine of a RODAS4 run (a problem with a body only)."""
    check_problem(problem)
    y0 = problem.initial_angles()
    inputs = {"chi": float("nan") if problem.chi is None else problem.chi, "N": N, "method": "rodas4",
              **opts.input_attrs(), "chords": problem.chords or "exact", "initial": "problem", "problem": problem}
    DP._warm_up()
    _warm_up()
    eng = Engine(y0, 0.0, mdl=problem.model(), **opts.engine_kwargs())
    if opts.drag_jacobian == "correct" and eng.rp[RB.RP_DRAG] == 0.0:  # (nothing to correct: twice the work)
        raise V.SnappingInputError("drag_jacobian='correct' corrects RODAS4's stage solves for air drag, and this "
                                   "line has none (drag_normal, drag_tangential, drag_linear_normal, "
                                   "drag_linear_tangential and tip_drag all 0): leave drag_jacobian='banded'")
    eng.rp[RB.RP_DCORR] = 1.0 if opts.drag_jacobian == "correct" else 0.0
    inputs["dt0"] = eng.dt0
    return inputs, eng
