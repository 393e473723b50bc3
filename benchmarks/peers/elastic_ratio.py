"""MoorDyn / this project at matched peak accuracy, timed side by side (issue 22): both codes run
the same problem (``elastic_common.py``: chi = 0.25, EA = c^2, the start given to both) again
and again, interleaved (a round: MoorDyn once, then this project at each tolerance once), so
that a shared machine's load falls on both alike; the ratio is that of the median CPU times.

* MoorDyn: ``--scheme`` (default RK4) at the step ``--dt-factor`` h/c (default 1, RK4's first
  rung in ``moordyn_elastic.py``), timed as ``elastic_table.py`` times it
  (``moordyn_elastic.stepping_cpu``: the input file, ``Init_NoIC``, the start loaded, then the
  steps to the reference's end, nothing sampled); its peak from one sampled run
  (``run_moordyn``, not timed).
* This project: ``elastic.solve(..., method=M)`` for each method M of ``--method`` (default
  ``rodas4``; ``rodas4-links`` the link-coordinate RODAS4, comma-separated for both) at each
  ``--tol``, timed as
  ``elastic_common.run_project`` times it (``time.process_time`` around ``solve``; the start
  is given data).

Each run's peak error against the reference (``elastic_common.reference``, cached in
``elastic_reference.json``; ``--peak`` as in the other scripts) is printed with the level
eps of ``--levels`` that it is within; the ratio is printed for every tolerance, and per level
for the cheapest tolerance within it (MoorDyn's run being within it too).

Usage::

    python benchmarks/peers/elastic_ratio.py --N 100 --c 30 --tol 3e-4,3e-5 --rounds 10
    python benchmarks/peers/elastic_ratio.py --N 100 --c 30 --tol 3e-4,3e-5 --method rodas4,rodas4-links
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import elastic_common as E  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--N", type=int, default=100)
    ap.add_argument("--c", type=float, default=30.0)
    ap.add_argument("--start", default="matched", choices=E.STARTS)
    ap.add_argument("--tol", default="3e-4,3e-5", help="this project's RODAS4 tolerances, comma-separated")
    ap.add_argument("--method", default="rodas4",
                    help="this project's methods, comma-separated (default rodas4; rodas4-links)")
    ap.add_argument("--scheme", default="rk4", help="MoorDyn's tScheme (default rk4)")
    ap.add_argument("--dt-factor", type=float, default=1.0, help="MoorDyn's step in units of h/c (default 1)")
    ap.add_argument("--rounds", type=int, default=10, help="interleaved rounds (default 10)")
    ap.add_argument("--levels", default="1e-3,1e-4", help="accuracy levels eps (default 1e-3,1e-4)")
    ap.add_argument("--peak", default="v", choices=("v", "sigma", "both"))
    ap.add_argument("--ref-tol", type=float, default=E.REF_TOL)
    a = ap.parse_args(argv)
    sys.stdout.reconfigure(line_buffering=True)
    E.REF_TOL, E.CRITERION = a.ref_tol, a.peak
    levels = sorted((float(x) for x in a.levels.split(",") if x), reverse=True)
    tols = [float(x) for x in a.tol.split(",") if x]
    methods = [m.strip() for m in a.method.split(",") if m.strip()]
    runs_of = [(m, tol) for m in methods for tol in tols]  # (this project's runs: method, tolerance)
    import moordyn_elastic as MD

    E.machine("moordyn")
    chi, N, c, start = a.chi, a.N, a.c, a.start
    ref = E.reference(chi, N, c, start=start)
    E.header(ref, chi)
    dt = a.dt_factor / (N * c)
    md = E.score(MD.run_moordyn(chi, N, c, dt, a.scheme, ref.t_end, start=start), ref)  # (its peaks; not timed)
    n_steps = md.count
    for m, tol in runs_of:  # compile and warm up
        E.run_project(chi, N, c, tol, m, start)
    MD.stepping_cpu(chi, N, c, dt, a.scheme, n_steps, start)
    ours = {k: [] for k in runs_of}
    runs = {}
    theirs = []
    for _ in range(a.rounds):
        theirs += MD.stepping_cpu(chi, N, c, dt, a.scheme, n_steps, start)
        for k in runs_of:
            r = E.run_project(chi, N, c, k[1], k[0], start)
            ours[k].append(r.cpu)
            runs[k] = E.score(r, ref)

    def within(r):
        e = E.error(r)
        ok = [lv for lv in levels if e <= lv]
        return f"within {min(ok):g}" if ok else f"not within {min(levels):g}"

    tm = float(np.median(theirs))
    print(f"\n  {a.rounds} interleaved rounds; CPU ms (time.process_time), median [min - max]")
    print(f"  MoorDyn {a.scheme} dt={dt:.3g} ({a.dt_factor:g} h/c): {n_steps:,} steps, {tm * 1e3:.2f} "
          f"[{min(theirs) * 1e3:.2f} - {max(theirs) * 1e3:.2f}] ms; peak v err {md.err:.1e}, sigma err "
          f"{md.err_sigma:.1e} ({within(md)})")
    for k in runs_of:
        r, ts = runs[k], ours[k]
        t = float(np.median(ts))
        print(f"  this project {k[0]} tol={k[1]:g}: {r.count:,} evaluations, {r.extra.split()[0]}, {t * 1e3:.2f} [{min(ts) * 1e3:.2f} - "
              f"{max(ts) * 1e3:.2f}] ms; peak v err {r.err:.1e}, sigma err {r.err_sigma:.1e} ({within(r)}); "
              f"MoorDyn / this = {tm / t:.2f}x (min/min {min(theirs) / min(ts):.2f}x)")
    for m in methods:
        for lv in levels:
            ok = [k for k in runs_of if k[0] == m and E.error(runs[k]) <= lv]
            if not ok or E.error(md) > lv:
                print(f"  {m} at {lv:g}: not reached by {'this project' if not ok else 'MoorDyn'} in these runs")
                continue
            k = min(ok, key=lambda q: np.median(ours[q]))
            t = float(np.median(ours[k]))
            print(f"  {m} at {lv:g}: this project tol={k[1]:g} {t * 1e3:.2f} ms, MoorDyn {tm * 1e3:.2f} ms: "
                  f"MoorDyn / this = {tm / t:.2f}x ({'>=' if tm / t >= 10 else '<'} 10x)")
    print(f"uptime: {os.popen('uptime').read().strip()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
