"""The driver: one loop for every method (stop rules, progress, signals, checkpoints,
recording into the run Dataset, failures), and the entry points :func:`run` and
:func:`rerun`. Continuing a run from its checkpoint file (``resume``,
``is_resumable``) is :mod:`snapping.simulate.resuming`, which hands the restored engine
back to this loop.

What is solved is a :class:`snapping.simulate.problem.Problem` (or the paper's
``(chi, N)``); how it is stepped is a method of :data:`snapping.simulate.methods.METHODS`
(an engine: the compiled step loop and its state); the options every method shares are
one validated :class:`snapping.simulate.options.RunOptions`. The driver calls the
engine's ``loop(bar, poll)`` and, at every return of the compiled loop, polls for
signals and due checkpoints; at the end it builds the Dataset
(:func:`snapping.simulate.dataset.build_dataset`) and saves it.
"""

from __future__ import annotations

import signal
import threading
import time

import numpy as np
import xarray as xr

from .. import _files
from .. import _validate as V
from ..estimates import check_chi
from . import kernels as K
from . import methods as M
from .chain import ChainState
from .dataset import Run, build_dataset, check_writable, inputs_from_attrs, save, seal
from .errors import FAILURES, RET_SIGNAL, RunInterrupted, SimulationError, deliver_late
from .options import RunOptions, check_checkpoint_every, check_memory, check_progress

__all__ = ["run", "rerun", "check_inputs", "integrate_fixed", "METHODS", "CHECKPOINT_EVERY", "DEFAULT_METHOD",
           "DEFAULT_CHORDS", "default_tol"]

#: the method names :func:`run` takes (the table: :data:`snapping.simulate.methods.METHODS`)
METHODS = M.NAMES
#: the default method of :func:`run` (and of ``snapping simulate``/``sweep``): the project's
#: fast exact method (link angles, links exact to round-off); the paper's Euler-Richardson
#: scheme is ``method="euler-richardson"`` (what ``snapping reproduce`` uses)
DEFAULT_METHOD = "fast"
#: the default initial chain of :func:`run`: nodes on the catenary with chords exactly 1/N
#: (the paper's chain, nodes at equal arclength, is ``chords="arclength"``)
DEFAULT_CHORDS = "exact"
#: default wall-clock seconds between checkpoints of a run with an output file
CHECKPOINT_EVERY = 300.0
#: layout version of the checkpoint variables (schema.CHECKPOINT_VARS); 2: the control array
#: has the held end's breakpoints (39 entries) and the file carries its integrity digest; 3: the
#: measurements carry the minimum tension and its link (layout.M_SIGMIN, M_SSIGMIN)
CHECKPOINT_VERSION = 3
#: test hook: called with the engine after every return of the compiled loop; may
#: return a signal number to act as if that signal had arrived
_chunk_hook = None
def _resolve_problem(chi, N, chords, initial, problem, method):
    """(chi, N, chords, initial, problem) of a run given a Problem: the paper's problem
    becomes (chi, N, chords) (today's runs, bit for bit); a uniform chain with a fixed held
    end from another start becomes ``initial`` for Euler-Richardson; any other problem
    stays a problem, which only the angle-form methods take."""
    from .problem import Problem

    if isinstance(chi, Problem):
        if problem is not None:
            raise V.SnappingInputError("a Problem was given twice (as chi and as problem=)")
        chi, problem = None, chi
    if problem is None:
        return chi, N, DEFAULT_CHORDS if chords is None else chords, initial, None
    if not isinstance(problem, Problem):
        raise V.SnappingInputError(f"problem={type(problem).__name__} is not a snapping.simulate.Problem")
    if chi is not None:
        raise V.SnappingInputError(f"chi={chi!r} given with a Problem: the problem's start sets the shape")
    if initial is not None:
        raise V.SnappingInputError("initial= given with a Problem: the problem's start is the initial state")
    if chords is not None:
        raise V.SnappingInputError(f"chords={chords!r} given with a Problem: use Problem.catenary(chi, N, "
                                   f"chords={chords!r})")
    if N is not None and V.integer("N", N, 1) != problem.N:
        raise V.SnappingInputError(f"N={N!r} disagrees with the problem's {problem.N} links")
    if problem.is_paper:
        return problem.chi, problem.N, problem.chords, None, None
    if method in M.euler_richardson.NAMES:
        why = []
        if not problem.links.is_paper:
            why.append("links or masses other than N equal links and masses 1/N" if problem.links.tip_mass == 0
                       else f"a tip mass ({problem.links.tip_mass:g})")
        if not problem.pin.is_fixed:
            why.append(f"a moving held end (pin motion {problem.pin.kind!r})")
        if problem.gravity != 1.0:
            why.append(f"gravity={problem.gravity:g} (it takes g = 1)")
        if getattr(problem, "body", None) is not None:
            why.append("a body (bending stiffness, damping, drag or a clamped held end)")
        if why:
            raise V.SnappingInputError(f"method={method!r} takes only the paper's chain with a fixed held end and "
                                       f"g = 1; this problem has {', '.join(why)}: use method='fast' (dop853)")
        return (None, problem.N, problem.chords or DEFAULT_CHORDS,
                ChainState(problem.x, problem.y, problem.vx, problem.vy, 0.0), None)
    return None, problem.N, problem.chords or DEFAULT_CHORDS, None, problem


def _choose(method: str, problem, tol, t_end) -> tuple[str, str]:
    """The method a run takes and why (:func:`snapping.simulate.stiffness.choose`: ``fast``
    on a problem with bending is dop853 or rodas4; '' for every other run, which keeps its
    method), after the cost check of an explicit method named on a stiff problem
    (:func:`snapping.simulate.stiffness.check_cost`)."""
    if problem is None or getattr(problem, "body", None) is None:
        return method, ""
    from . import stiffness

    if M.resolve(method) != "dop853":
        return method, ""
    choice = ""
    if method == "fast":
        method, choice = stiffness.choose(problem, tol=1e-6 if tol is None else V.positive("tol", tol), t_end=t_end)
    if M.resolve(method) == "dop853":
        stiffness.check_cost(problem, "dop853", t_end=t_end)
    return method, choice


def default_tol(method: str) -> float:
    """The stepper tolerance a run of ``method`` takes when none is given: the method's
    ``DEFAULT_TOL`` (Euler-Richardson: the paper's 1e-8; ``fast``/dop853: chosen by
    ``benchmarks/bench_default_tol.py``, see ``docs/benchmarks/bench_default_tol.txt``).

    >>> default_tol("euler-richardson")
    1e-08
    """
    return float(M.method(method).DEFAULT_TOL)


def _validate_start(chi, N, method, chords, initial, problem):
    """(chi, N) of a run, and the method and chords checked."""
    if problem is not None:
        N = problem.N
        chi = float("nan")
    elif initial is None:
        chi = check_chi(chi)
        N = V.integer("N", N, 1)
    else:
        if not isinstance(initial, ChainState):
            raise V.SnappingInputError(f"initial={type(initial).__name__} must be a ChainState")
        if N is not None and V.integer("N", N, 1) != initial.N:
            raise V.SnappingInputError(f"N={N} does not match the initial state's N={initial.N}")
        N = initial.N
        chi = float("nan") if chi is None else check_chi(chi)
    if not isinstance(method, str) or method not in METHODS:
        raise V.SnappingInputError(f"method={method!r} is not one of {METHODS}")
    if chords is None and problem is not None:  # (a general problem's start holds its own nodes)
        return chi, N
    if not isinstance(chords, str) or chords not in ("arclength", "exact"):
        raise V.SnappingInputError(f"chords={chords!r} is not one of ('arclength', 'exact')")
    return chi, N


def _check_drag_jacobian(opts, method: str, asked: str | None = None) -> None:
    """SnappingInputError for ``drag_jacobian`` other than the default on a method without stage solves
    (``asked``: the method asked for; 'fast', what it steps this problem with is said)."""
    if opts.drag_jacobian != "banded" and method not in ("rodas4", "stiff"):
        how = (f"method='fast' steps this problem with {M.resolve(method)!r}: give method='rodas4' or"
               if "fast" in (asked, method) else f"this run's method is {method!r}:")
        raise V.SnappingInputError(f"drag_jacobian={opts.drag_jacobian!r} is an option of method='rodas4' (stiff) "
                                   f"only; {how} leave drag_jacobian='banded'")


def run(
    chi: float | None = None,
    N: int | None = None,
    *,
    tol: float | None = None,
    method: str = DEFAULT_METHOD,
    dt0: float | None = None,
    t_end: float | None = None,
    stop_fraction: float = 0.5,
    t_end_max: float = 10.0,
    snapshot_times=(),
    record_thin: float = 0.0,
    max_link_error: float = 1e-2,
    chords: str | None = None,
    initial: ChainState | None = None,
    output=None,
    progress: bool | None = False,
    max_energy_drift: float | None = None,
    dt_min: float = 1e-14,
    max_rejections: int = 100,
    drag_jacobian: str = "banded",
    checkpoint_every: float | None = CHECKPOINT_EVERY,
    problem=None,
    overwrite: bool = False,
) -> Run:
    """Simulate the falling chain released from the paper's catenary, to the snap and a bit after.

    The N-pendulum of the paper's appendix (eqs. (discretemo) and the tension
    system). By default (``method="fast"``, ``chords="exact"``) it is integrated in
    link angles, every link exactly 1/N to round-off, with the compiled Dormand-Prince
    8(5,3) method (:mod:`snapping.simulate.methods.dop853`), from the catenary sampled
    with chords exactly 1/N. The paper's own computation is
    ``run(chi, N, method="euler-richardson", chords="arclength")`` (what
    ``snapping reproduce`` runs): its Euler-Richardson scheme, half step, full step,
    error estimate eq. (error), dt_new = 0.9 dt (tol/eps)^(1/2) (eq. (dtau)), from nodes
    at equal arclength. Everything is nondimensional (length L, mass M, time
    sqrt(L/g), force M g).

    Euler-Richardson step rejection: a step is accepted when eps <= tol; otherwise it is retried
    from the same state with dt = 0.9 dt (tol/eps)^(1/2) (the same rule). The
    half-step evaluation alone decides, so a rejected step costs one evaluation
    and an accepted step two (the accelerations at the end of a step are those
    at the start of the next). Initial step: ``dt0 = sqrt(tol)`` unless given
    (eps ~ dt^2 max|a|/4 at rest, so this is accepted for max|a| ~ 1 and adapts
    from there); if eps = 0 exactly the step grows by ``ZERO_ERROR_GROWTH``.

    Stopping: with ``t_end`` the run ends at that time (the last step is clipped to
    land on it). Otherwise at the snap: the run stops once the maximum speed over
    the chain has fallen below ``stop_fraction`` of its running peak (the global
    peak of v_max), or at ``t_end_max`` at the latest.

    Recording: every accepted step (or, with ``record_thin > 0``, only steps where
    v_max, a_max, sigma_max or kappa_max changed by more than that fraction since
    the last recorded step; this keeps memory bounded and the record stays dense
    where things change fast, near the snap). The three steps around the peak of
    each of v_max, a_max, sigma_max, kappa_max are tracked densely regardless,
    and give the snapping times (vertex of the parabola through them).
    Snapshots of the full profiles: at t = 0, at the first step at or after each
    time in ``snapshot_times``, whenever v_max first reaches 1, 1.5, 1.5^2, ...
    (they pile up towards the snap), at the peak of v_max, when v_max falls to
    0.9 and 0.7 of the peak, and at the end.

    Parameters
    ----------
    chi : float or Problem
        Initial end separation / length, in (0, 1); or a
        :class:`snapping.simulate.problem.Problem` (any chain, start, held end, gravity).
    N : int
        Number of links, >= 1.
    problem : Problem, optional
        The problem to solve (the same as passing it as ``chi``): unequal links and
        masses, a tip mass, any start shape and velocities, a moving held end, any
        gravity. ``run(Problem.catenary(chi, N))`` is ``run(chi, N)``, bit for bit.
        Methods ``dop853``/``fast`` take every problem; ``euler-richardson`` only the
        paper's chain (N equal links and masses) with a fixed held end and g = 1.
    tol : float, optional
        Stepper tolerance (default: the method's ``DEFAULT_TOL``, :func:`default_tol`:
        Euler-Richardson the paper's eps_tol 1e-8; fast/dop853 1e-6, whose peaks agree
        with tol 1e-11 to 3e-8, measured by ``benchmarks/bench_default_tol.py``).
    method : {"fast", "dop853", "rodas4", "stiff", "euler-richardson", "euler-richardson-fixed"}
        ``fast`` (default): the project's best exact method (``dop853``, link angles; for
        a problem with a body whose damped bending waves make dop853 stiff, ``rodas4``:
        :mod:`snapping.simulate.stiffness`, the reason in the attribute ``method_choice``);
        ``rodas4``/``stiff``: linearly implicit, L-stable, for problems with a body;
        ``euler-richardson``: the paper's adaptive scheme (reference);
        ``euler-richardson-fixed``: the same step with fixed dt = dt0. An explicit method
        on a problem whose bending stiffness needs more than ~1e6 steps warns
        (:class:`snapping.simulate.stiffness.CostWarning`), more than 1e9 is refused.
    dt0 : float, optional
        Initial (fixed-mode: constant) time step.
    t_end : float, optional
        End time (> 0); default: stop automatically after the snap.
    stop_fraction : float
        Automatic stop when v_max < stop_fraction * peak, in (0, 1).
    t_end_max : float
        Hard end time of an automatic run.
    snapshot_times : sequence of float
        Extra snapshot times.
    record_thin : float
        Relative-change threshold of the thinned per-step record, in [0, 1).
    max_link_error : float
        The run fails when a link length is off from 1/N by more than this fraction
        plus the initial chord error ``link_error_initial``.
    chords : {"exact", "arclength"}, optional
        Initial node placement (see :func:`initial_state`): ``exact`` (default) chords
        exactly 1/N; ``arclength`` nodes at equal arclength (the paper's chain). Not
        with a Problem (``Problem.catenary(chi, N, chords=...)`` holds its own).
    initial : ChainState, optional
        Start from this state instead of the catenary (``chi`` then optional).
    output : path, optional
        Write the netCDF4 file here (the whole path checked before the run: a new
        path or, with ``overwrite``, an existing regular file; its directory, and
        room on its filesystem; locked against other writers while the run lasts;
        also written when the run fails or is interrupted; rules: :mod:`snapping._files`).
    overwrite : bool
        Replace ``output`` if it exists (default: refuse an existing file).
    progress : bool or None
        tqdm progress bar on stderr (None: the bar on a terminal, else a plain line every ~10 s,
        :mod:`snapping.simulate.progress_lines`).
    max_energy_drift : float, optional
        The run fails when |E(t) - E(0)| exceeds this (default: no bound).
    dt_min : float
        The run fails when the adaptive time step falls below this floor.
    max_rejections : int
        The run fails after more than this many consecutive rejected steps.
    drag_jacobian : {"banded", "correct"}
        ``method="rodas4"`` only: its stage solves use the banded Jacobian, which leaves air
        drag out (``"banded"``, the default), or correct each stage once for it (``"correct"``:
        ``J U`` by one difference of the right side, one evaluation and one banded solve more per
        stage; on drag-dominated lines far fewer steps, :mod:`snapping.simulate.rosenbrock`).
    checkpoint_every : float or None
        With ``output``: save the full state of the run to ``output`` (status
        'checkpoint', atomically) every this many seconds of wall time (0: at every
        return of the compiled loop; None: only when stopped). A checkpointed or
        interrupted file continues with :func:`resume` to the same Dataset, bit for bit.

    Returns
    -------
    Run
        ``.dataset`` (xarray.Dataset, schema in :mod:`snapping.schema`), ``.state``.

    Raises
    ------
    SnappingInputError
        Bad input, before anything runs; also a run whose record and snapshots
        would not fit in the available memory (see :func:`memory_need`).
    SimulationError
        A numerical failure, as one of its subclasses: :class:`NonFiniteError`
        (NaN/inf), :class:`StepSizeError` (dt below ``dt_min``), :class:`DriftError`
        (link drift past ``max_link_error``), :class:`EnergyDriftError` (past
        ``max_energy_drift``), :class:`RejectionError` (more than
        ``max_rejections`` consecutive rejections). It carries ``t``, ``step`` and
        the worst ``node``; what was computed is in ``exc.dataset`` (and in
        ``output``), status 'failed', ``stop_reason`` and ``failure`` saying why.
    RunInterrupted
        SIGINT or SIGTERM arrived: the run stopped at a step boundary and was saved
        (status 'interrupted') with its checkpoint; a ``KeyboardInterrupt``.

    Examples
    --------
    >>> r = run(0.5, 8, t_end=0.05)                       # fast (dop853), exact chords
    >>> ds = r.dataset
    >>> ds.attrs["status"], ds.attrs["method"], ds.attrs["chords"], int(ds.attrs["N"]), float(ds.t[-1])
    ('completed', 'dop853', 'exact', 8, 0.05)
    >>> bool(ds.attrs["energy_drift"] < 1e-9), bool(ds.attrs["link_drift"] < 1e-9)
    (True, True)
    >>> snap = run(0.5, 50).dataset.attrs                 # to shortly after the snap
    >>> round(snap["t_snap_v"], 3), snap["stop_reason"]   # (below the folded string's t* = 1.19814)
    (1.144, 'snap detected: v_max fell below 0.5 of its peak')
    >>> paper = run(0.5, 50, method="euler-richardson", chords="arclength").dataset.attrs  # the paper's
    >>> round(paper["t_snap_v"], 3)
    1.144
    """
    chi, N, chords, initial, problem = _resolve_problem(chi, N, chords, initial, problem, method)
    chi, N = _validate_start(chi, N, method, chords, initial, problem)
    asked = method
    method, choice = _choose(method, problem, tol, t_end)
    opts = RunOptions(tol=default_tol(method) if tol is None else tol, dt0=dt0, t_end=t_end, stop_fraction=stop_fraction, t_end_max=t_end_max,
                      snapshot_times=snapshot_times, record_thin=record_thin, max_link_error=max_link_error,
                      max_energy_drift=max_energy_drift, dt_min=dt_min, max_rejections=max_rejections,
                      drag_jacobian=drag_jacobian)
    _check_drag_jacobian(opts, method, asked)
    checkpoint_every = check_checkpoint_every(checkpoint_every)
    progress = check_progress(progress)
    method_ = M.method(method)
    opts = method_.complete(opts, method)
    need = check_memory(N, opts, chi=chi, method=method)
    if output is not None:
        output = check_writable(output, overwrite=overwrite, need_bytes=need["file_bytes"])
    inputs, eng = method_.setup(chi, N, method, opts, chords=chords, initial=initial, problem=problem)
    if choice:
        inputs["method_choice"] = choice
    return _drive(eng, inputs, output=output, progress=progress, checkpoint_every=checkpoint_every,
                  wall_before=0.0, overwrite=overwrite)


def check_inputs(chi=None, N=None, **options) -> dict:
    """Check the inputs of :func:`run` without running it (a sweep checks every run
    before the first starts); raises :class:`SnappingInputError` like :func:`run`, or
    returns the run's estimated needs (:func:`memory_need`, with ``file_bytes``, the
    run file's size).

    >>> check_inputs(0.3, 10, tol=-1.0)
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: tol=-1.0 is out of range: must be > 0
    """
    import inspect

    params = inspect.signature(run).parameters
    unknown = sorted(k for k in options if k not in params or k in ("chi", "N"))
    if unknown:
        raise V.SnappingInputError(f"unknown keywords {unknown} of simulate.run (valid: "
                                   f"{sorted(k for k in params if k not in ('chi', 'N'))})")
    kw = {k: p.default for k, p in params.items() if k not in ("chi", "N")}
    kw.update(options)
    chi, N, chords, initial, problem = _resolve_problem(chi, N, kw["chords"], kw["initial"], kw["problem"],
                                                        kw["method"])
    chi, N = _validate_start(chi, N, kw["method"], chords, initial, problem)
    asked = kw["method"]
    kw["method"], _ = _choose(kw["method"], problem, kw["tol"], kw["t_end"])
    if kw["tol"] is None:
        kw["tol"] = default_tol(kw["method"])
    opts = M.method(kw["method"]).complete(RunOptions.pick(kw), kw["method"])
    _check_drag_jacobian(opts, kw["method"], asked)
    check_checkpoint_every(kw["checkpoint_every"])
    check_progress(kw["progress"])
    need = check_memory(N, opts, chi=chi, method=kw["method"])
    if kw["output"] is not None:
        check_writable(kw["output"], overwrite=kw["overwrite"], need_bytes=need["file_bytes"])
    return need


# ---------------------------------------------------------------- the driver: signals, checkpoints, results
def _checkpoint_dataset(eng, inputs: dict, results: dict) -> xr.Dataset:
    ds = build_dataset(eng.records(), eng.snapshots_now(), eng.N, inputs, results)
    ds = ds.assign(eng.checkpoint_vars())
    ds.attrs.update({
        "checkpoint_version": CHECKPOINT_VERSION,
        "checkpoint_wall_time": float(results["wall_time"]),
        "checkpoint_link_error_initial": eng.link_error_initial,
        "checkpoint_time": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
    })
    return seal(ds)


def _resume_command(path) -> str:
    import shlex

    return f"snapping simulate --resume {shlex.quote(str(path))}"


def _drive(eng, inputs: dict, *, output, progress, checkpoint_every, wall_before: float, overwrite: bool) -> Run:
    """Run ``eng`` to its end, with progress bar, signal handling and checkpoints; build and save the result.

    With an ``output``, its lock is held from before the first step to after the last
    save, and the path is checked again under the lock (another process may have
    created it since the first check); every save of the run replaces its own file.
    """
    if output is None:
        return _drive_locked(eng, inputs, output=None, progress=progress, checkpoint_every=checkpoint_every,
                             wall_before=wall_before)
    with _files.locked(output):
        check_writable(output, overwrite=overwrite)
        return _drive_locked(eng, inputs, output=output, progress=progress, checkpoint_every=checkpoint_every,
                             wall_before=wall_before)


def expected_snap_time(inputs: dict) -> float | None:
    """A rough estimate of the snapping time of an automatic run (the progress bar's total,
    shown as an estimate): the folded string's t* = 2E(pi/4|2) = 1.19814
    (:data:`snapping.ideal.T_STAR`), which t*_chi approaches from below as chi -> 0 (1.194 at
    chi = 0.1, 1.175 at 0.25, 1.144 at 0.5), less a small correction for larger chi,
    t* - 0.25 chi^2 (within 1% at those three chi), floored at 0.5 t*. None for a start
    that is not the paper's catenary (a general problem or a given state): no estimate.

    >>> round(expected_snap_time({"chi": 0.1, "initial": "catenary"}), 3)
    1.196
    >>> expected_snap_time({"chi": float("nan"), "initial": "problem"}) is None
    True
    """
    from ..ideal import T_STAR

    chi = inputs.get("chi")
    if str(inputs.get("initial", "catenary")) != "catenary" or chi is None or not np.isfinite(chi):
        return None
    return float(max(T_STAR - 0.25 * chi ** 2, 0.5 * T_STAR))


def _drive_locked(eng, inputs: dict, *, output, progress, checkpoint_every, wall_before: float) -> Run:
    """:func:`_drive` once the output (if any) is locked and checked.

    ``eng`` is a method's engine (:data:`snapping.simulate.methods.METHODS`): each
    provides ``t``, ``n_steps``,
    ``loop(bar, poll)``, ``records()``, ``snapshots_now()``, ``checkpoint_vars()``,
    ``results(...)``, ``worst_node(code)``, ``failure_message(code, node)``,
    ``final_state()`` and ``link_error_initial``."""
    t_end = inputs["t_end"] or None
    N = eng.N
    from .progress_lines import open_bar

    expected = None if t_end else expected_snap_time(inputs)
    desc = f"chain N={N}" if M.method(inputs["method"]) is M.euler_richardson else f"chain N={N} ({inputs['method']})"
    bar = open_bar(desc, progress=progress, t_end=t_end, expected=expected, initial=eng.t,
                   line_desc=f"chain N={N} ({inputs['method']})")
    got = {"signum": None, "last": time.monotonic()}
    wall0 = time.perf_counter()

    def on_signal(signum, frame):
        got["signum"] = signum

    def poll():
        if _chunk_hook is not None:
            r = _chunk_hook(eng)
            if r:
                got["signum"] = int(r)
        if got["signum"] is not None:
            return RET_SIGNAL
        if output is not None and checkpoint_every is not None and time.monotonic() - got["last"] >= checkpoint_every:
            wall = wall_before + time.perf_counter() - wall0
            res = eng.results("checkpoint", f"running; checkpoint at t={eng.t:.9g}, step {eng.n_steps}; "
                              f"if the run was killed, continue with: {_resume_command(output)}", wall)
            save(_checkpoint_dataset(eng, inputs, res), output, overwrite=True)
            got["last"] = time.monotonic()
        return None

    handlers = {}
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            try:
                handlers[sig] = signal.signal(sig, on_signal)
            except (ValueError, OSError):  # pragma: no cover - exotic embedding
                pass
    try:
        status, reason, code = "completed", "", None
        try:
            code = eng.loop(bar, poll)
        except KeyboardInterrupt:  # no handler of ours (e.g. one raised by another handler)
            got["signum"] = signal.SIGINT
            code = RET_SIGNAL
        finally:
            wall = wall_before + time.perf_counter() - wall0
            if bar is not None:
                bar.close()
        failure, node = "", -1
        if code == RET_SIGNAL:
            status = "interrupted"
            try:
                name = signal.Signals(got["signum"]).name
            except ValueError:
                name = f"signal {got['signum']}"
            reason = f"interrupted by {name} at t={eng.t:.9g}, step {eng.n_steps}"
            if output is not None:
                reason += f"; continue with: {_resume_command(output)}"
            ds = _checkpoint_dataset(eng, inputs, eng.results(status, reason, wall))
            path = save(ds, output, overwrite=True) if output is not None else None
            raise RunInterrupted(f"{reason}" + (f" (saved in {path})" if path else " (not saved: no output file)"),
                                 int(got["signum"]), dataset=ds, path=path)
        if code == K.RET_STOP:
            reason = f"snap detected: v_max fell below {inputs['stop_fraction']:g} of its peak"
            settle = float(getattr(eng, "settle_time", -1.0))
            if settle >= 0.0:
                reason = (f"snap detected: the speed relative to the held end (settled at t={settle:.9g}) fell below "
                          f"{inputs['stop_fraction']:g} of its peak")
        elif code == K.RET_END:
            reason = "t_end reached" if t_end is not None else "t_end_max reached before the speed fell after a peak"
        else:
            status = "failed"
            node = eng.worst_node(code)
            reason = eng.failure_message(code, node)
            failure = FAILURES.get(code, SimulationError).kind
        ds = seal(build_dataset(eng.records(), eng.snapshots_now(), N, inputs,
                                   eng.results(status, reason, wall, failure, node)))
        final = eng.final_state() if status == "completed" else None
        path = save(ds, output, overwrite=True) if output is not None else None
    finally:
        for sig, h in handlers.items():
            signal.signal(sig, h)
    if got["signum"] is not None:  # noted after the loop's last poll or while the file was written: acted on now
        deliver_late(got["signum"])
    if status == "failed":
        where = f"; what was computed is saved in {path}" if path else ""
        cls = FAILURES.get(code, SimulationError)
        raise cls(f"simulation failed: {reason}{where}", dataset=ds, path=path, t=eng.t,
                  step=eng.n_steps, node=node)
    return Run(ds, final, path)


def rerun(ds: xr.Dataset, **overrides) -> Run:
    """Run again from a run Dataset's attributes (``run(**inputs_from_attrs(ds))``).

    Examples
    --------
    >>> r1 = run(0.5, 6, t_end=0.02)
    >>> r2 = rerun(r1.dataset)
    >>> bool((r1.dataset.v_max == r2.dataset.v_max).all())
    True
    """
    kw = inputs_from_attrs(ds)
    kw.update(overrides)
    return run(**kw)


def integrate_fixed(state: ChainState, dt: float, n_steps: int) -> ChainState:
    """Advance ``state`` by ``n_steps`` Euler-Richardson steps of fixed size ``dt``
    (no error control; for measuring the order of accuracy).

    >>> from snapping.simulate import initial_state
    >>> s = integrate_fixed(initial_state(0.5, 4), 1e-3, 10)
    >>> round(s.t, 12)
    0.01
    """
    if not isinstance(state, ChainState):
        raise V.SnappingInputError(f"state={type(state).__name__} is not a ChainState")
    dt = V.positive("dt", dt)
    n_steps = V.integer("n_steps", n_steps, 1)
    try:
        r = run(initial=state, method="euler-richardson-fixed", dt0=dt, t_end=state.t + n_steps * dt,
                max_link_error=0.5, progress=False)
    except V.SnappingInputError as exc:  # (t_end = t + n_steps dt: name what the user gave)
        raise V.SnappingInputError(f"dt={dt!r}, n_steps={n_steps}: {exc}") from None
    return r.state
