"""Benchmark: the elastic line (snapping.simulate.elastic) against the inextensible chain.

chi = 0.25, released from the stretched equilibrium at rest (``--start matched``: the start
stretched to the rigid chain's tensions after release, no release wave), no damping, to the
snap (v_max falls to half its peak). For each N and wave speed c/sqrt(gL): the elastic run with scipy's
Radau (analytic banded Jacobian) and, optionally, scipy's explicit DOP853 on the same
compiled right-hand side; steps, right-hand-side evaluations (the primary measure),
Jacobians, LU factorisations, wall time, and the peaks (v, a, sigma) relative to the
inextensible run's (``run(problem=..., method="fast")``, same links and masses).

Usage::

    PYTHONPATH=src python benchmarks/bench_elastic.py                 # N = 100, 300; c = 30, 300, 3000
    PYTHONPATH=src python benchmarks/bench_elastic.py --N 30 100 --c 30 300 --tol 1e-5 --methods radau dop853
    PYTHONPATH=src python benchmarks/bench_elastic.py --N 30 --c 300 --grid-damping 0 1   # the grid damping

With ``--ref-tol`` each (N, c, zeta) is also run with ``rodas4`` at that tolerance (the
converged elastic solution of the same N and start) and every run's peaks are quoted relative
to it (``ev/v``, ``ea/a``, ``es/s``); with two ``--ref-tol`` the tighter is the reference and
the looser's peaks relative to it (the ``ref2`` row) say how far it is converged. ``x_fast``
is the run's evaluations over the inextensible fast run's (tol 1e-10), ``w_fast`` its CPU
time over the fast run's (``cpu_s``: process time, less noisy than wall on a shared machine). Give several ``--tol`` to find the
loosest that meets a peak accuracy (``--target``, marked ``*``).

    PYTHONPATH=src python benchmarks/bench_elastic.py --N 100 --c 30 300 3000 --grid-damping 1 \
        --methods rodas4 --tol 1e-4 1e-5 1e-6 --ref-tol 1e-8

Wall times are noisy on a shared machine: the load average is printed with them.
"""

from __future__ import annotations

import argparse
import os
import platform
import time

from snapping.simulate import run
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.problem import Links, Problem


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", type=int, nargs="+", default=[100, 300])
    ap.add_argument("--c", type=float, nargs="+", default=[30.0, 300.0, 3000.0])
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--tol", type=float, nargs="+", default=[1e-6])
    ap.add_argument("--methods", nargs="+", default=["radau"], choices=["radau", "dop853", "rodas4"])
    ap.add_argument("--ref-tol", type=float, nargs="+", default=None,
                    help="tolerance(s) of the rodas4 reference run (two: the tighter is the reference)")
    ap.add_argument("--start", default="stretched", choices=["stretched", "matched", "unstretched"],
                    help="the elastic line's start (elastic.solve's start)")
    ap.add_argument("--target", type=float, default=1e-4, help="peak accuracy that marks a run '*'")
    ap.add_argument("--grid-damping", type=float, nargs="+", default=[0.0],
                    help="damping ratio(s) zeta of the shortest longitudinal mode (Elastic.grid_damping)")
    ap.add_argument("--max-rhs", type=int, default=2_000_000, help="stop a run after this many evaluations")
    a = ap.parse_args(argv)
    print(f"machine: {platform.node()} {platform.processor() or platform.machine()}, {os.cpu_count()} cpus; "
          f"chi = {a.chi}, start = {a.start}, tol = {a.tol}, ref_tol = {a.ref_tol}, load average "
          f"{os.getloadavg()[0]:.1f}")
    print(f"{'N':>5} {'c':>6} {'zeta':>5} {'method':>7} {'tol':>7} {'steps':>7} {'n_rhs':>9} {'n_jac':>6} {'n_lu':>7} "
          f"{'cpu_s':>8} {'dv/v':>9} {'da/a':>9} {'ds/s':>9} {'ev/v':>9} {'ea/a':>9} {'es/s':>9} {'x_fast':>7} "
          f"{'w_fast':>7}  status")
    keys = ("v_peak", "a_peak", "sigma_peak")
    for N in a.N:
        p = Problem.catenary(a.chi, links=Links.uniform(N, lumping="shared"))
        run(problem=p, method="fast", tol=1e-10)  # (compile)
        t0 = time.process_time()
        ref = run(problem=p, method="fast", tol=1e-10).summary()
        wf = time.process_time() - t0
        print(f"{N:>5} {'inf':>6} {'':>5} {'fast':>7} {1e-10:>7.0e} {ref['n_steps']:>7} {ref['n_rhs']:>9} {'':>6} {'':>7} "
              f"{wf:>8.3f} v={ref['v_peak']:.8g} a={ref['a_peak']:.8g} sigma={ref['sigma_peak']:.8g}", flush=True)
        for c in a.c:
            for zeta in a.grid_damping:
                el = Elastic.from_wave_speed(c, grid_damping=zeta)
                conv = None
                for rt in sorted(a.ref_tol or [], reverse=True):  # (the looser first: ref2, then the reference)
                    t0 = time.process_time()
                    prev, conv = conv, solve(p, el, tol=rt, method="rodas4", max_rhs=a.max_rhs,
                                             start=a.start).summary()
                    agree = ("" if prev is None else "  ref2 vs ref: " + " ".join(
                        f"{k[0]}:{prev[k] / conv[k] - 1.0:.1e}" for k in keys))
                    print(f"{N:>5} {c:>6g} {zeta:>5g} {'ref':>7} {rt:>7.0e} {conv['n_steps']:>7} {conv['n_rhs']:>9} "
                          f"{'':>6} {'':>7} {time.process_time() - t0:>8.2f} v={conv['v_peak']:.8g} "
                          f"a={conv['a_peak']:.8g} sigma={conv['sigma_peak']:.8g} {conv['status']}{agree}", flush=True)
                for m in a.methods:
                    for tol in a.tol:
                        t0 = time.process_time()
                        s = solve(p, el, tol=tol, method=m, max_rhs=a.max_rhs, start=a.start).summary()
                        w = time.process_time() - t0
                        rel = [s[k] / ref[k] - 1.0 for k in keys]
                        acc = [s[k] / conv[k] - 1.0 for k in keys] if conv else [float("nan")] * 3
                        ok = "*" if conv and max(abs(x) for x in acc) <= a.target else " "
                        print(f"{N:>5} {c:>6g} {zeta:>5g} {m:>7} {tol:>7.0e} {s['n_steps']:>7} {s['n_rhs']:>9} "
                              f"{s['n_jac']:>6} {s['n_lu']:>7} {w:>8.2f} {rel[0]:>9.2e} {rel[1]:>9.2e} {rel[2]:>9.2e} "
                              f"{acc[0]:>9.2e} {acc[1]:>9.2e} {acc[2]:>9.2e}{ok} {s['n_rhs'] / ref['n_rhs']:>6.1f} "
                              f"{w / wf:>7.1f}  {s['status']} ({s['stop_reason']}), load {os.getloadavg()[0]:.1f}"
                              f"{', pivoted LU ' + str(s['n_lu_pivoted']) if s.get('n_lu_pivoted') else ''}",
                              flush=True)


if __name__ == "__main__":
    main()
