"""The elastic falling catenary of issue 22, this project's side, shared by the peer scripts
``moordyn_elastic.py`` and ``pyelastica_elastic.py``.

The problem (nondimensional: length L = 1, mass per length lambda = 1, g = 1, time
sqrt(L/g), force M g): the level catenary of end separation ``chi``, N equal links of rest
length 1/N, node masses ``Links.uniform(N, lumping="shared")`` (1/N, half at the free end),
every link a tension-only spring of axial stiffness EA = c^2 (c the longitudinal wave speed
in units of sqrt(g L)), no damping. Start: the stretched static equilibrium of the line
hanging between its two ends (:func:`start_nodes`: what :meth:`ElasticLine.start` with
``"stretched"`` computes, found here by shooting), at rest; at t = 0
the free end (node 0) is let go, the held end (node N, the origin) stays. y points down.

Peaks: the largest speed of any node (``v``; it is the free end's at the snap, checked in
each reference: ``s_v_max``) and the largest link tension (``sigma``), each with its time,
up to the snap: this project's run stops once the largest node speed has fallen below half
its running peak; the peers run to the same time as the reference (``Result.t_end``), so
that the tension peak is taken over the same window.

The reference of each (chi, N, c) is this project's run at a tight tolerance (``REF_TOL``,
DOP853), cached in ``elastic_reference.json`` beside this file (delete an entry to redo it;
the environment variable ``SNAPPING_PEERS_REFERENCE`` names another file).
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

#: the accuracy levels at which costs are compared (relative error of the peak speed)
LEVELS = (1e-2, 1e-3)
#: tolerance and method of the reference solve
REF_TOL, REF_METHOD = 1e-9, "dop853"
REF_FILE = os.environ.get("SNAPPING_PEERS_REFERENCE", os.path.join(HERE, "elastic_reference.json"))
#: this project's tolerances tried for the cost at matched accuracy (loosest first)
PROJECT_TOLS = (1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 1e-5, 1e-6)


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


def run_project(chi: float, N: int, c: float, tol: float, method: str = "radau") -> Result:
    from snapping.simulate.elastic import solve

    w = time.process_time()
    x, y = start_nodes(chi, N, c)
    z = np.zeros(N + 1)
    r = solve(problem(chi, N), elastic(c), tol=tol, method=method, initial=(x, y, z, z))
    w = time.process_time() - w
    a = r.dataset.attrs
    pk = r.peaks
    ds = r.dataset
    k = int(np.argmax(ds.v_max.values))
    extra = (f"steps={a['n_steps']} n_lu={a['n_lu']} status={a['status']} s_v_max={float(ds.s_v_max.values[k]):.3f} "
             f"slack_steps={a['n_slack_steps']} drift={a['energy_drift']:.1e}")
    return Result("snapping", N, c, f"tol={tol:g} ({method})", int(a["n_rhs"]), w, pk["v"]["value"], pk["v"]["t"],
                  pk["sigma"]["value"], pk["sigma"]["t"], extra, float(a["t_final"]))


def reference(chi: float, N: int, c: float, recompute: bool = False) -> Result:
    """This project's run at ``REF_TOL`` (cached in ``REF_FILE``)."""
    key = f"chi={chi:g},N={N},c={c:g},tol={REF_TOL:g},{REF_METHOD}"
    cache = {}
    if os.path.exists(REF_FILE):
        with open(REF_FILE) as fh:
            cache = json.load(fh)
    if key in cache and not recompute and "t_end" in cache[key]:
        return Result(**cache[key])
    r = run_project(chi, N, c, REF_TOL, REF_METHOD)
    if os.path.exists(REF_FILE):  # (another run may have added entries meanwhile)
        with open(REF_FILE) as fh:
            cache = json.load(fh)
    cache[key] = asdict(r)
    with open(REF_FILE, "w") as fh:
        json.dump(cache, fh, indent=1, sort_keys=True)
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


def project_rows(chi, N, c, ref: Result, levels=LEVELS, method="radau", tols=PROJECT_TOLS, budget=300.0):
    """This project at ``tols`` (loosest first) until each level is reached (or the CPU budget
    is spent): the cheapest tolerance that just reaches each level."""
    rows = []
    spent = 0.0
    for tol in tols:
        if spent > budget:
            print(f"  (snapping tol={tol:g} skipped: the budget of {budget:g} s is spent)")
            break
        r = run_project(chi, N, c, tol, method)
        spent += r.cpu
        score(r, ref)
        rows.append(r)
        if r.err <= min(levels) and len(rows) >= 2:
            break
    return rows


def score(r: Result, ref: Result) -> Result:
    r.err = abs(r.v_peak / ref.v_peak - 1.0)
    r.err_sigma = abs(r.sigma_peak / ref.sigma_peak - 1.0)
    return r


def header(ref: Result, chi: float) -> None:
    print(f"chi = {chi:g}, N = {ref.N}, c/sqrt(gL) = {ref.c:g} (EA = {ref.c ** 2:g} M g); reference: this project at "
          f"{ref.setting}: v peak {ref.v_peak:.8f} at t = {ref.t_v:.6f}, tension peak {ref.sigma_peak:.6f} at t = "
          f"{ref.t_sigma:.6f} ({ref.count} evaluations, {ref.cpu:.1f} s CPU; {ref.extra})")


def table(rows) -> None:
    print(f"  {'code':<11}{'N':>5}{'c':>5}  {'setting':<24}{'steps/evals':>12}{'cpu s':>9}{'v peak':>13}{'t_v':>9}"
          f"{'T peak':>11}{'t_T':>9}{'err v':>9}{'err T':>9}")
    for r in rows:
        print(f"  {r.code:<11}{r.N:>5}{r.c:>5g}  {r.setting:<24}{r.count:>12d}{r.cpu:>9.2f}{r.v_peak:>13.7f}"
              f"{r.t_v:>9.5f}{r.sigma_peak:>11.4f}{r.t_sigma:>9.5f}{r.err:>9.1e}{r.err_sigma:>9.1e}")


def matched(rows, peer: str, levels=LEVELS) -> None:
    """At each level: the cheapest run of each code within it and the speed-up."""
    for level in levels:
        best = {}
        for code in ("snapping", peer):
            ok = [r for r in rows if r.code == code and r.err <= level]
            best[code] = min(ok, key=lambda r: r.cpu) if ok else None
        a, b = best["snapping"], best[peer]
        if a and b:
            print(f"  at {level:g}: snapping {a.cpu:.2f} s ({a.setting}, {a.count} evaluations), {peer} {b.cpu:.2f} s "
                  f"({b.setting}, {b.count} steps): {peer}/snapping = {b.cpu / a.cpu:.3g}")
        else:
            who = " and ".join(c for c, r in best.items() if r is None)
            print(f"  at {level:g}: not reached by {who} within the runs above")


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
