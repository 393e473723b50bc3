"""Benchmark and first science of the 3D chain (:mod:`snapping.spatial`).

1. Does the planar snap stay planar? The paper's catenary with an out-of-plane velocity
   ``eps sin(pi s/L)`` (s from the held end) added, run to the snap: the out-of-plane
   amplitude ``z_amp = max_j |z_j|`` and speed ``vz_amp = max_j |vz_j|`` at the speed peak,
   divided by eps, for eps = 1e-6, 1e-4, 1e-2 (equal ratios: linear growth), and the change
   of the peak speed from the planar run's (second order in eps if the snap is stable).
2. Cost at N = 1000, chi = 0.25, same tol: one evaluation of the 3D right-hand side against
   the planar one (the paper's uniform kernel and the general chain's), and a whole run of
   the perturbed 3D start against the planar run (``snapping.simulate.run``, ``fast``).
3. N = 10000 in 3D to the snap: time and peak memory (resident set).

Counts (evaluations, steps) are the primary measure; wall times depend on the machine's
load (printed).

Usage::

    python benchmarks/bench_chain3d.py                     # all three
    python benchmarks/bench_chain3d.py --parts growth --N 100,200,400 --chi 0.25,0.1
    python benchmarks/bench_chain3d.py --parts growth --N 200 --chi 0.25 --mode random --seed 1
    python benchmarks/bench_chain3d.py --parts cost,big --tol 1e-8
    python benchmarks/bench_chain3d.py --parts profile          # where a 3D step's time goes
"""

from __future__ import annotations

import argparse
import os
import resource
import time

import numpy as np


def _load() -> str:
    return "load %.2f %.2f %.2f" % os.getloadavg()


def growth(chis, Ns, epss, tol, mode="sin", seed=1):
    from snapping.spatial import Problem3D, run3d

    what = "eps sin(pi s/L)" if mode == "sin" else f"eps times random node values (seed {seed}, max 1)"
    print(f"# out-of-plane growth: velocity perturbation {what}, tol {tol:g}")
    print(f"{'chi':>5} {'N':>5} {'eps':>7} {'v_peak':>12} {'dv/v':>10} {'z_snap/eps':>11} {'vz_snap/eps':>12} "
          f"{'zmax/eps':>9} {'vzmax/eps':>10} {'n_rhs':>7}")
    for chi in chis:
        for N in Ns:
            base = run3d(Problem3D.catenary(chi, N), tol=tol)
            for eps in epss:
                r = run3d(Problem3D.catenary(chi, N).perturbed(eps, mode, seed=seed), tol=tol)
                dv = r["v_peak"] / base["v_peak"] - 1.0
                print(f"{chi:5.2f} {N:5d} {eps:7.0e} {r['v_peak']:12.9f} {dv:10.2e} {r['z_amp_snap'] / eps:11.6f} "
                      f"{r['vz_amp_snap'] / eps:12.5f} {r['z_amp_max'] / eps:9.5f} {r['vz_amp_max'] / eps:10.4f} "
                      f"{r['n_rhs']:7d}", flush=True)


def _time_calls(fns, n=300, rounds=20):
    """The least CPU time (``time.process_time``) of one call of each function, the
    functions interleaved over ``rounds`` rounds of ``n`` calls (robust on a loaded machine)."""
    best = {k: np.inf for k in fns}
    for fn in fns.values():
        fn()
    for _ in range(rounds):
        for k, fn in fns.items():
            t0 = time.process_time()
            for _ in range(n):
                fn()
            best[k] = min(best[k], (time.process_time() - t0) / n)
    return best


def cost(N, chi, tol, eps=1e-4, repeat=3):
    from snapping.simulate import general as G
    from snapping.simulate import models as MD
    from snapping.simulate import angles as AG
    from snapping.simulate import run
    from snapping.simulate.problem import Problem
    from snapping.spatial import Problem3D, run3d
    from snapping.spatial import chain3d as C

    prob = Problem.catenary(chi, N)
    p3 = Problem3D.catenary(chi, N).perturbed(eps)
    # one evaluation each
    mdl = prob.model()
    y = prob.initial_angles()
    f = np.empty_like(y)
    w = AG.Work(N)
    gm = G.make_model(prob.links.h, 1.0 / prob.links.m)
    yg = np.concatenate([y, [0.0]])
    fg = np.empty_like(yg)
    m3 = p3.model()
    y3 = p3.initial_state()
    f3 = np.empty_like(y3)
    w3 = C.Work(N)
    best = _time_calls({
        "uni": lambda: MD.model_rhs(N, 0.0, y, f, w.c, w.s, w.S, w.cp, w.dp, w.sig, mdl),
        "gen": lambda: G.general_rhs(N, 0.0, yg, fg, w.c, w.s, w.S, w.cp, w.dp, w.sig, *gm),
        "3d": lambda: C.rhs3d(N, 0.0, y3, f3, w3.T, w3.cp, w3.dp, *m3)})
    t_uni, t_gen, t_3d = best["uni"], best["gen"], best["3d"]
    print(f"# cost at N={N}, chi={chi}, tol={tol:g}, least CPU time of {repeat} runs ({_load()})")
    print(f"one evaluation (least CPU time): planar uniform {t_uni * 1e6:.2f} us, planar general {t_gen * 1e6:.2f} us, "
          f"3D {t_3d * 1e6:.2f} us: 3D/uniform {t_3d / t_uni:.2f}x, 3D/general {t_3d / t_gen:.2f}x")
    run(problem=Problem.catenary(chi, 20), method="fast", tol=tol)  # (compiled, both)
    run3d(Problem3D.catenary(chi, 20), tol=tol)
    pc = rc = np.inf
    for _ in range(repeat):  # (least CPU time of `repeat` runs each, interleaved)
        c0 = time.process_time()
        ds = run(problem=prob, method="fast", tol=tol).dataset
        pc = min(pc, time.process_time() - c0)
        c0 = time.process_time()
        r = run3d(p3, tol=tol)
        rc = min(rc, time.process_time() - c0)
    pw, pn, ps = float(ds.attrs["wall_time"]), int(ds.attrs["n_rhs"]), int(ds.attrs["n_steps"])
    print(f"planar run: v_peak {float(ds.attrs['v_peak']):.9f}, {pn} evaluations, {ps} steps, wall {pw:.3f} s, "
          f"CPU {pc:.3f} s ({pc / pn * 1e6:.2f} us CPU an evaluation incl. stepping)")
    print(f"3D run (eps {eps:g}): v_peak {r['v_peak']:.9f}, {r['n_rhs']} evaluations, {r['n_steps']} steps, "
          f"wall {r['wall_time']:.3f} s, CPU {rc:.3f} s ({rc / r['n_rhs'] * 1e6:.2f} us CPU an evaluation incl. stepping)")
    print(f"3D/planar: evaluations {r['n_rhs'] / pn:.2f}x, CPU per run {rc / pc:.2f}x, CPU per evaluation incl. "
          f"stepping {(rc / r['n_rhs']) / (pc / pn):.2f}x", flush=True)


def profile(N, chi, tol, eps=1e-4):
    """Where a 3D step's time goes at N links (least CPU time of each part, one step's worth):
    the 12 evaluations of an attempted step against the stage arithmetic, the end state, the
    error norm, the per-step measurements and the projection, all O(6N + 1) in the state."""
    from snapping.simulate import rk as R
    from snapping.spatial import Problem3D
    from snapping.spatial import chain3d as C
    from snapping.spatial import solve3d as S

    p3 = Problem3D.catenary(chi, N).perturbed(eps)
    par, h, invm = p3.model()
    y0 = p3.initial_state()
    n = y0.size
    K = np.random.default_rng(0).random((R.NSX, n))
    ytmp, y1, w = np.zeros(n), np.zeros(n), C.Work(N)
    meas, snode = np.zeros(C.NMEAS), np.zeros(N + 1)

    def stages():
        for st in range(1, R.NS):
            S._stage_state3d(n, st, 0.01, y0, K, ytmp)

    best = _time_calls({
        "12 evaluations": lambda: [C.rhs3d(N, 0.0, y0, K[1], w.T, w.cp, w.dp, par, h, invm) for _ in range(R.NS)],
        "stage states": stages, "end state": lambda: R.end_state(n, 0.01, y0, K, y1),
        "error norm": lambda: S.step_error3d(N, 0.01, tol, y0, y0, K, ytmp),
        "measurements": lambda: C.measure3d(N, 0.0, y0, w.T, meas, snode, par, h, invm),
        "projection": lambda: C.project(N, y0.copy())}, n=30, rounds=10)
    tot = sum(best.values())
    print(f"# one attempted 3D step at N={N} (state {n}; least CPU time, {_load()}): "
          + ", ".join(f"{k} {v * 1e6:.1f} us ({v / tot:.0%})" for k, v in best.items()))


def big(N, chi, tol, eps=1e-4):
    from snapping.spatial import Problem3D, run3d

    run3d(Problem3D.catenary(0.5, 10), tol=tol)  # (compiled)
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    p3 = Problem3D.catenary(chi, N).perturbed(eps)
    t0, c0 = time.perf_counter(), time.process_time()
    r = run3d(p3, tol=tol)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    rss1 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    state_mb = (2 * 16 + 2 * 7 + 6) * (6 * N + 1) * 8 / 2**20
    print(f"# N={N}, chi={chi}, tol={tol:g}, eps={eps:g} ({_load()})")
    print(f"v_peak {r['v_peak']:.9f} at t {r['t_snap_v']:.9f}, z_snap/eps {r['z_amp_snap'] / eps:.6f}, "
          f"{r['n_rhs']} evaluations, {r['n_steps']} steps, wall {wall:.1f} s, CPU {cpu:.1f} s "
          f"({cpu / r['n_rhs'] * 1e6:.0f} us CPU an evaluation incl. stepping), "
          f"peak RSS {rss1 / 1024:.0f} MiB (grew {(rss1 - rss0) / 1024:.0f} MiB; stepper arrays {state_mb:.0f} MiB)")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--parts", default="growth,cost,big")
    ap.add_argument("--chi", default="0.25,0.1")
    ap.add_argument("--N", default="100,200,400")
    ap.add_argument("--eps", default="1e-6,1e-4,1e-2")
    ap.add_argument("--tol", type=float, default=1e-10, help="tol of the growth study")
    ap.add_argument("--mode", default="sin", help="perturbation mode (sin, random)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--cost-tol", type=float, default=1e-8)
    ap.add_argument("--cost-N", type=int, default=1000)
    ap.add_argument("--big-N", type=int, default=10000)
    ap.add_argument("--repeat", type=int, default=3, help="runs of each in the cost part (least CPU time)")
    a = ap.parse_args(argv)
    parts = a.parts.split(",")
    if "growth" in parts:
        growth([float(c) for c in a.chi.split(",")], [int(n) for n in a.N.split(",")],
               [float(e) for e in a.eps.split(",")], a.tol, a.mode, a.seed)
    if "cost" in parts:
        cost(a.cost_N, 0.25, a.cost_tol, repeat=a.repeat)
    if "profile" in parts:
        profile(a.cost_N, 0.25, a.cost_tol)
    if "big" in parts:
        big(a.big_N, 0.25, a.cost_tol)


if __name__ == "__main__":
    main()
