"""The elastic falling catenary of issue 22, this project's side, shared by the peer scripts
``moordyn_elastic.py`` and ``pyelastica_elastic.py``.

The problem (nondimensional: length L = 1, mass per length lambda = 1, g = 1, time
sqrt(L/g), force M g): the level catenary of end separation ``chi``, N equal links of rest
length 1/N, node masses ``Links.uniform(N, lumping="shared")`` (1/N, half at the free end),
every link a tension-only spring of axial stiffness EA = c^2 (c the longitudinal wave speed
in units of sqrt(g L)), no damping. Start (``start``, :data:`STARTS`), at rest:

* ``"stretched"``: the stretched static equilibrium of the line hanging between its two ends
  (:func:`start_nodes`: what :meth:`ElasticLine.start` with ``"stretched"`` computes, found
  here by shooting); the release launches an unloading wave that rings to the snap;
* ``"matched"``: :meth:`ElasticLine.start` with ``"matched"`` (branch ``elmatch``): each link
  stretched to the tension the rigid chain has just after release, so that no release wave
  is launched.

At t = 0 the free end (node 0) is let go, the held end (node N, the origin) stays. y points
down. Every code is given the same nodes, velocities, masses and EA (:func:`start_state`).

Peaks: the largest speed of any node (``v``; it is the free end's at the snap, checked in
each reference: ``s_v_max``) and the largest link tension (``sigma``), each with its time,
up to the snap: this project's run stops once the largest node speed has fallen below half
its running peak; the peers run to the same time as the reference (``Result.t_end``), so
that the tension peak is taken over the same window.

The reference of each (chi, N, c, start) is this project's run at two tolerances
(``REF_TOL`` and ten times it, ``REF_METHOD``); their difference, printed with the reference,
says to what accuracy the reference itself is established (a level below it is not
claimed). Each run is cached in ``elastic_reference.json`` beside this file, keyed by the
start (delete an entry to redo it; the environment variable ``SNAPPING_PEERS_REFERENCE``
names another file).

Accuracy: the relative error of the peak speed ``v`` (``err``) and of the peak tension
``sigma`` (``err_sigma``); :data:`CRITERION` says which decides "within eps" (``"v"``,
``"sigma"`` or ``"both"``; set by the scripts' ``--peak``).
"""

from __future__ import annotations

import json
import os
import sys
import time
from dataclasses import asdict, dataclass

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, os.pardir))  # (bench_simulate.print_machine)

#: the accuracy levels eps at which costs are compared (relative error of the peaks, CRITERION)
LEVELS = (1e-3, 1e-4)
#: which peak decides "within eps": "v" (the peak speed), "sigma" (the peak tension) or "both"
CRITERION = "v"
#: the starts every code can be given (see the module docstring)
STARTS = ("stretched", "matched")
#: tolerance and method of the reference solve
REF_TOL, REF_METHOD = 1e-9, "dop853"
REF_FILE = os.environ.get("SNAPPING_PEERS_REFERENCE", os.path.join(HERE, "elastic_reference.json"))
#: the reference's second, looser run: REF_TOL times this
REF_LOOSE = 10.0
#: this project's tolerances tried for the cost at matched accuracy (loosest first)
PROJECT_TOLS = (1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6)
_STATES: dict = {}


def problem(chi: float, N: int):
    from snapping.simulate.problem import Links, Problem

    return Problem.catenary(chi, links=Links.uniform(N, lumping="shared"))


def elastic(c: float):
    from snapping.simulate.elastic import Elastic

    return Elastic.from_wave_speed(c)


def line(chi: float, N: int, c: float):
    from snapping.simulate.elastic import ElasticLine

    return ElasticLine(problem(chi, N), elastic(c))


def start_nodes(chi: float, N: int, c: float):
    """(x, y) of the N + 1 nodes at t = 0 (node 0 the free end, node N the held end at the
    origin): the stretched static equilibrium between the problem's end nodes, the start every
    code is given.

    Found by shooting, not by ``ElasticLine.start("stretched")`` (whose Newton iteration does
    not converge at N = 400: see RESULTS.md): the tension of link j (from node j to j + 1) is
    the vector (H, V - sum of the weights of nodes 1 .. j), its length h_j (1 + |T_j|/EA_j)
    along it; the two unknowns (H, V) put node N at the held end (``scipy.optimize.root``, from
    the inextensible catenary's end tension). Every link is taut (the hanging line's tension
    is positive), so the linear law holds throughout."""
    from scipy.optimize import root

    p = problem(chi, N)
    h, m, ea = p.links.h, p.links.m, np.full(N, c * c)
    g = float(p.gravity)
    wsum = np.concatenate([[0.0], np.cumsum(m[1:N] * g)])  # weights of nodes 1 .. j, j = 0 .. N-1
    target = np.array([p.x[N] - p.x[0], p.y[N] - p.y[0]])

    def chords(hv):
        tx = np.full(N, hv[0])
        ty = hv[1] - wsum
        tn = np.hypot(tx, ty)
        f = h * (1.0 + tn / ea) / tn
        return tx * f, ty * f

    def miss(hv):
        dx, dy = chords(hv)
        return np.array([dx.sum(), dy.sum()]) - target

    d0 = np.array([p.x[1] - p.x[0], p.y[1] - p.y[0]]) / h[0]  # the catenary's first link
    a = 1.0  # the catenary's horizontal tension lambda g a, 2 a sinh(chi/(2a)) = 1
    for _ in range(100):
        a = 0.5 * chi / np.arcsinh(0.5 / a)
    guess = d0 * (a * g * float(m.sum() + m[0]) / abs(d0[0]))
    sol = root(miss, guess, method="hybr", options={"xtol": 1e-15})
    if np.abs(miss(sol.x)).max() > 1e-13:
        raise RuntimeError(f"start: shooting did not converge ({sol.message}; miss {np.abs(miss(sol.x)).max():.2e})")
    dx, dy = chords(sol.x)
    x = p.x[0] + np.concatenate([[0.0], np.cumsum(dx)])
    y = p.y[0] + np.concatenate([[0.0], np.cumsum(dy)])
    x[N], y[N] = p.x[N], p.y[N]
    return x, y


def start_state(chi: float, N: int, c: float, start: str = "stretched"):
    """(x, y, vx, vy) of the N + 1 nodes at t = 0 for ``start`` (:data:`STARTS`), the held end
    (node N) at the origin: what every code is given."""
    key = (chi, N, c, start)
    if key in _STATES:
        return tuple(a.copy() for a in _STATES[key])
    if start == "stretched":
        x, y = start_nodes(chi, N, c)
        z = np.zeros(N + 1)
        out = (x, y, z, z.copy())
    elif start == "matched":
        from snapping.simulate.elastic_model import STARTS as MODEL_STARTS

        if "matched" not in MODEL_STARTS:
            raise RuntimeError("start='matched' needs ElasticLine.start('matched') (branch elmatch); this "
                               f"checkout's starts are {MODEL_STARTS}")
        ln = line(chi, N, c)
        out = tuple(np.asarray(a, dtype=float).copy() for a in ln.unpack(ln.start("matched"), 0.0))
    else:
        raise ValueError(f"start={start!r} is not one of {STARTS}")
    _STATES[key] = out
    return tuple(a.copy() for a in out)


@dataclass
class Result:
    code: str
    N: int
    c: float
    setting: str  # "tol=... (method)" or "dt=..."
    count: int  # right-hand-side evaluations (project), steps (peers)
    cpu: float  # CPU seconds of the whole run (setup included)
    v_peak: float
    t_v: float
    sigma_peak: float
    t_sigma: float
    extra: str = ""
    t_end: float = float("nan")  # where the run stopped (the peers run to the reference's)
    err: float = float("nan")  # |v_peak / v_ref - 1|
    err_sigma: float = float("nan")
    start: str = "stretched"
    agree_v: float = float("nan")  # (a reference) |v at REF_TOL / v at REF_LOOSE * REF_TOL - 1|
    agree_sigma: float = float("nan")
    cpu_runs: tuple = ()  # every timing of the run (``cpu`` is their least: repeats, elastic_table.py)


def run_project(chi: float, N: int, c: float, tol: float, method: str = "radau", start: str = "stretched") -> Result:
    from snapping.simulate.elastic import solve

    p, el, ini = problem(chi, N), elastic(c), start_state(chi, N, c, start)  # the given data: not timed
    w = time.process_time()
    r = solve(p, el, tol=tol, method=method, initial=ini)
    w = time.process_time() - w
    a = r.dataset.attrs
    pk = r.peaks
    ds = r.dataset
    k = int(np.argmax(ds.v_max.values))
    extra = (f"steps={a['n_steps']} n_lu={a['n_lu']} status={a['status']} s_v_max={float(ds.s_v_max.values[k]):.3f} "
             f"slack_steps={a['n_slack_steps']} drift={a['energy_drift']:.1e}")
    return Result("snapping", N, c, f"tol={tol:g} ({method})", int(a["n_rhs"]), w, pk["v"]["value"], pk["v"]["t"],
                  pk["sigma"]["value"], pk["sigma"]["t"], extra, float(a["t_final"]), start=start)


def _cached_run(chi, N, c, tol, method, start, recompute=False) -> Result:
    """This project at ``tol`` (cached in ``REF_FILE``; the stretched start's entries written
    before the start was a key are read too)."""
    key = f"chi={chi:g},N={N},c={c:g},start={start},tol={tol:g},{method}"
    legacy = f"chi={chi:g},N={N},c={c:g},tol={tol:g},{method}"
    cache = {}
    if os.path.exists(REF_FILE):
        with open(REF_FILE) as fh:
            cache = json.load(fh)
    for k in (key, legacy if start == "stretched" else None):
        if k in cache and not recompute and "t_end" in cache[k]:
            d = dict(cache[k])
            d["start"] = start
            return Result(**d)
    r = run_project(chi, N, c, tol, method, start)
    if os.path.exists(REF_FILE):  # (another run may have added entries meanwhile)
        with open(REF_FILE) as fh:
            cache = json.load(fh)
    cache[key] = asdict(r)
    with open(REF_FILE, "w") as fh:
        json.dump(cache, fh, indent=1, sort_keys=True)
    return r


def reference(chi: float, N: int, c: float, recompute: bool = False, start: str = "stretched") -> Result:
    """This project's run at ``REF_TOL`` (``REF_METHOD``), with ``agree_v`` / ``agree_sigma``
    its peaks' relative differences from the run at ``REF_LOOSE * REF_TOL``: the accuracy to
    which the reference is established (both runs cached in ``REF_FILE``)."""
    r = _cached_run(chi, N, c, REF_TOL, REF_METHOD, start, recompute)
    loose = _cached_run(chi, N, c, REF_LOOSE * REF_TOL, REF_METHOD, start, recompute)
    r.agree_v = abs(loose.v_peak / r.v_peak - 1.0)
    r.agree_sigma = abs(loose.sigma_peak / r.sigma_peak - 1.0)
    r.cpu_loose, r.count_loose = loose.cpu, loose.count
    return r


def vertex(t, v):
    """Largest value of the samples v(t) and its time: the vertex of the parabola through the
    three samples around the largest (the sample itself at either end)."""
    t, v = np.asarray(t, dtype=float), np.asarray(v, dtype=float)
    k = int(np.argmax(v))
    if k == 0 or k == v.size - 1:
        return float(v[k]), float(t[k])
    c2, c1, c0 = np.polyfit(t[k - 1:k + 2] - t[k], v[k - 1:k + 2], 2)
    if c2 >= 0.0:
        return float(v[k]), float(t[k])
    tv = -c1 / (2.0 * c2)
    return float(c0 - c1 * c1 / (4.0 * c2)), float(t[k] + tv)


#: codes whose tension output is not a link's: MoorDyn's ``GetLineMaxTen`` is the largest node
#: tension, the mean of the two segments' at an inner node (MoorDyn's ``Line::getNodeTen``), 2e-3
#: below the largest segment's at N = 100, c = 30 (matched start); "both" judges them by v alone
NODE_AVERAGED = ("MoorDyn",)


def error(r: Result, criterion: str | None = None) -> float:
    """The relative error that decides "within eps": the peak speed's, the peak tension's or the
    larger of the two (``criterion``, default :data:`CRITERION`; "both" is v alone for the
    codes of :data:`NODE_AVERAGED`)."""
    crit = CRITERION if criterion is None else criterion
    if crit == "v" or (crit == "both" and r.code in NODE_AVERAGED):
        return r.err
    if crit == "sigma":
        return r.err_sigma
    return max(r.err, r.err_sigma)


def project_rows(chi, N, c, ref: Result, levels=LEVELS, method="radau", tols=PROJECT_TOLS, budget=300.0,
                 start="stretched"):
    """This project at ``tols`` (loosest first) with each method of ``method`` (a name or a
    comma-separated list) until the finest level is reached (or the CPU budget is spent)."""
    rows = []
    for meth in str(method).split(","):
        spent = 0.0
        for tol in tols:
            if spent > budget:
                print(f"  (snapping tol={tol:g} ({meth}) skipped: the budget of {budget:g} s is spent)")
                break
            r = run_project(chi, N, c, tol, meth, start)
            spent += r.cpu
            score(r, ref)
            rows.append(r)
            if error(r) <= min(levels):
                break
    return rows


def score(r: Result, ref: Result) -> Result:
    r.err = abs(r.v_peak / ref.v_peak - 1.0)
    r.err_sigma = abs(r.sigma_peak / ref.sigma_peak - 1.0)
    return r


def header(ref: Result, chi: float) -> None:
    print(f"chi = {chi:g}, N = {ref.N}, c/sqrt(gL) = {ref.c:g} (EA = {ref.c ** 2:g} M g), start {ref.start}; "
          f"reference: this project at {ref.setting}: v peak {ref.v_peak:.8f} at t = {ref.t_v:.6f}, tension peak "
          f"{ref.sigma_peak:.6f} at t = {ref.t_sigma:.6f} ({ref.count} evaluations, {ref.cpu:.1f} s CPU; {ref.extra})")
    print(f"  reference established to: v {ref.agree_v:.1e}, sigma {ref.agree_sigma:.1e} (against tol "
          f"{REF_LOOSE * REF_TOL:g}); peaks judged by {CRITERION!r}")


def table(rows) -> None:
    print(f"  {'code':<11}{'N':>5}{'c':>5}  {'setting':<24}{'steps/evals':>12}{'cpu s':>9}{'v peak':>13}{'t_v':>9}"
          f"{'T peak':>11}{'t_T':>9}{'err v':>9}{'err T':>9}")
    for r in rows:
        print(f"  {r.code:<11}{r.N:>5}{r.c:>5g}  {r.setting:<24}{r.count:>12d}{r.cpu:>9.2f}{r.v_peak:>13.7f}"
              f"{r.t_v:>9.5f}{r.sigma_peak:>11.4f}{r.t_sigma:>9.5f}{r.err:>9.1e}{r.err_sigma:>9.1e}")


def ladder_of(r: Result) -> str:
    """The ladder a run belongs to: the code and its method or scheme ('snapping dop853',
    'MoorDyn rk2', 'PyElastica')."""
    if r.code == "snapping":
        return "snapping " + r.setting.split("(")[-1].rstrip(")")
    if r.code == "MoorDyn":
        return "MoorDyn " + r.setting.split()[0]
    return r.code


def fineness(r: Result) -> float:
    """How fine a run's setting is: 1/tol (this project), 1/dt (the peers)."""
    for word in r.setting.replace("(", " ").split():
        if word.startswith(("tol=", "dt=")):
            return 1.0 / float(word.split("=")[1])
    return float(r.count)


def cheapest(rows, code: str, level: float, criterion: str | None = None):
    """The run of ``code`` (a name, or a prefix such as 'MoorDyn') of least CPU time that is
    within ``level``, and so is every finer run of its ladder (:func:`ladder_of`, a smaller
    tolerance or step: :func:`fineness`): a run within it by chance, with finer ones outside,
    does not count. None if none."""
    ok = []
    mine = [r for r in rows if r.code.startswith(code)]
    for r in mine:
        same = [q for q in mine if ladder_of(q) == ladder_of(r) and fineness(q) >= fineness(r)]
        if all(error(q, criterion) <= level for q in same):
            ok.append(r)
    return min(ok, key=lambda r: r.cpu) if ok else None


def matched(rows, peer: str, levels=LEVELS, target: float = 10.0, ref: Result | None = None) -> None:
    """At each level: the cheapest run of each code within it, the speed-up, and whether it is
    at least ``target``."""
    for level in levels:
        a, b = cheapest(rows, "snapping", level), cheapest(rows, peer, level)
        note = ""
        if ref is not None and level < max(ref.agree_v if CRITERION == "v" else
                                           ref.agree_sigma if CRITERION == "sigma" else
                                           max(ref.agree_v, ref.agree_sigma), 0.0):
            note = " (below the reference's own agreement: not established)"
        if a and b:
            q = b.cpu / a.cpu
            print(f"  at {level:g}: snapping {a.cpu:.2f} s ({a.setting}, {a.count} evaluations), {peer} {b.cpu:.2f} s "
                  f"({b.setting}, {b.count} steps): {peer}/snapping = {q:.3g} ({'>=' if q >= target else '<'}"
                  f" {target:g}x){note}")
        else:
            who = " and ".join(n for n, r in (("snapping", a), (peer, b)) if r is None)
            print(f"  at {level:g}: not reached by {who} within the runs above{note}")


def add_arguments(ap, peer: str) -> None:
    """The options every elastic peers script shares (the line, this project's side, the
    reference and the accuracy levels); ``peer`` names the other code in the help."""
    ap.add_argument("--chi", type=float, default=0.25, help="end separation / length (default 0.25)")
    ap.add_argument("--N", default="100", help="links, comma-separated (default 100)")
    ap.add_argument("--c", default="30", help="wave speeds c/sqrt(gL), comma-separated (default 30)")
    ap.add_argument("--method", default="dop853,rodas4",
                    help="this project's methods, comma-separated (names of elastic.METHODS; default dop853,rodas4)")
    ap.add_argument("--start", default="stretched", choices=STARTS,
                    help="the start every code is given (default stretched; matched: no release wave)")
    ap.add_argument("--peak", default="v", choices=("v", "sigma", "both"),
                    help="which peak decides 'within eps': the speed, the tension or both (default v)")
    ap.add_argument("--levels", default=",".join(f"{x:g}" for x in LEVELS),
                    help="the accuracy levels eps, comma-separated (default 1e-3,1e-4)")
    ap.add_argument("--ref-method", default=REF_METHOD, help=f"the reference's method (default {REF_METHOD})")
    ap.add_argument("--tols", default=",".join(f"{t:g}" for t in PROJECT_TOLS),
                    help="this project's tolerances, loosest first (stops once the finest level is reached)")
    ap.add_argument("--budget", type=float, default=300.0, help=f"CPU seconds for {peer} per point (default 300)")
    ap.add_argument("--ref-tol", type=float, default=REF_TOL,
                    help=f"tolerance of the reference run (default {REF_TOL:g}; cached per tolerance)")
    ap.add_argument("--no-reference", action="store_true",
                    help="the peer's runs only (no reference, no runs of this project; the peer stops at its snap)")


def apply_arguments(a):
    """Set the module's reference and accuracy settings from :func:`add_arguments`' options;
    returns (the N, the c, this project's tolerances) as lists."""
    global REF_TOL, REF_METHOD, CRITERION, LEVELS
    REF_TOL, REF_METHOD, CRITERION = a.ref_tol, a.ref_method.lower(), a.peak
    LEVELS = tuple(sorted((float(x) for x in a.levels.split(",") if x), reverse=True))
    return ([int(x) for x in a.N.split(",") if x], [float(x) for x in a.c.split(",") if x],
            [float(x) for x in a.tols.split(",") if x])


def machine(peer_pkg: str) -> None:
    try:
        from bench_simulate import print_machine

        print_machine()
    except ImportError:  # pragma: no cover
        print(f"machine: {os.uname().nodename}, load {os.getloadavg()[0]:.2f}\n")
    try:
        from importlib.metadata import version

        print(f"  {peer_pkg:<14} {version(peer_pkg)}\n")
    except Exception:
        print(f"  {peer_pkg:<14} not installed\n")
    print(f"uptime: {os.popen('uptime').read().strip()}\n", flush=True)
