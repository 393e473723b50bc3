"""Benchmark: the elastic line (snapping.simulate.elastic) against the inextensible chain.

chi = 0.25, released from the stretched equilibrium at rest, no damping, to the snap (v_max
falls to half its peak). For each N and wave speed c/sqrt(gL): the elastic run with scipy's
Radau (analytic banded Jacobian) and, optionally, scipy's explicit DOP853 on the same
compiled right-hand side; steps, right-hand-side evaluations (the primary measure),
Jacobians, LU factorisations, wall time, and the peaks (v, a, sigma) relative to the
inextensible run's (``run(problem=..., method="fast")``, same links and masses).

Usage::

    PYTHONPATH=src python benchmarks/bench_elastic.py                 # N = 100, 300; c = 30, 300, 3000
    PYTHONPATH=src python benchmarks/bench_elastic.py --N 30 100 --c 30 300 --tol 1e-5 --methods radau dop853
    PYTHONPATH=src python benchmarks/bench_elastic.py --N 30 --c 300 --grid-damping 0 1   # the grid damping

Wall times are noisy on a shared machine: the load average is printed with them.
"""

from __future__ import annotations

import argparse
import os
import time

from snapping.simulate import run
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.problem import Links, Problem


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", type=int, nargs="+", default=[100, 300])
    ap.add_argument("--c", type=float, nargs="+", default=[30.0, 300.0, 3000.0])
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--methods", nargs="+", default=["radau"], choices=["radau", "dop853"])
    ap.add_argument("--grid-damping", type=float, nargs="+", default=[0.0],
                    help="damping ratio(s) zeta of the shortest longitudinal mode (Elastic.grid_damping)")
    ap.add_argument("--max-rhs", type=int, default=2_000_000, help="stop a run after this many evaluations")
    a = ap.parse_args(argv)
    print(f"chi = {a.chi}, tol = {a.tol}, load average {os.getloadavg()[0]:.1f}")
    print(f"{'N':>5} {'c':>6} {'zeta':>5} {'method':>7} {'steps':>7} {'n_rhs':>9} {'n_jac':>6} {'n_lu':>7} {'wall_s':>8} "
          f"{'dv/v':>9} {'da/a':>9} {'ds/s':>9} {'slack':>6}  status")
    for N in a.N:
        p = Problem.catenary(a.chi, links=Links.uniform(N, lumping="shared"))
        t0 = time.perf_counter()
        ref = run(problem=p, method="fast", tol=1e-10).summary()
        w = time.perf_counter() - t0
        print(f"{N:>5} {'inf':>6} {'':>5} {'fast':>7} {ref['n_steps']:>7} {ref['n_rhs']:>9} {'':>6} {'':>7} {w:>8.3f} "
              f"v={ref['v_peak']:.6g} a={ref['a_peak']:.6g} sigma={ref['sigma_peak']:.6g}")
        for c in a.c:
            for m, zeta in ((m, z) for m in a.methods for z in a.grid_damping):
                t0 = time.perf_counter()
                s = solve(p, Elastic.from_wave_speed(c, grid_damping=zeta), tol=a.tol, method=m,
                          max_rhs=a.max_rhs).summary()
                w = time.perf_counter() - t0
                rel = [s[k] / ref[k] - 1.0 for k in ("v_peak", "a_peak", "sigma_peak")]
                print(f"{N:>5} {c:>6g} {zeta:>5g} {m:>7} {s['n_steps']:>7} {s['n_rhs']:>9} {s['n_jac']:>6} {s['n_lu']:>7} "
                      f"{w:>8.2f} {rel[0]:>9.2e} {rel[1]:>9.2e} {rel[2]:>9.2e} {s['n_slack_steps']:>6}  "
                      f"{s['status']} ({s['stop_reason']}), load {os.getloadavg()[0]:.1f}", flush=True)


if __name__ == "__main__":
    main()
