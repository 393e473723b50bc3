"""The mechanisms and accuracy presets of a regime study (:mod:`snapping.regimes`).

Kept apart from the study (which needs xarray and the continuum tools) so that the command
line can build its parser, and answer a table query, without importing them.
"""

from __future__ import annotations

__all__ = ["MECHANISMS", "ACCURACY", "NUMBER_MAX", "STRETCH_METHOD", "STRETCH_METHODS", "STRETCH_STOP_FLOOR", "STRETCH_START",
           "STRETCH_DAMPING", "STRETCH_MAX_RHS",
           "STRETCH_TOL_C", "stretch_tol", "STRETCH_TIP_TIME", "STRETCH_MAX_RHS_LINKS", "stretch_tip_floor",
           "STRETCH_SNAP_PEAKS", "BEND_SNAP_PEAKS", "BEND_PEAKS_KEY", "STRETCH_PEAK_ATTRS", "STRETCH_PEAKS_KEY", "STRETCH_EXTRA_PEAKS", "STRETCH_ESCALATE", "STRETCH_EXTRA_LEVELS",
           "CHAIN_EXTRA_PEAKS"]

#: mechanism -> (the number's name in snapping.dimensionless, grading of the levels, what it is)
MECHANISMS = {
    "bending": ("beta", "fold", "bending stiffness B/(lambda g L^3) (rest start; grid damping vanishing as h^2)"),
    "drag": ("drag_normal", "fold", "air drag: normal number d, tangential d*pi*C_t/C_n (default coefficients)"),
    "drag-normal": ("drag_normal", "fold", "normal (cross-flow) air drag alone"),
    "drag-tangential": ("drag_tangential", "fold", "tangential air drag (skin friction) alone"),
    "end-mass": ("end_mass", "fold", "a point mass M_end/(lambda L) at the free end"),
    "stretching": ("inverse_stretching", "fold", "stretching: sqrt(g L)/c, c = sqrt(EA/lambda) the wave speed (the "
                   "elastic line; 0 the inextensible ideal)"),
}

#: accuracy presets: levels, first level, links of level 0 of uniform chains (n0), tolerance. Measured
#: (ideal chain, `benchmarks`-free check in the guide): coarse gives 34.1 +- 2.0 at chi = 0.1 and
#: 11.33 +- 0.13 at chi = 0.25 (fold-graded 493-1857 and 193-639 links), medium 32.98 +- 0.10 and
#: 11.282 +- 0.004 (947-7328 and 341-2436 links); the paper's limits are 32.97 and 11.28
ACCURACY = {
    "coarse": {"levels": 3, "first": -2, "n0": 50, "tol": 1e-7},
    "medium": {"levels": 4, "first": -1, "n0": 50, "tol": 1e-7},
    "fine": {"levels": 4, "first": 0, "n0": 100, "tol": 1e-7},
}

#: the largest number a cell takes (every mechanism's number is a ratio to the chain's scales)
NUMBER_MAX = 1e4

#: stretching: the elastic line's method in a study: RODAS4 in link coordinates
#: (:mod:`snapping.simulate.elastic_links_rodas`; its grid damping is the study's ``damping``), the
#: shipped study's (``benchmarks/stretch_scan.py``: v_peak within 1% in 32/32 cells). The regime study's
#: only: the caps' stretch factor keeps its own default (:data:`snapping.caps_runs.STRETCH_METHOD`, "rodas4")
STRETCH_METHOD = "rodas4-links"
#: stretching: the elastic methods a study may take (``regimes(method=)``): the node-coordinate
#: RODAS4 of :mod:`snapping.simulate.elastic_rodas` (the study shipped before branch shipstretch), or the
#: default, RODAS4 in link coordinates, whose steps are not capped by the wave speed c
#: (``benchmarks/stretch_links.py``, docs/guide/regimes.md)
STRETCH_METHODS = ("rodas4", "rodas4-links")
#: stretching: the running peak of v_max (units sqrt(g L)) above which the elastic run's stop rule
#: judges the snap (:func:`snapping.simulate.elastic.solve`'s ``stop_floor``). Its default bound,
#: from the release's elastic energy given to the lightest node, exceeds the snap itself on
#: fold-graded links (tip links of 1e-5: chi = 0.5, c = 30, a floor of 14.6 against a peak of 4.3),
#: so the run went on to t = 10. Every snap scanned peaks above 2 (c = 3.3, chi = 0.5: 3.7), and
#: the fall's own speed passes 1 only at t ~ 1, the release's ringing adding far less (the fall's
#: v_max 0.397 at t = 0.36 against g t = 0.36, chi = 0.5, c = 30)
STRETCH_STOP_FLOOR = 1.0

#: stretching: the elastic line's start in a study (:func:`snapping.simulate.elastic.solve`'s ``start``):
#: ``"matched"``, the line at rest at the catenary stretched to the rigid chain's tensions just after
#: release (no release wave: what the study measures is the snap's own stretching, not the release's
#: ringing); ``"stretched"`` (the hanging equilibrium let go: the study file of stop 29) is kept
#: reproducible by ``regimes(start="stretched")``. Stored in the study's attributes (``elastic_start``);
#: a study file without it was run from ``"stretched"``
STRETCH_START = "matched"

#: stretching: the study's default elastic grid damping (the damping ratio of each link's shortest
#: longitudinal mode; it vanishes with the links, so the continuum extrapolation removes it). 4, not 1:
#: at 1 the fold-graded tip links (1e-5 to 1e-4 long, tension ~ their own tiny mass) are knocked slack by
#: the step's error and chatter slack/taut at steps of 1e-7 (chi = 0.3, c = 442, 108 links, matched
#: start, tol 1e-6: 1,054,295 evaluations, 108,601 of 125,498 steps with a slack link); at 4 no link
#: goes slack there: 83,633 evaluations, v_peak 7.89554 against 7.89520 (4e-5)
STRETCH_DAMPING = 4.0
#: stretching: a run stops (failed, the study goes on without it and says so) after this many
#: evaluations: a line whose tip links chatter slack/taut (chi = 0.1, c = 1000, 267 links at tol 1e-6:
#: 1.5 million evaluations for the first 0.17 of the 1.19 time units to the snap) would otherwise
#: hold a worker for hours; a study resumed with a larger cap redoes only the runs missing
STRETCH_MAX_RHS = 2_500_000

#: stretching: the wave speed (units sqrt(g L)) above which a run's tolerance is the study's times
#: ``(STRETCH_TOL_C / c)^2`` (:func:`stretch_tol`)
STRETCH_TOL_C = 450.0


def stretch_tol(tol: float, c: float) -> float:
    """The tolerance of a stretching run of wave speed ``c``: the study's ``tol`` up to
    ``STRETCH_TOL_C``, then ``tol (STRETCH_TOL_C / c)^2``. Why: the tip links of a fold-graded line
    carry a tension of the order of their own tiny mass, so their elastic stretch, T/EA ~ c^-2, is
    what the step's position error must stay below; above it the error knocks them slack and they
    chatter slack/taut at steps of 1e-8 to 1e-7. Measured (chi = 0.5, c = 1000, 91 links, matched
    start, grid damping 4): tol 1e-6 took 2,354,092 evaluations, tol 2e-7 252,651 (v_peak 4.37868).

    >>> stretch_tol(1e-6, 100.0), round(stretch_tol(1e-6, 900.0), 12)
    (1e-06, 2.5e-07)
    """
    return tol if c <= STRETCH_TOL_C else tol * (STRETCH_TOL_C / c) ** 2


#: stretching, ``method="rodas4-links"``: the free end's links are at least ``STRETCH_TIP_TIME * c`` long
#: (units L, c in sqrt(g L)): a tip link's longitudinal wave crossing time h/c is at least this. Why: the
#: fold-graded tip links carry a tension of the order of their own weight (strain ~ g h / c^2), far
#: below what the step's error resolves, so they sit at the slack/taut kink of the tension law, where
#: the grid damping's force jumps by zeta c lambda l' as a link turns taut. Where h/c is short the
#: integrator follows that chatter (steps ~ zeta h / c, 1e-9 to 1e-7) from the start and never leaves it:
#: at tol 1e-6, grid damping 4, every run measured that stalled (chi = 0.5, c = 442, h_min 2.1e-6 and
#: 4.2e-6 on level 1; c = 87 and 196 on level 2; chi = 0.1, c = 442 on level 1) or was flagged slack
#: (chi = 0.1, c = 1000 on levels -1 and 0, c = 442 on level 2) had h_min/c <= 1.2e-8 (not every run
#: there failed), and every run with h_min/c >= 1.8e-8 ran (a few hundred to 2,100 steps); 3e-8 leaves
#: a margin of 2.5 over the longest that failed (benchmarks/stretch_tip_floor.py). The tip links resolve
#: nothing the peaks need at that length: flooring moves v_peak by 1.3e-6 to 1.3e-5 relative at
#: chi = 0.5 (c = 442, levels -1 ... 1), 1.8e-5 (chi = 0.1, c = 196, level 0) and 2.6e-4 (chi = 0.1,
#: c = 442, level 0). Two physical scales were tried first and fail: the arm length where
#: the ideal fold's speed reaches c does not exist for the stiff lines (v_peak of the ideal, 4.5 to 33,
#: stays below c >= 87), and the tip zone whose tension ~ lambda g s is below the grid damping's
#: response to the tolerance's velocity error (s < zeta c tol, 1.8e-3 at c = 442, tol 1e-6), used as a
#: floor, lowers chi = 0.1's level-0 peak from 31.4 to 20.1 (docs/guide/regimes.md)
STRETCH_TIP_TIME = 3e-8
#: stretching, ``method="rodas4-links"``: a run stops (failed) after this many evaluations. Its runs
#: took at most 77,436 in the full 4 x 8 scan at levels -1 ... 2 (chi = 0.3, c = 442, level 2, its
#: evaluations doubling with each level), at most 13,343 elsewhere; a stalled run (tip-link chatter,
#: 1e-8 steps) would otherwise run to STRETCH_MAX_RHS, 2.5 million evaluations, an hour at 7000 links
STRETCH_MAX_RHS_LINKS = 200_000


def stretch_tip_floor(c: float, method: str) -> float:
    """The shortest free-end link of a stretching run of wave speed ``c`` by ``method``:
    ``STRETCH_TIP_TIME * c`` for ``"rodas4-links"``, 0 (no floor: the node-method study's
    links, shipped before branch shipstretch) otherwise.

    >>> round(stretch_tip_floor(442.0, "rodas4-links"), 12), stretch_tip_floor(442.0, "rodas4")
    (1.326e-05, 0.0)
    """
    return STRETCH_TIP_TIME * c if method == "rodas4-links" else 0.0


#: stretching: the peaks a study keeps from each elastic run's snap, not its whole run (the run's
#: ``a_peak_snap``, ``sigma_peak_snap``: :mod:`snapping.simulate.snap_window`); the study's key
#: says ``"peaks": "snap"`` (a file of the run's peaks is not resumed)
STRETCH_SNAP_PEAKS = ("a_peak", "sigma_peak")

#: stretching (branch stretch1pct): the run attribute each of the study's peaks is taken from: the
#: acceleration and the tension over the snap (0.9 window, :data:`STRETCH_SNAP_PEAKS`)
STRETCH_PEAK_ATTRS = {"a_peak": "a_peak_snap", "sigma_peak": "sigma_peak_snap"}
#: the study key's ``"peaks"`` for :data:`STRETCH_PEAK_ATTRS`
STRETCH_PEAKS_KEY = "snap"
#: stretching: further peaks a study keeps beside :data:`snapping.continuum.QUANTITIES` (levels, limit,
#: error, order, ratio), from the run attribute named: the tension over the taut snap (until the line
#: first goes slack after the speed peak, :func:`snapping.simulate.snap_window.taut_end`). Measured, not
#: the study's sigma_peak: in soft lines it is a turning point after the 0.9 window and before any slack
#: link, but it grows with the fold levels by a near-constant step (chi 0.1, c 7.53: 27.75, 28.87, 29.97),
#: so it has no continuum limit on these levels (docs/guide/regimes.md "The taut snap's tension").
#: The ideal chain's (inextensible: never slack) is its run's sigma_peak
STRETCH_EXTRA_PEAKS = {"sigma_peak_taut": "sigma_peak_taut"}
#: every study keeps beside QUANTITIES the runs' ``kappa_peak_approach`` (stretching's cells since branch stretchapp: the
#: elastic line's, :mod:`snapping.simulate.elastic_approach`): the curvature peak
#: while v_max rises to the snap, at the joints at least ``general.KAPPA_TIP_JOINTS`` links from the free end.
#: The run's kappa_peak is the node next to the free end's (a node-index boundary layer, 1.29x the curvature
#: a few joints in at every resolution) and the larger of two maxima, one before the speed peak and one after
#: (the whirl); the second converges slowly and overtakes the first from the second level on, so the levels
#: jump (ideal chi 0.2: 334.0, 340.5, 364.5, 369.2). docs/guide/regimes.md "The curvature peak".
CHAIN_EXTRA_PEAKS = ("kappa_peak_approach",)
#: ... and, of each run's n_rhs, the evaluations that located kappa_peak_approach (``<name>_level``): the
#: escalation's cost cap judges the integration's own cost, n_rhs less these, the work it judged before the
#: fifth peak existed (:func:`snapping.regimes_escalate.integration_rhs`; branch emkappa)
CHAIN_COST_PARTS = ("n_rhs_approach",)

#: stretching, the shipped scan (``benchmarks/stretch_scan.py``): a cell (or the ideal at a chi) whose
#: v_peak, a_peak or sigma_peak error bar exceeds this fraction of its limit runs one more level
#: (``regimes(escalate=)``, :mod:`snapping.regimes_escalate`), up to :data:`STRETCH_EXTRA_LEVELS` more
STRETCH_ESCALATE = 0.01
STRETCH_EXTRA_LEVELS = 1

#: bending (branch snapbend): the peaks a study keeps from each run's snap without the release
#: (:func:`snapping.simulate.snap_window.run_snap_peaks`: from the last step before the speed peak with v_max
#: below half its peak to the first after, the run's end), not its whole run: the rest start's folded shape
#: rings at the grid scale when let go, its acceleration at t = 0 doubling with each fold level (chi 0.5,
#: beta 0.01: 96, 197, 395, 789 against the snap's 10.2). kappa_peak stays the run's (snap_window's module text)
BEND_SNAP_PEAKS = ("a_peak", "sigma_peak")
#: the study key's ``"peaks"`` for :data:`BEND_SNAP_PEAKS`
BEND_PEAKS_KEY = "snap"
