"""Stepping the extensible line (:mod:`snapping.simulate.elastic_model`): error-controlled, with
steps that its stiffness does not dictate, recorded into a run Dataset.

The default method is scipy's ``Radau`` (implicit Runge-Kutta, order 5, L-stable) with the
analytic block-tridiagonal Jacobian as a sparse matrix: its LU factors are banded, O(N) per
factorisation, so a stiff line (a large wave speed c) costs steps set by the accuracy of the
motion, not by c. ``"DOP853"`` (scipy's explicit 8th-order method, the same compiled
right-hand side) is there to compare: its steps are bounded by stability, dt ~ h/c.
``"rodas4"`` is a compiled RODAS4 (:mod:`snapping.simulate.elastic_rodas`: the exact banded
Jacobian, W and D rows included, the stage system reduced to the velocities, O(N) a step):
as many evaluations as Radau for the same peak accuracy or fewer (5x fewer at N = 100, c = 300)
and 10-70x less wall time. Its step loop and the bookkeeping below (records, peaks, snapshots,
the stop rule) are compiled (:mod:`snapping.simulate.elastic_advance`; Python runs once per
snapshot or 4096 steps), the same numbers as the Python loop (``COMPILED_LOOP = False``); so is
the refinement of its peaks (:mod:`snapping.simulate.elastic_refine`; ``COMPILED_REFINE =
False``: :meth:`_Peaks.refine`, the same numbers). The Dataset is built by
:mod:`snapping.simulate.elastic_dataset`.
``"rodas4-links"`` is the same RODAS4 in link coordinates (each link's length and angle:
:mod:`snapping.simulate.elastic_links_rodas`), whose steps the wave speed does not cap (the
elastic guide, "Link coordinates"); its loop and refinement are compiled too
(:func:`elastic_advance.advance_links`, :func:`elastic_refine.refine_segments` for the Python
loop), the same numbers.

Slack-taut transitions make the force continuous with a jump in its derivative; the error
control of the method meets them (steps shrink there); no events are used. The energy
``kinetic + gravity + elastic - W + D`` (W the held end's work, D the damping's dissipation,
both integrated with the state) is conserved to the method's accuracy, also through them;
``energy_drift`` reports its largest change.

Example
-------
>>> from snapping.simulate.problem import Links, Problem
>>> from snapping.simulate.elastic import Elastic, solve
>>> r = solve(Problem.catenary(0.25, links=Links.uniform(12, lumping="shared")), Elastic.from_wave_speed(20.0),
...           t_end=0.3, tol=1e-6)
>>> r.dataset.attrs["status"], bool(r.dataset.attrs["energy_drift"] < 1e-5)
('completed', True)
"""

from __future__ import annotations

import contextlib
import json
import time

import numpy as np
from scipy.integrate import DOP853, Radau

from .. import _validate as V
from . import elastic_advance as EA
from . import elastic_body_advance as EBA
from . import elastic_checkpoint as ECK
from . import elastic_checks as EC
from . import elastic_progress as EP
from . import elastic_refine as ERF
from . import elastic_rodas as ER
from .elastic_approach import refine_peaks
from .elastic_dataset import STEP_NAMES, dataset as _dataset
from .snap_edge import window_edge
from .snap_window import SNAP_FRACTION, snap_peaks, taut_peaks
from .elastic_model import STARTS, Elastic, ElasticLine
from .options import check_checkpoint_every, check_progress
from .elastic_rodas import RodasStepper
from .elastic_rodas_body import RodasBodyStepper
from .elastic_links_rodas import LinksStepper

__all__ = ["solve", "ElasticRun", "METHODS", "speed_floor"]

METHODS = {"radau": Radau, "dop853": DOP853, "rodas4": RodasStepper, "rodas4-links": LinksStepper}
#: intervals per step at whose interior points the dense output around each peak is sampled
PEAK_SAMPLES = 24
#: samples on either side of the dense output's best one whose states are integrated from the
#: step's start (:class:`_Peaks`)
PEAK_RESTEP = 1
#: an automatic run (no t_end) fails once its energy error exceeds this fraction of the line's
#: energy |E(0)| + |W| + U(0) (0.255 for chi = 0.25): the snap can no longer be told from the
#: error (measured, chi = 0.25, N = 30 and 60, c = 30-300, tol 1e-2 and 3e-3: Radau/RODAS4 runs
#: that reach the snap err by at most 0.04 of it; DOP853 at tol 1e-2, c = 100, by 0.76 at
#: t = 0.23, with a false snap there; Radau at tol 1e-2, N = 30, c = 300 by 0.15 at t = 1.75)
ENERGY_ERROR_FAIL = 0.1
#: RODAS4 (node and links, a body's too: :mod:`elastic_body_advance`, branch fastbody) runs its step loop
#: compiled (:func:`elastic_advance.advance`, ``advance_links``); False: the Python loop
#: below, one step a call (the reference the compiled loop equals, bit for bit)
COMPILED_LOOP = True
#: a compiled RODAS4 run (and a rodas4-links run of either loop) refines its peaks compiled
#: (:func:`elastic_refine.refine`, ``refine_segments``); False: :meth:`_Peaks.refine` on the
#: kept steps (the reference it equals, bit for bit)
COMPILED_REFINE = True


class ElasticRun:
    """Result of :func:`solve`: ``dataset`` (xarray), ``peaks`` (dict), ``state`` (the last
    state vector), ``line`` (the :class:`ElasticLine`)."""

    def __init__(self, dataset, peaks, state, line):
        self.dataset, self.peaks, self.state, self.line = dataset, peaks, state, line

    def summary(self) -> dict:
        """Inputs and results as plain Python values."""
        out = {}
        for k, v in self.dataset.attrs.items():
            out[k] = v.item() if isinstance(v, np.generic) else v
        return out


def _record(line, t, z, dt, mm):
    """One row of STEP_NAMES from the measures ``mm`` of the state ``z`` at ``t``."""
    s_node = np.concatenate([line.snode, [0.0]])
    s_link = line.snode - 0.5 * line.h
    W, D = z[4 * line.N], z[4 * line.N + 1]
    return [dt, mm[0], mm[2], mm[4], s_node[int(mm[1])], s_node[int(mm[3])], s_link[int(mm[5])], mm[6], mm[8], mm[9],
            mm[10], mm[11], mm[12] + mm[13] + mm[14], mm[14], W, D, mm[15], mm[16], mm[17], s_node[int(mm[18])],
            mm[19]]


class _Peaks:
    """The running maxima of v_max, a_max, sigma_max over accepted steps, keeping the steps on
    either side of each (start time and state, end time, dense output), to refine them
    afterwards.

    The dense output only guides the refinement: it is sampled at ``PEAK_SAMPLES - 1`` interior
    times of each kept step, and the state at its best sample and the ``PEAK_RESTEP`` samples on
    either side is integrated from the step's start by the run's own method and tolerance
    (``restep``); the peak is the largest of those and of the step ends. The dense output's own
    values are not used: it (RODAS4's and Radau's are of order 3) carries an error along the
    links of about the tolerance, which the tension ``EA e`` and a node's acceleration
    (``EA/(h m)`` times a length error) multiply by up to ``2 c^2 N^2``. At chi 0.25, N = 100,
    c = 10000, tol 1e-7 (RODAS4) that raised a_peak by 8.5e-5 (relative) above the states the
    steps reach: the "plateau" of a_peak as EA -> infinity (``benchmarks/elastic_ea_limit.py``)."""

    COLS = {"v": 0, "a": 2, "sigma": 4}

    #: the approach kind (branch stretchapp): kappa_max_interior where v_max is at its running peak
    #: (``kappa_peak_approach``), kept and refined apart (:meth:`refine_approach`)
    APPROACH = {"kappa_approach": ERF.KIN}

    def __init__(self):
        kinds = {**self.COLS, **self.APPROACH}
        self.best = {k: (-np.inf, 0.0) for k in kinds}
        self.keep = {k: [] for k in kinds}
        self.after = dict.fromkeys(kinds, False)
        self.prev = None
        self.run = None  # (a compiled RODAS4 run whose kept steps elastic_refine.refine refines)

    def update(self, t, mm, seg):
        """Record the accepted step ``seg = (t_old, y_old, t, dense)`` (None for the initial
        state) ending at ``t`` with the measures ``mm``."""
        for k, c in {**self.COLS, **self.APPROACH}.items():
            q = mm[c] if k in self.COLS or mm[0] >= self.best["v"][0] else -np.inf
            if self.after[k] and seg is not None:
                self.keep[k].append(seg)
                self.after[k] = False
            if q > self.best[k][0]:
                self.best[k] = (float(q), float(t))
                self.keep[k] = [d for d in (self.prev, seg) if d is not None]
                self.after[k] = True
        self.prev = seg

    def refine_approach(self, line, restep):
        """:meth:`refine` of the approach kind alone (its own integrations: the others' unchanged):
        (value, time), (NaN, NaN) without one."""
        if not self.best["kappa_approach"][0] > -np.inf:
            return (np.nan, np.nan)
        return self.refine(line, restep, self.APPROACH)["kappa_approach"]

    def refine(self, line, restep, kinds=None):
        """The refined peaks {name: (value, time)}; ``restep(t0, y0, t1)`` the state at ``t1``
        integrated from ``(t0, y0)`` (None if that fails: the sample is left out)."""
        out = {}
        cache = {}
        for k, c in (self.COLS if kinds is None else kinds).items():
            val, tp = self.best[k]
            guide, gval = None, -np.inf
            for seg in self.keep[k]:
                grid = np.linspace(seg[0], seg[2], PEAK_SAMPLES + 1)
                for i in range(1, PEAK_SAMPLES):
                    m = line.measure(grid[i], seg[3](grid[i]))[c]
                    if m > gval:
                        guide, gval = (seg, grid, i), m
            if guide is None:
                out[k] = (val, tp)
                continue
            (t_old, y_old, _, _), grid, i = guide
            for j in range(max(1, i - PEAK_RESTEP), min(PEAK_SAMPLES - 1, i + PEAK_RESTEP) + 1):
                key = (t_old, j)
                if key not in cache:
                    y = restep(t_old, y_old, grid[j])
                    cache[key] = None if y is None else line.measure(grid[j], y)
                mm = cache[key]
                if mm is not None and mm[c] > val:
                    val, tp = float(mm[c]), float(grid[j])
            out[k] = (val, tp)
        return out


def speed_floor(elastic_energy: float, m_min: float, stop_fraction: float) -> float:
    """The running peak of v_max above which the stop rule may judge the snap.

    The release puts the start's elastic energy ``E_r`` into motion the inextensible fall does
    not have (the longitudinal ringing); it can give a node of mass >= ``m_min`` at most
    ``v_r = sqrt(2 E_r / m_min)``. With the
    fall's own largest speed V(t) nondecreasing before the snap (the rigid chain's stop rule
    rests on that) and ``V - v_r <= v_max <= V + v_r``, a peak ``P >= 2 v_r / (1 - f)``
    (``f = stop_fraction``) gives ``V >= P - v_r >= v_r (1 + f)/(1 - f)`` from then on, hence
    ``v_max >= V - v_r >= f (V + v_r) >= f P`` until the fall's own speed drops: only the
    snap can take v_max below ``f P``. (The integration's energy error is judged apart: see
    ``ENERGY_ERROR_FAIL``.)

    >>> float(round(speed_floor(0.005, 0.01, 0.5), 6))
    4.0
    """
    return 2.0 * np.sqrt(2.0 * elastic_energy / m_min) / (1.0 - stop_fraction)


_ENERGY_MSG = (f"energy error above {ENERGY_ERROR_FAIL:g} of the line's energy (the steps do not resolve the "
               "motion: tighten tol)")


def _snapshot(ts, t_old, y_old, t, y, restep, dense):
    """The state at ``ts`` in the step ``(t_old, y_old) -> (t, y)``: a step end, or the state
    integrated from the step's start (``restep``), not the dense output (see :class:`_Peaks`);
    ``dense()`` only if that integration fails."""
    if ts >= t:
        return y.copy()
    if ts <= t_old:
        return y_old.copy()
    zs = restep(t_old, y_old, ts)
    return zs if zs is not None else dense()(ts)


def _run_rodas(solver, line, mm0, snaps, snap_t, snap_z, snap_kind, peaks, peak_state, stop_reason, restep, bar=None,
               state=None, poll=None, **kw):
    """The step loop of :func:`solve` for RODAS4, compiled (:func:`elastic_advance.advance`:
    the same bookkeeping, many steps a call; with a progress ``bar``, calls of about
    :data:`elastic_progress.CHUNK_SECONDS`, the bar moved after each). Returns the record rows
    (t first), the running peak's state, the first slack time, when the stop rule was armed,
    status and reason; the snapshots and the peaks' kept steps (refined by
    :meth:`_Peaks.refine`) are filled in."""
    Run = EA.LinksRun if isinstance(solver, LinksStepper) else EBA.BodyRun if line.body is not None else EA.RodasRun
    run = Run(solver, mm0, energy_fail=ENERGY_ERROR_FAIL, **kw)
    if state is not None:  # (a resumed run: elastic_checkpoint)
        run.restore(state)
    chunks, status = [], "completed"
    sizes, nsteps = EP.Chunks(bar, run.rec.shape[0], short=poll is not None), 0
    while True:
        code = run.advance(snaps[0] if snaps else np.inf, sizes.start())
        chunks.append(run.drain())
        sizes.done(len(chunks[-1]))
        if bar is not None and len(chunks[-1]):
            nsteps += len(chunks[-1])
            last = chunks[-1][-1]
            EP.show(bar, float(last[0]), nsteps, solver.nrej, float(last[2]), float(last[1]))
        if code == EA.R_STEP_FAILED:
            status, stop_reason = "failed", f"step failed: step size {solver.ctl[ER.C_HFAIL]:.3g} too small at " \
                f"t = {solver.t:.9g}"
            break
        t, dense = solver.t, None
        while snaps and snaps[0] <= t:
            ts = snaps.pop(0)
            if ts >= 0.0:
                dense = dense or run.last_dense()
                snap_t.append(ts)
                snap_z.append(_snapshot(ts, dense.t_old, run.last_start(), t, solver.y, restep, lambda: dense))
                snap_kind.append("requested")
        if code in (EA.R_SNAPSHOT, EA.R_BUFFER):
            if poll is not None:  # checkpoints and signals, at a step boundary (may raise RunInterrupted)
                poll(run, chunks)
            continue
        if code == EA.R_SNAP:
            stop_reason = "snap"
        elif code == EA.R_NONFINITE:
            status, stop_reason = "failed", "non-finite state"
        elif code == EA.R_MAXRHS:
            status, stop_reason = "failed", f"more than max_rhs={kw['max_rhs']} right-hand-side evaluations"
        elif code == EA.R_ENERGY:
            status, stop_reason = "failed", _ENERGY_MSG
        break
    if COMPILED_REFINE and line.body is None:  # (a body's peaks: _Peaks.refine with its stepper)
        peaks.run = run
    else:
        for k, (val, tp, segs) in zip({**peaks.COLS, **peaks.APPROACH}, run.segments().values()):
            peaks.best[k], peaks.keep[k] = (val, tp), segs
    sc = run.sctl
    if sc[EA.S_RUN] > 0.0:
        peak_state = (float(sc[EA.S_PEAKT]), run.peak_z.copy())
    return np.concatenate(chunks), peak_state, float(sc[EA.S_SLACK]), float(sc[EA.S_ARMED]), status, stop_reason


def solve(problem, elastic: Elastic, *, t_end: float | None = None, tol: float = 1e-8, method: str = "radau",
          start: str = "stretched", initial=None, stop_fraction: float = 0.5, t_end_max: float = 10.0,
          snapshot_times=(), max_rhs: int = 50_000_000, stop_floor: float | None = None,
          progress: bool | None = False, checkpoint=None, checkpoint_every: float | None = None,
          resume=None, compression: bool | None = None) -> ElasticRun:
    """Integrate the elastic line of ``problem`` made of ``elastic`` links.

    Parameters
    ----------
    problem : Problem
        Links (rest lengths, masses, tip mass), start, held end's motion, gravity.
    elastic : Elastic
        Axial stiffness or table, Kelvin-Voigt damping.
    t_end : float, optional
        End time; by default the run stops at the snap, once v_max has fallen below
        ``stop_fraction`` of its running peak, that peak being above the noise floor of
        :func:`speed_floor` (or at ``t_end_max``; or, status 'failed', once the energy error
        exceeds 0.1 of the energy the line holds).
    tol : float
        Relative and absolute tolerance of the error control (rtol = atol).
    method : {"radau", "dop853", "rodas4", "rodas4-links"}
        scipy's Radau IIA (with the analytic banded Jacobian), explicit DOP853, or the compiled
        RODAS4 of :mod:`snapping.simulate.elastic_rodas` (exact banded Jacobian, O(N) a step;
        its tolerance is a max norm, Radau's and DOP853's an rms norm); ``"rodas4-links"`` the
        same RODAS4 in link coordinates (:mod:`snapping.simulate.elastic_links_rodas`: each
        link's length and angle, steps not capped by the wave speed c; its error measured in
        node values, so tol means the same; its loop compiled as RODAS4's).
    start : {"stretched", "unstretched", "matched"}
        See :mod:`snapping.simulate.elastic_model`: ``"stretched"`` the static equilibrium with
        both ends held, then released (its unloading wave rings); ``"matched"`` the start's
        shape stretched to the rigid chain's tensions after release (no release wave: the
        rigid chain's release as EA -> infinity); ``"unstretched"`` every link at its rest
        length. Recorded in the Dataset's ``start`` attribute; ignored when ``initial`` is given.
    initial : (x, y, vx, vy), optional
        Node values at t = 0 (N + 1 each, the last the held end's), any strains.
    snapshot_times : sequence of float
        Times of full profiles (besides t = 0, the peak of v_max and the end).
    max_rhs : int
        Right-hand-side evaluations after which the run stops (status 'failed').
    stop_floor : float, optional
        The running peak of v_max above which the stop rule judges the snap, instead of
        :func:`speed_floor`'s bound (which, from the lightest node's mass, can exceed the snap
        itself on fold-graded links: the run then goes on to ``t_end_max``).
    progress : bool or None
        A progress bar on stderr, as :func:`snapping.simulate.run`'s (None: the bar on a
        terminal, else a plain line every ~10 s; :mod:`snapping.simulate.elastic_progress`):
        ``t`` out of ``t_end`` or of the estimated snap, the steps and rejected steps taken.
        The run's numbers are the same with or without it.
    checkpoint : path, optional
        ``"rodas4"`` and ``"rodas4-links"`` only: the file (:mod:`snapping.simulate.elastic_checkpoint`)
        written on SIGINT or SIGTERM (status 'interrupted', then :class:`RunInterrupted` is
        raised, as by :func:`snapping.simulate.run`) and every ``checkpoint_every`` seconds of
        wall time (status 'checkpoint'; 0: at every return of the compiled loop, None: only
        when stopped). An existing file is refused unless it is ``resume``'s. It (and ``resume``)
        is locked while the run lasts (:func:`snapping._files.locked`: another process writing or
        resuming it gets :class:`snapping._files.OutputBusyError`, naming its PID). The run's
        numbers are the same with or without it.
    resume : path, optional
        A checkpoint of this run to continue (the same ``problem``, ``elastic`` and options:
        others are refused by name, as is a file whose digest fails); the result equals the
        uninterrupted run's, bit for bit (``wall_time`` aside: it adds up the sessions).
        Further checkpoints go to ``checkpoint``, by default this file.
    compression : bool, optional
        A body's (:mod:`snapping.simulate.elastic_body`: methods radau, dop853): whether a link
        shorter than its rest length pushes (a rod); None: when the body bends.

    Returns
    -------
    ElasticRun
    """
    line = ElasticLine(problem, elastic, compression=compression)
    tol = V.positive("tol", tol)
    if not 1e-13 <= tol <= 1e-2:
        raise V.SnappingInputError(f"tol={tol!r} is out of range: must lie in [1e-13, 1e-2]")
    if not isinstance(method, str) or method.lower() not in METHODS:
        raise V.SnappingInputError(f"method={method!r} is not one of {tuple(METHODS)} (the elastic line's methods)")
    method = method.lower()
    if t_end is not None:
        t_end = V.positive("t_end", t_end)
    t_end_max = V.positive("t_end_max", t_end_max)
    stop_fraction = V.real("stop_fraction", stop_fraction)
    if not 0.0 < stop_fraction < 1.0:
        raise V.SnappingInputError(f"stop_fraction={stop_fraction!r} is out of range: must lie in (0, 1)")
    if not isinstance(start, str) or start not in STARTS:
        raise V.SnappingInputError(f"start={start!r} is not one of {STARTS}")
    snaps = sorted(float(V.real("snapshot_times", s)) for s in np.atleast_1d(np.asarray(snapshot_times, float)))
    max_rhs = V.integer("max_rhs", max_rhs, 1)
    if stop_floor is not None:
        stop_floor = V.positive("stop_floor", stop_floor)
    progress = check_progress(progress)
    checkpoint_every = check_checkpoint_every(checkpoint_every)
    asked = [(k, v) for k, v in (("checkpoint", checkpoint), ("resume", resume), ("checkpoint_every", checkpoint_every))
             if v is not None]
    line.check_method(method, asked)  # (a body: its methods, and no checkpoint, before any file is looked at)
    if asked and (method not in ECK.METHODS or not COMPILED_LOOP):
        k, v = asked[0]
        raise V.SnappingInputError(f"{k}={str(v) if k != 'checkpoint_every' else v!r} with method={method!r}: only the "
                                   f"methods {ECK.METHODS} (compiled loop) keep checkpoints")
    checkpoint = resume if checkpoint is None else checkpoint
    if checkpoint_every is not None and checkpoint is None:
        raise V.SnappingInputError(f"checkpoint_every={checkpoint_every!r} needs a checkpoint file (checkpoint=PATH)")
    checkpoint, resume = ECK.check_paths(checkpoint, resume)
    inputs = {"N": line.N, "method": method, "tol": tol, "t_end": 0.0 if t_end is None else t_end,
              "stop_fraction": stop_fraction, "t_end_max": t_end_max, "start": start if initial is None else "initial",
              "model": "elastic", "elastic": json.dumps(elastic.describe(), sort_keys=True),
              "problem": problem.describe_json(), "chi": np.nan if problem.chi is None else float(problem.chi),
              "tip_mass": float(problem.links.tip_mass), "gravity": line.g, "pin_motion": problem.pin.kind}
    line.solve_inputs(method, inputs)  # (a body: its methods checked, "compression" recorded)
    with ECK.held(checkpoint, resume) if checkpoint is not None else contextlib.nullcontext():
        return _solve(line, problem, inputs, method=method, tol=tol, t_end=t_end, t_end_max=t_end_max,
                      stop_fraction=stop_fraction, start=start, initial=initial, snaps=snaps, max_rhs=max_rhs,
                      stop_floor=stop_floor, progress=progress, checkpoint=checkpoint,
                      checkpoint_every=checkpoint_every, resume=resume)


def _solve(line, problem, inputs, *, method, tol, t_end, t_end_max, stop_fraction, start, initial, snaps, max_rhs,
           stop_floor, progress, checkpoint, checkpoint_every, resume):
    """:func:`solve` once its inputs are checked (and its checkpoint files locked)."""
    wall0, wall_before = time.perf_counter(), 0.0
    z0 = EC.initial_state(line, start, initial)
    t_bound = t_end if t_end is not None else t_end_max
    count = [0]

    def fun(t, z):
        count[0] += 1
        return line.rhs(t, z)

    Rodas = RodasStepper if line.body is None else RodasBodyStepper  # (a body: elastic_rodas_body, elastic_body_advance)
    if method == "rodas4":
        solver = Rodas(line, 0.0, z0, t_bound, tol)
    elif method == "rodas4-links":
        solver = LinksStepper(line, 0.0, z0, t_bound, tol)
    else:
        kw = {"jac": line.jac} if method == "radau" else {}
        solver = METHODS[method](fun, 0.0, z0, t_bound, rtol=tol, atol=tol, **kw)

    mm0 = line.measure(0.0, z0)
    rows = [_record(line, 0.0, z0, 0.0, mm0)]
    times = [0.0]
    E0 = rows[0][STEP_NAMES.index("energy")]
    snap_t, snap_z, snap_kind = [0.0], [z0.copy()], ["initial"]
    peaks = _Peaks()
    peaks.update(0.0, mm0, None)
    running, stop_reason, status = 0.0, "t_end" if t_end is not None else "t_end_max", "completed"
    first_slack = np.nan
    i_en, i_w, i_d = (STEP_NAMES.index(k) for k in ("energy", "pin_work", "dissipated"))
    U0, m_min = float(rows[0][STEP_NAMES.index("elastic_energy")]), float(np.min(line.m))
    U0 -= 0.0 if line.body is None else line.body.bending_energy(0.0, z0)  # (the release's: not V_b, the shape's)
    err, t_armed, floor = 0.0, np.nan, speed_floor(U0, m_min, stop_fraction) if stop_floor is None else stop_floor
    peak_state = (0.0, z0.copy())
    t_prev, z_prev = 0.0, z0.copy()
    n_restep = [0]

    def restep(t0, y0, t1):  # the state at t1 integrated from (t0, y0) with the run's method and tol
        if method == "rodas4":
            st = Rodas(line, t0, y0, t1, tol, h0=t1 - t0)
        elif method == "rodas4-links":
            st = LinksStepper(line, t0, y0, t1, tol, h0=t1 - t0)
        else:
            kw = {"jac": line.jac} if method == "radau" else {}
            st = METHODS[method](line.rhs, t0, y0, t1, rtol=tol, atol=tol, first_step=t1 - t0, **kw)
        while st.status == "running":
            st.step()
        n_restep[0] += st.nfev
        return st.y if st.status == "finished" else None

    state = poll = sigs = None
    if checkpoint is not None:
        key = {**{k: repr(v) if isinstance(v, float) else v for k, v in inputs.items()}, "max_rhs": max_rhs,
               "snapshot_times": repr(snaps), "stop_floor": repr(floor), "initial": repr(z0.tolist())}
        if resume is not None:
            RunCls = EA.LinksRun if method == "rodas4-links" else EA.RodasRun
            got = ECK.read(resume, key, [f"stepper_{k}" for k in RunCls.STEPPER_STATE] + list(RunCls.RUN_STATE))
            if not np.array_equal(got["rows"][0], np.asarray(rows[0], float), equal_nan=True):
                raise V.SnappingInputError(f"resume={str(resume)!r}: its first recorded step is not the start its "
                                           "inputs give (the file was changed after it was written)")
            state, rows, times, wall_before = got["state"], got["rows"], got["times"], got["wall"]
            snap_t, snap_z, snap_kind = got["snap_t"], got["snap_z"], got["snap_kind"]
            snaps = [x for x in snaps if x > times[-1]]
            n_restep[0] = got["n_restep"]
        sigs = ECK.Signals()  # (between chunks: a due checkpoint, or a signal: save, raise RunInterrupted)
        poll = ECK.Poller(sigs, checkpoint_every, checkpoint, key, solver=solver, line=line, inputs=inputs, rows=rows,
                          times=times, snaps=(snap_t, snap_z, snap_kind), peak_state=peak_state, n_restep=n_restep,
                          wall_before=wall_before, wall0=wall0)

    bar = EP.open_run_bar(problem, method, t_end, progress)
    try:
        if method in ("rodas4", "rodas4-links") and COMPILED_LOOP:
            with sigs if sigs is not None else contextlib.nullcontext():  # (the signals noted, checkpointed runs)
                rec_steps, peak_state, first_slack, t_armed, status, stop_reason = _run_rodas(
                    solver, line, mm0, snaps, snap_t, snap_z, snap_kind, peaks, peak_state, stop_reason, restep,
                    t_end_given=t_end is not None, stop_fraction=stop_fraction, floor=floor, E0=E0, U0=U0,
                    max_rhs=max_rhs, bar=bar, state=state, poll=poll)
            rows = np.concatenate([np.asarray(rows, dtype=float), rec_steps[:, 1:]])  # (not through lists: 1 ms)
            times = np.concatenate([times, rec_steps[:, 0]])
        else:
            while solver.status == "running":
                msg = solver.step()
                if solver.status == "failed":
                    status, stop_reason = "failed", f"step failed: {msg}"
                    break
                t, z = float(solver.t), solver.y
                while snaps and snaps[0] <= t:
                    ts = snaps.pop(0)
                    if ts >= 0.0:
                        snap_t.append(ts)
                        snap_z.append(_snapshot(ts, t_prev, z_prev, t, z, restep, solver.dense_output))
                        snap_kind.append("requested")
                mm = line.measure(t, z)
                rows.append(_record(line, t, z, t - solver.t_old, mm))
                times.append(t)
                EP.show(bar, t, len(times) - 1, getattr(solver, "nrej", None), mm[0], t - solver.t_old)
                peaks.update(t, mm, (t_prev, z_prev, t, solver.dense_output()))
                t_prev, z_prev = t, z.copy()
                if mm[16] > 0 and np.isnan(first_slack):
                    first_slack = t
                if mm[0] > running:
                    running, peak_state = mm[0], (t, z.copy())
                if not np.all(np.isfinite(z)):
                    status, stop_reason = "failed", "non-finite state"
                    break
                if max(count[0], solver.nfev) > max_rhs:
                    status, stop_reason = "failed", f"more than max_rhs={max_rhs} right-hand-side evaluations"
                    break
                row = rows[-1]
                err = max(err, abs(row[i_en] - row[i_w] + row[i_d] - E0))
                if np.isnan(t_armed) and running >= floor:
                    t_armed = t
                if t_end is None and not np.isnan(t_armed) and mm[0] < stop_fraction * running:
                    stop_reason = "snap"
                    break
                if t_end is None and err > ENERGY_ERROR_FAIL * (abs(E0) + abs(row[i_w]) + U0):
                    status, stop_reason = "failed", _ENERGY_MSG
                    break
    finally:
        if bar is not None:
            bar.close()
    t_final = float(times[-1])
    zf = solver.y.copy()
    snap_t += [peak_state[0], t_final]
    snap_z += [peak_state[1], zf]
    snap_kind += ["peak", "final"]
    rec = np.asarray(rows, dtype=float)
    ref, app, n_app = refine_peaks(peaks, solver, method, line, restep, n_restep, samples=PEAK_SAMPLES,
                                   window=PEAK_RESTEP, compiled=COMPILED_REFINE)
    wall = wall_before + time.perf_counter() - wall0

    en = rec[:, STEP_NAMES.index("energy")] - rec[:, STEP_NAMES.index("pin_work")] + \
        rec[:, STEP_NAMES.index("dissipated")]
    isig = int(np.argmax(rec[:, 3]))
    slack_rows = np.flatnonzero(rec[:, STEP_NAMES.index("n_slack")] > 0)
    results = {
        "status": status, "stop_reason": stop_reason, "snap_reached": int(stop_reason == "snap"),
        "v_peak": ref["v"][0], "t_snap_v": ref["v"][1], "a_peak": ref["a"][0], "t_snap_a": ref["a"][1],
        "sigma_peak": ref["sigma"][0], "t_snap_sigma": ref["sigma"][1],
        "s_sigma_peak": float(rec[isig, STEP_NAMES.index("s_sigma_max")]),
        "strain_peak": float(rec[:, STEP_NAMES.index("strain_max")].max()),
        # the chain's kappa_peak: the largest curvature over the run (t = 0 and every accepted step)
        "kappa_peak": float(rec[:, STEP_NAMES.index("kappa_max")].max()),
        "kappa_max_0": float(rec[0, STEP_NAMES.index("kappa_max")]),
        # the chain's fifth peak: kappa_max_interior on the approach, refined between the steps as v/a/sigma
        "kappa_peak_approach": float(app[0]), "t_kappa_peak_approach": float(app[1]), "n_rhs_approach": int(n_app),
        "t_first_slack": float(first_slack), "n_slack_steps": int(slack_rows.size),
        "energy_initial": float(E0), "energy_drift": float(np.abs(en - en[0]).max()),
        "dissipated_total": float(rec[-1, STEP_NAMES.index("dissipated")]),
        "t_final": t_final, "n_steps": len(times) - 1, "n_rhs": int(solver.nfev) + n_restep[0],
        "n_jac": int(getattr(solver, "njev", 0)), "n_lu": int(getattr(solver, "nlu", 0)),
        "n_lu_pivoted": int(getattr(solver, "npiv", 0)),
        "dt_min_accepted": float(rec[1:, 0].min()) if len(times) > 1 else np.nan,
        "wall_time": wall, "wave_speed": line.wave_speed, "stop_speed_floor": float(floor),
        "t_stop_armed": float(t_armed),
    }
    edge = window_edge(times, rec[:, STEP_NAMES.index("v_max")], peak_state, ref["v"][0],
                       ERF.restep_call(solver, method, n_restep) or restep, line.measure, SNAP_FRACTION)
    snap = snap_peaks(times, rec[:, STEP_NAMES.index("v_max")],
                      {k: rec[:, STEP_NAMES.index(f"{k}_max")] for k in ("a", "sigma")}, ref, ref["v"][1],
                      edge=None if edge is None else (edge[0], edge[1], {"a": edge[2][2], "sigma": edge[2][4]}))
    results.update(a_peak_snap=snap["a"], sigma_peak_snap=snap["sigma"], t_snap_end=snap["t_snap_end"],
                   t_snap_edge=snap["t_snap_edge"], n_rhs=int(solver.nfev) + n_restep[0])
    taut = taut_peaks(times, rec[:, STEP_NAMES.index("v_max")], rec[:, STEP_NAMES.index("n_slack")],
                      {"sigma": rec[:, STEP_NAMES.index("sigma_max")]}, ref, ref["v"][1])
    if edge is not None and taut["t_taut_end"] == snap["t_snap_end"]:  # (the taut window is the 0.9 one: its end)
        taut["sigma"] = snap["sigma"]
    results.update(sigma_peak_taut=taut["sigma"], t_taut_end=taut["t_taut_end"])
    cols = {k: rec[:, STEP_NAMES.index(k)] for k in ("sigma_max", "dt", "n_slack", "sigma_min")}
    ring, ok, note = EC.peak_guard(np.asarray(times), cols, wave_speed=line.wave_speed, length=float(np.sum(line.h)),
                                   start=start if initial is None else "initial", t_snap_sigma=ref["sigma"][1],
                                   energy_drift=results["energy_drift"],
                                   energy_scale=abs(E0) + abs(float(rec[-1, i_w])) + U0)
    results.update(peak_ringing=ring, peaks_resolved=int(ok), peak_note=note)
    if not ok:
        results["status"] = "failed"  # stop_reason unchanged: peak_note says why
    ds = _dataset(line, np.asarray(times), rec, snap_t, snap_z, snap_kind, {**inputs, **results})
    return ElasticRun(ds, {k: {"value": v[0], "t": v[1]} for k, v in ref.items()}, zf, line)
