"""Benchmark of the general chain's right-hand side against the paper's uniform kernel.

Prints, for each N: ns per node of one evaluation of ``angles.angle_rhs`` (the paper's
chain) and of ``general.general_rhs`` on (a) the same uniform chain, (b) a tapered chain
with a tip mass and unequal (graded) links, fixed held end, (c) the same with a moving
held end (a flick), each called from Python (best of 15 batches, the four taking turns
so that a change of load hits them alike); then the same ratios with both kernels called
from compiled loops, as dop853 calls them (without Python's dispatch of 16 arguments
against 9: about 0.6 us a call here, 5 % of a call at N = 1000), interleaved batch by
batch, as the median of the per-batch ratios with its quartiles (a loaded machine moves
these far less than absolute times); then full dop853 runs to the snap of the paper's
chain by the uniform path and by the general path (the same chain, a zero pull on the
held end), with their evaluations and wall times, and tapered / tip-mass runs for
comparison.

Usage::

    python benchmarks/bench_general.py                  # N = 1000, 20000; runs at N = 1000
    python benchmarks/bench_general.py --sizes 1000 --runs 0.25:1000,0.1:2000
    python benchmarks/bench_general.py --runs "" --batches 201    # kernels only
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np
from numba import njit

from snapping.simulate import Links, PinMotion, Problem, run
from snapping.simulate import angles as AG
from snapping.simulate import general as G

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_simulate import print_machine  # noqa: E402


def per_eval(fns, N, min_time=0.06, rounds=15) -> list[float]:
    """ns per node of one call of each of fns: the best of ``rounds`` batches, the
    functions taking turns batch by batch (so that a change of load hits them alike)."""
    for fn in fns:
        fn()
    n = 1
    while True:
        t = time.perf_counter()
        for _ in range(n):
            fns[0]()
        if time.perf_counter() - t > min_time:
            break
        n *= 2
    best = [np.inf] * len(fns)
    for _ in range(rounds):
        for i, fn in enumerate(fns):
            t = time.perf_counter()
            for _ in range(n):
                fn()
            best[i] = min(best[i], (time.perf_counter() - t) / n)
    return [b * 1e9 / N for b in best]


@njit(cache=False)
def _loop_uniform(K, N, y, f, c, s, S, cp, dp, sig):
    for _ in range(K):
        AG.angle_rhs(N, y, f, c, s, S, cp, dp, sig)


@njit(cache=False)
def _loop_general(K, N, t, y, f, c, s, S, cp, dp, sig, mdl):
    for _ in range(K):
        G.general_rhs(N, t, y, f, c, s, S, cp, dp, sig, *mdl)


def compiled_ratios(N, y2, y3, w, f, models, batches: int) -> str:
    """Median (quartiles) over interleaved batches of general/uniform time, compiled loops."""
    K = max(1, int(2e6 / (12.0 * N)))  # about 2 ms a batch
    fns = [lambda: _loop_uniform(K, N, y2, f, w.c, w.s, w.S, w.cp, w.dp, w.sig)]
    fns += [lambda m=m: _loop_general(K, N, 0.1, y3, f, w.c, w.s, w.S, w.cp, w.dp, w.sig, m) for m in models]
    for fn in fns:
        fn()
    dt = np.empty((batches, len(fns)))
    for b in range(batches):
        for i, fn in enumerate(fns):
            t = time.perf_counter()
            fn()
            dt[b, i] = time.perf_counter() - t
    r = dt[:, 1:] / dt[:, :1]
    lo, med, hi = np.percentile(r, [25, 50, 75], axis=0)
    best = dt[:, 0].min() * 1e9 / (K * N)
    cells = [f"{m:5.3f}x ({a:5.3f}-{b:5.3f})" for a, m, b in zip(lo, med, hi)]
    return (f"N = {N:6d}: compiled, interleaved, median (quartiles) of {batches} batches: angle_rhs best "
            f"{best:6.2f} ns/node | general_rhs uniform {cells[0]}, taper+tip+graded {cells[1]}, + flick {cells[2]}")


def kernels(N: int, batches: int) -> None:
    rng = np.random.default_rng(1)
    th = -np.pi / 2 + 0.3 * rng.standard_normal(N)
    om = rng.standard_normal(N)
    w = AG.Work(N)
    f = np.empty(2 * N + 1)
    y2 = np.concatenate([th, om])
    y3 = np.concatenate([th, om, [0.0]])
    mu = G.make_model(np.full(N, 1.0 / N), np.full(N, float(N)))
    s = np.linspace(0.0, 1.0, N + 1)
    h = np.diff(1.0 - (1.0 - s) ** 1.5)[::-1]  # graded: fine at the free end
    links = Links.taper(N, 0.1, tip_mass=0.2, h=h / h.sum())
    mg = G.make_model(links.h, 1.0 / links.m)
    mf = G.make_model(links.h, 1.0 / links.m, **PinMotion.flick((1.0, 0.5), 0.3).model_args())
    t_uni, t_gu, t_gg, t_gf = per_eval([
        lambda: AG.angle_rhs(N, y2, f, w.c, w.s, w.S, w.cp, w.dp, w.sig),
        lambda: G.general_rhs(N, 0.1, y3, f, w.c, w.s, w.S, w.cp, w.dp, w.sig, *mu),
        lambda: G.general_rhs(N, 0.1, y3, f, w.c, w.s, w.S, w.cp, w.dp, w.sig, *mg),
        lambda: G.general_rhs(N, 0.1, y3, f, w.c, w.s, w.S, w.cp, w.dp, w.sig, *mf)], N)
    print(f"N = {N:6d}: angle_rhs {t_uni:6.2f} ns/node | general_rhs uniform {t_gu:6.2f} ({t_gu / t_uni:5.3f}x), "
          f"taper+tip+graded {t_gg:6.2f} ({t_gg / t_uni:5.3f}x), + flick {t_gf:6.2f} ({t_gf / t_uni:5.3f}x)")
    if batches:
        print(compiled_ratios(N, y2, y3, w, f, (mu, mg, mf), batches))


def runs(cases) -> None:
    print("\nfull runs, dop853 tol 1e-8, exact chords, to the snap (stop_fraction 0.5):")
    print(f"{'case':<44} {'v_peak':>11} {'a_peak':>12} {'sigma_peak':>11} {'t_snap_v':>10} {'RHS evals':>10} "
          f"{'wall s':>7}")
    for chi, N in cases:
        rows = [
            ("paper's chain, uniform path", Problem.catenary(chi, N, chords="exact")),
            ("paper's chain, general path (zero pull)", Problem.catenary(chi, N, chords="exact",
                                                                          pin=PinMotion.pull((0.0, 0.0)))),
            ("shared lumping (free end 1/(2N))", Problem.catenary(chi, links=Links.uniform(N, lumping="shared"),
                                                                  chords="exact")),
            ("taper ratio 0.1 (linear)", Problem.catenary(chi, links=Links.taper(N, 0.1), chords="exact")),
            ("tip mass 0.1", Problem.catenary(chi, links=Links.uniform(N, tip_mass=0.1), chords="exact")),
        ]
        for name, p in rows:
            t = time.perf_counter()
            a = run(p, method="fast", tol=1e-8, progress=False).dataset.attrs
            wall = time.perf_counter() - t
            print(f"chi={chi:<5g} N={N:<6d} {name:<31} {a['v_peak']:11.7f} {a['a_peak']:12.5f} {a['sigma_peak']:11.6f} "
                  f"{a['t_snap_v']:10.7f} {a['n_rhs']:10d} {wall:7.2f}")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="1000,20000", help="N of the kernel timings (comma-separated)")
    ap.add_argument("--runs", default="0.25:1000,0.1:1000", help="chi:N of the full runs ('' for none)")
    ap.add_argument("--batches", type=int, default=101,
                    help="interleaved batches of the compiled-loop ratios (0: skip them)")
    a = ap.parse_args(argv)
    print_machine()
    for N in (int(v) for v in a.sizes.split(",") if v):
        kernels(N, a.batches)
    cases = [(float(c.split(":")[0]), int(c.split(":")[1])) for c in a.runs.split(",") if c]
    if cases:
        runs(cases)


if __name__ == "__main__":
    main()
