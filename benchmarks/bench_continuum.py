"""Benchmark of the continuum limit: graded chains against uniform ones, at equal accuracy.

For each chi: refinement levels of the fold-following grading (``snapping.continuum``)
are added until the extrapolated peaks of speed, acceleration and tension carry the
target error bar (relative), or the time budget is spent; then uniform chains (the
paper's, dop853, exact chords) at a few N are measured against that limit, their error
fitted as C N^-q and their cost as D N^s, and the N and wall time a uniform chain would
need for the same accuracy are extrapolated.

A case is ``chi:target[:ratio[:first]]``: the levels' ratio and the index of the coarsest
one (:func:`snapping.continuum.level_parameters`; default 0.5 and 0). chi = 0.05 uses
ratio 2^-1/2 from level 3 (fold fraction 0.0141): the error bar compares the Richardson
estimates of the last two triples of levels, so all four last levels must be in the
asymptotic range. With ratio 1/2 from level 0 the coarsest (fraction 0.04, local order
1.5-1.8 against 1.8-2.0 further on) is not: four levels left error bars of 3e-3
(acceleration) and 4e-3 (tension) while their estimates were within 5e-5 and 4e-4 of the
5-level limit, and a fifth, finest level (4x the cost of the fourth) was needed. Four
levels a factor 2^-1/2 apart, fractions 0.0141 to 0.005, are all asymptotic and cost
~2x the finest of them.

Each level's wall and CPU time (``time.process_time`` of its run; the runs are
single-threaded, one worker) are printed: on a loaded machine the wall times are inflated.

Usage::

    python benchmarks/bench_continuum.py                       # chi 0.25, 0.1 (1e-4), 0.05 (1e-3)
    python benchmarks/bench_continuum.py --cases 0.25:1e-4 --uniform 1000,2000
    python benchmarks/bench_continuum.py --cases 0.05:1e-3:0.7071067811865476:3 --uniform ""
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time

import numpy as np

from snapping.continuum import converge
from snapping.simulate import run

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_simulate import print_machine  # noqa: E402

PEAKS = ("v_peak", "a_peak", "sigma_peak")


def study(chi: float, target: float, budget: float, uniform_N, ratio: float = 0.5, first: int = 0) -> None:
    print(f"\nchi = {chi:g}: levels (ratio {ratio:.6g}, from level {first}) until the error bars of "
          f"{', '.join(PEAKS)} are <= {target:g} (relative)")
    d = tempfile.mkdtemp(prefix=f"conv{chi:g}_")
    levels, res, spent, cpu_of = 3, None, 0.0, {}
    while True:
        t = time.perf_counter()
        res = converge(chi, levels=levels, ratio=ratio, first=first, output=d, workers=1)
        spent += time.perf_counter() - t
        ds = res.dataset
        for k in range(ds.sizes["level"]):  # a rerun resumes the levels already run: keep their CPU time
            if np.isfinite(float(ds.cpu_time[k])):
                cpu_of[k] = float(ds.cpu_time[k])
        a = ds.attrs
        worst = max(a[q + "_error"] / abs(a[q + "_limit"]) for q in PEAKS)
        if worst <= target or spent > budget:
            break
        levels += 1
    ds = res.dataset
    ds["cpu_time"] = ("level", np.array([cpu_of.get(k, math.nan) for k in range(ds.sizes["level"])]))
    print(res.table())
    wall_runs, cpu = float(ds.wall_time.sum()), float(ds.cpu_time.sum())
    print(f"runs' wall time {wall_runs:.1f} s, CPU time {cpu:.1f} s in all (one core); worst relative error bar "
          f"{worst:.2g} ({'met' if worst <= target else 'NOT met'}: target {target:g}); links at the finest level "
          f"{int(ds.n_links[-1])}")
    if not uniform_N:
        return
    print(f"uniform chains (the paper's, dop853 tol 1e-8, exact chords) against the limit (cost: CPU time):")
    run(chi, 50, method="fast", chords="exact")  # load the uniform kernels first: not counted below
    errs, walls = {q: [] for q in PEAKS}, []
    for N in uniform_N:
        t = time.process_time()
        u = run(chi, N, method="fast", chords="exact").dataset.attrs
        w = time.process_time() - t
        walls.append(w)
        row = []
        for q in PEAKS:
            e = abs(u[q] - a[q + "_limit"]) / abs(a[q + "_limit"])
            errs[q].append(e)
            row.append(f"{q} {u[q]:.7g} (off {e:.2e})")
        print(f"  N = {N:6d}: " + ", ".join(row) + f", wall {float(u['wall_time']):.2f} s, CPU {w:.2f} s")
    Ns = np.array(uniform_N, dtype=float)
    s = np.polyfit(np.log(Ns), np.log(walls), 1)[0] if len(Ns) > 1 else 1.0
    for q in PEAKS:
        e = np.array(errs[q])
        if len(Ns) < 2 or np.any(e <= 0):
            continue
        slope, icpt = np.polyfit(np.log(Ns), np.log(e), 1)
        qq = -slope
        if np.any(np.diff(e) >= 0):
            print(f"  {q}: the error does not fall monotonically with N ({', '.join(f'{v:.2e}' for v in e)}): "
                  f"no extrapolation")
            continue
        N_need = math.exp((math.log(target) - icpt) / slope) if slope < 0 else math.inf
        wall_need = walls[-1] * (N_need / Ns[-1]) ** s if math.isfinite(N_need) else math.inf
        print(f"  {q}: error ~ N^-{qq:.2f}; error {target:g} needs N ~ {N_need:.3g}, ~{wall_need:.3g} s "
              f"(CPU ~ N^{s:.2f}); graded: {cpu:.3g} s CPU, ratio {wall_need / cpu:.3g}")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", default="0.25:1e-4,0.1:1e-4,0.05:1e-3:0.7071067811865476:3",
                    help="chi:target relative error bar[:ratio of the levels[:index of the coarsest]]")
    ap.add_argument("--budget", type=float, default=600.0, help="seconds per study before giving up (default 600)")
    ap.add_argument("--uniform", default="1000,2000,5000", help="N of the uniform comparison ('' for none)")
    a = ap.parse_args(argv)
    print_machine()
    uniform_N = [int(v) for v in a.uniform.split(",") if v]
    for case in a.cases.split(","):
        chi, target, *extra = case.split(":")
        chi, target = float(chi), float(target)
        extra = [float(extra[0])] + [int(v) for v in extra[1:2]] if extra else []
        study(chi, target, a.budget, uniform_N, *extra)


if __name__ == "__main__":
    main()
