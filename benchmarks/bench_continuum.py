"""Benchmark of the continuum limit: graded chains against uniform ones, at equal accuracy.

For each chi: refinement levels of the fold-following grading (``snapping.continuum``)
are added until the extrapolated peaks of speed, acceleration and tension carry the
target error bar (relative), or the time budget is spent; then uniform chains (the
paper's, dop853, exact chords) at a few N are measured against that limit, their error
fitted as C N^-q and their cost as D N^s, and the N and wall time a uniform chain would
need for the same accuracy are extrapolated.

Usage::

    python benchmarks/bench_continuum.py                       # chi 0.25, 0.1 (1e-4), 0.05 (1e-3)
    python benchmarks/bench_continuum.py --cases 0.25:1e-4 --uniform 1000,2000
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


def study(chi: float, target: float, budget: float, uniform_N) -> None:
    print(f"\nchi = {chi:g}: levels until the error bars of {', '.join(PEAKS)} are <= {target:g} (relative)")
    d = tempfile.mkdtemp(prefix=f"conv{chi:g}_")
    levels, res, spent = 3, None, 0.0
    while True:
        t = time.perf_counter()
        res = converge(chi, levels=levels, output=d)
        spent += time.perf_counter() - t
        a = res.dataset.attrs
        worst = max(a[q + "_error"] / abs(a[q + "_limit"]) for q in PEAKS)
        if worst <= target or spent > budget:
            break
        levels += 1
    print(res.table())
    ds = res.dataset
    cpu = float(ds.wall_time.sum())
    print(f"runs' wall time {cpu:.1f} s in all (one core); worst relative error bar {worst:.2g} "
          f"({'met' if worst <= target else 'NOT met'}: target {target:g}); links at the finest level "
          f"{int(ds.n_links[-1])}")
    if not uniform_N:
        return
    print(f"uniform chains (the paper's, dop853 tol 1e-8, exact chords) against the limit:")
    errs, walls = {q: [] for q in PEAKS}, []
    for N in uniform_N:
        t = time.perf_counter()
        u = run(chi, N, method="fast", chords="exact").dataset.attrs
        w = time.perf_counter() - t
        walls.append(w)
        row = []
        for q in PEAKS:
            e = abs(u[q] - a[q + "_limit"]) / abs(a[q + "_limit"])
            errs[q].append(e)
            row.append(f"{q} {u[q]:.7g} (off {e:.2e})")
        print(f"  N = {N:6d}: " + ", ".join(row) + f", wall {w:.2f} s")
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
              f"(wall ~ N^{s:.2f}); graded: {cpu:.3g} s, ratio {wall_need / cpu:.3g}")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", default="0.25:1e-4,0.1:1e-4,0.05:1e-3", help="chi:target relative error bar")
    ap.add_argument("--budget", type=float, default=600.0, help="seconds per study before giving up (default 600)")
    ap.add_argument("--uniform", default="1000,2000,5000", help="N of the uniform comparison ('' for none)")
    a = ap.parse_args(argv)
    print_machine()
    uniform_N = [int(v) for v in a.uniform.split(",") if v]
    for case in a.cases.split(","):
        chi, target = (float(v) for v in case.split(":"))
        study(chi, target, a.budget, uniform_N)


if __name__ == "__main__":
    main()
