"""Locating the peaks the compiled step loop flagged, on the dense output, and what the fifth costs.

:meth:`snapping.simulate.methods.dop853.Engine.refine` (DOP853 and RODAS4) locates each flagged peak
with a bounded scalar minimization on the dense output; every evaluation counts in ``n_rhs``. A
general chain's fifth peak, ``kappa_peak_approach`` (branch kappa), is located the same way, and
its evaluations are counted apart as well, in the engine's ``n_rhs_approach`` (the run attribute of
that name): ``n_rhs - n_rhs_approach`` is the cost the run had before the fifth peak existed, to the
evaluation (branch emkappa, issue 24). Why: a regime study's escalation cap
(:func:`snapping.regimes_escalate.too_costly`) judges a cell by the cost of its integration, and
the fifth peak's location (+0.2% median, up to +15%) pushed end mass chi 0.1 M 0.0072 from 588,503
evaluations over the 600,000 cap, so the study stopped it one level earlier than before.

Exact accounting: the dense output of a step (:data:`DENSE_EVALS` evaluations) is built once and
kept while the step is one of the last two. The fifth peak is refined after the other four in each
call, so it pays for a step's dense output only when none of them built it; when a later refinement
of the four (or a snapshot) then uses that step's dense output, it would have built it itself before
the fifth peak existed, and those evaluations move back from ``n_rhs_approach`` (:func:`note_dense`).
"""

from __future__ import annotations

from scipy.optimize import minimize_scalar

from . import rk as R

__all__ = ["APPROACH_ROW", "DENSE_EVALS", "BUILT_FOR_APPROACH", "refine", "note_dense"]

#: the peak table's row of kappa_peak_approach (a general chain's fifth peak)
APPROACH_ROW = 4
#: evaluations of one step's dense output (DOP853's extra stages)
DENSE_EVALS = R.NSX - R.NS - 1
#: a step slot's ``DOK`` when the fifth peak's refinement built its dense output (1: built otherwise; 0: not)
BUILT_FOR_APPROACH = 2.0


def note_dense(eng, slot: int, built: bool) -> None:
    """Account a use of step ``slot``'s dense output (``built``: it was built just now, its
    :data:`DENSE_EVALS` evaluations counted in ``n_rhs``): built while the fifth peak is refined, it is
    the fifth peak's (``DOK[slot]`` :data:`BUILT_FOR_APPROACH`, checkpointed with the slot; the step loop
    sets it to 0 when the slot takes a new step); built by it and used now by anything else, its
    evaluations go back to the rest, once."""
    mine = getattr(eng, "_refining_approach", False)
    if built:
        if mine:
            eng.DOK[slot] = BUILT_FOR_APPROACH
    elif eng.DOK[slot] == BUILT_FOR_APPROACH and not mine:
        eng.n_rhs_approach -= DENSE_EVALS
        eng.DOK[slot] = 1.0


def refine(eng, peak_meas, xtol: float, one_call: bool) -> None:
    """Locate the peaks flagged by the compiled loop (``ctl[Q_REFINE]``'s bits) on ``eng``'s dense
    output; ``peak_meas``: the measurement index of each peak row; ``xtol``: the relative width of
    the bracket to which each is located; ``one_call``: DOP853's dense output measured in one compiled
    call (``eng.meas_at``), else an engine with its own (RODAS4's) by ``eng.Z_at``. The fifth row's evaluations are added to
    ``eng.n_rhs_approach`` as well."""
    bits = int(eng.ctl[R.Q_REFINE])
    eng.ctl[R.Q_REFINE] = 0.0
    pk = eng.pk
    measure = eng.meas_at if one_call else (lambda tt: eng.Z_at(tt)[1])
    for qi in range(pk.shape[0]):
        if not bits & (1 << qi):
            continue
        ta, tb = float(pk[qi, R.PK_TA]), float(pk[qi, R.PK_TB])
        m = peak_meas[qi]
        if not tb > ta:
            continue
        before = eng.ctl[R.Q_NRHS]
        eng._refining_approach = qi == APPROACH_ROW
        try:
            res = minimize_scalar(lambda tt: -measure(tt)[m], bounds=(ta, tb), method="bounded",
                                  options={"xatol": xtol * (tb - ta) + 1e-15 * abs(tb)})
        finally:
            eng._refining_approach = False
        if qi == APPROACH_ROW:
            eng.n_rhs_approach += eng.ctl[R.Q_NRHS] - before
        tq = float(res.x)
        q = float(-res.fun)
        if q > pk[qi, R.PK_BEST]:
            pk[qi, R.PK_BEST] = q
            pk[qi, R.PK_TBEST] = tq
        if qi == 0 and (eng.peak_state is None or eng.peak_state[0] != pk[0, R.PK_TBEST]):
            tq = float(pk[0, R.PK_TBEST])
            eng.peak_state = (tq, eng.Z_at(tq)[0])
