"""Euler-Richardson (the paper's) against DOP853 in link angles, side by side; ensembles.

For each (chi, N): peak speed, acceleration and tension, snapping time, the largest
link-length error over the run, right-hand-side evaluations and wall time of both
methods, from the same initial chain (the catenary with exact chords 1/N, so that
both integrate the same N-pendulum), and the relative differences of the peaks.
Then the ensemble: M chi values of one N in one vectorised kernel against M single
runs (total wall time, per member), and the growth of the evaluation count with N.

Usage::

    python benchmarks/bench_methods.py              # chi 0.25, 0.1 x N 1000, 2000, 5000 (~10 min on one core)
    python benchmarks/bench_methods.py --quick      # chi 0.25 x N 500, 1000; ensemble of 4 at N 300
    python benchmarks/bench_methods.py --cases 0.25:2000 --no-ensemble
    python benchmarks/bench_methods.py --cases 0.05:5000,0.05:20000 --dop853-only --no-ensemble   # large N
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

from snapping.simulate import SimulationError, run, run_ensemble

sys.path.insert(0, os.path.dirname(__file__))
from bench_simulate import print_machine  # noqa: E402


def one(chi: float, N: int, method: str, tol: float) -> dict | None:
    """The run's peaks and costs; None (and a line saying why) if it fails."""
    try:
        a = run(chi, N, method=method, tol=tol, chords="exact").dataset.attrs
    except SimulationError as e:
        a = e.dataset.attrs
        print(f"  {chi:>5g} {N:>5} {method:<17} failed after {a['n_rhs']} evaluations, {a['wall_time']:.1f} s: "
              f"{a['stop_reason']}")
        return None
    return {k: a[k] for k in ("v_peak", "a_peak", "sigma_peak", "t_snap_v", "link_drift", "n_rhs", "n_steps",
                              "wall_time", "energy_drift")}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="a quick subset (a minute)")
    p.add_argument("--cases", default=None, help="comma-separated chi:N (default 0.25 and 0.1 at N 1000,2000,5000)")
    p.add_argument("--tol", type=float, default=1e-8, help="tolerance of both methods (default 1e-8)")
    p.add_argument("--no-ensemble", action="store_true", help="skip the ensemble comparison")
    p.add_argument("--dop853-only", action="store_true",
                   help="run only dop853 (for N where Euler-Richardson would take hours)")
    p.add_argument("--ensemble", default=None, help="M:N of the ensemble comparison (default 8:1000; quick 4:300)")
    args = p.parse_args(argv)
    if args.cases:
        cases = [(float(c), int(n)) for c, n in (v.split(":") for v in args.cases.split(","))]
    elif args.quick:
        cases = [(0.25, 500), (0.25, 1000)]
    else:
        cases = [(chi, N) for chi in (0.25, 0.1) for N in (1000, 2000, 5000)]
    M, NE = (4, 300) if args.quick else (8, 1000)
    if args.ensemble:
        M, NE = (int(v) for v in args.ensemble.split(":"))

    print_machine()
    methods = "dop853" if args.dop853_only else "both methods"
    print(f"{methods} from the catenary with exact chords, tol {args.tol:g}, to shortly after the snap")
    hdr = (f"  {'chi':>5} {'N':>5} {'method':<17} {'v_peak':>12} {'a_peak':>12} {'sigma_peak':>11} {'t_snap_v':>10} "
           f"{'link err':>9} {'rhs evals':>10} {'wall s':>8}")
    print(hdr)
    growth = []
    for chi, N in cases:
        er = None if args.dop853_only else one(chi, N, "euler-richardson", args.tol)
        ho = one(chi, N, "dop853", args.tol)
        if ho is None:
            continue
        for name, r in (("euler-richardson", er), ("dop853", ho)):
            if r is not None:
                print(f"  {chi:>5g} {N:>5} {name:<17} {r['v_peak']:>12.8g} {r['a_peak']:>12.8g} "
                      f"{r['sigma_peak']:>11.8g} {r['t_snap_v']:>10.7f} {r['link_drift']:>9.1e} {r['n_rhs']:>10} "
                      f"{r['wall_time']:>8.2f}")
        if er is not None:
            rel = {q: abs(ho[q] / er[q] - 1) for q in ("v_peak", "a_peak", "sigma_peak")}
            print(f"  {'':>5} {'':>5} {'dop853 / ER':<17} {rel['v_peak']:>12.1e} {rel['a_peak']:>12.1e} "
                  f"{rel['sigma_peak']:>11.1e} {ho['t_snap_v'] - er['t_snap_v']:>10.1e} {'':>9} "
                  f"{er['n_rhs'] / ho['n_rhs']:>9.1f}x {er['wall_time'] / ho['wall_time']:>7.1f}x")
        growth.append((chi, N, ho["n_rhs"], ho["n_steps"], er["n_rhs"] if er is not None else "-"))
    if not args.dop853_only:
        print("  (dop853 / ER row: relative differences of the peaks, difference of t_snap_v, and how many times fewer\n"
              "   evaluations and how much less wall time dop853 needs; link err: largest relative link-length error)")
    print()
    print("evaluation count against N (dop853 steps are ~1/N in the smooth fall: its high link modes set them)")
    print(f"  {'chi':>5} {'N':>5} {'dop853 evals':>13} {'evals / N':>10} {'steps':>7} {'ER evals':>10}")
    for chi, N, ev, st, eer in growth:
        print(f"  {chi:>5g} {N:>5} {ev:>13} {ev / N:>10.2f} {st:>7} {eer:>10}")
    for chi in sorted({g[0] for g in growth}):
        pts = [(N, ev) for c, N, ev, _, _ in growth if c == chi]
        if len(pts) >= 2:
            slope = np.polyfit(np.log([q[0] for q in pts]), np.log([q[1] for q in pts]), 1)[0]
            print(f"  chi={chi:g}: dop853 evaluations ~ N^{slope:.2f} over N = {pts[0][0]}..{pts[-1][0]}")
    if not args.no_ensemble:
        chis = list(np.round(np.linspace(0.2, 0.5, M), 4))
        print()
        print(f"ensemble: {M} members chi = {chis[0]:g}..{chis[-1]:g}, N = {NE} (dop853, tol {args.tol:g})")
        run_ensemble(chis[:2], 20)  # compile / load caches
        t0 = time.perf_counter()
        dss = run_ensemble(chis, NE, tol=args.tol, chords="exact")
        t_ens = time.perf_counter() - t0
        t0 = time.perf_counter()
        singles = [run(c, NE, method="dop853", tol=args.tol, chords="exact").dataset for c in chis]
        t_single = time.perf_counter() - t0
        dv = max(abs(a.attrs["v_peak"] / b.attrs["v_peak"] - 1) for a, b in zip(dss, singles))
        print(f"  {'':<22} {'wall s':>8} {'per member':>11} {'rhs evals':>10}")
        print(f"  {'one ensemble':<22} {t_ens:>8.2f} {t_ens / M:>11.3f} {sum(d.attrs['n_rhs'] for d in dss):>10}")
        print(f"  {f'{M} single runs':<22} {t_single:>8.2f} {t_single / M:>11.3f} "
              f"{sum(d.attrs['n_rhs'] for d in singles):>10}")
        print(f"  ensemble / singles: {t_ens / t_single:.2f} of the cost; peaks agree to {dv:.1e}")
    print(f"\n  load average   {os.getloadavg()[0]:.2f} (at end)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
