"""RODAS4 on tiny tip links (issue 24's fifth bending level): evaluations and CPU time by tolerance.

The reproduction of the defect the ``tinylink`` branch fixed: a fold-graded chain (chi = 0.1,
beta = 7.2e-8, the regime study's grid damping ratio 1) whose free end's links fall to 1.7e-7
(153 links: ``grading.fold_following(0.1, frac=0.5, h_min=1e-7, h_max=0.1, gamma=1)``). Before
the roundoff floor of the error norm (:func:`snapping.simulate.rosenbrock.omega_floor`) tol 1e-7
took 69,758 steps of ~1e-11 to t = 1e-6 (562,284 evaluations, 9.2 s of CPU; after: 199
steps, 1,346 evaluations); tol 1e-6 to the snap 13,829 evaluations (after: 12,616). Costs in CPU time (``time.process_time``) and evaluations.

Usage::

    python benchmarks/bench_tiplinks.py                 # to t = 1e-6 and to the snap, tol 1e-5 .. 1e-8
    python benchmarks/bench_tiplinks.py --t-end 1e-6 --tol 1e-7
"""

from __future__ import annotations

import argparse
import os
import sys
import time

from snapping.regimes import eta_grid
from snapping.simulate import Body, Links, Problem, grading, run

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_simulate import print_machine  # noqa: E402

CHI, BETA = 0.1, 7.2e-8


def problem(h_min: float = 1e-7):
    h = grading.fold_following(CHI, frac=0.5, h_min=h_min, h_max=0.1, gamma=1.0)
    return Problem.catenary(CHI, links=Links.graded(h), chords="exact",
                            body=Body(bending=BETA, damping=eta_grid(h, BETA, 1.0)))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tol", type=float, nargs="*", default=[1e-5, 1e-6, 1e-7, 1e-8])
    ap.add_argument("--t-end", type=float, nargs="*", default=[1e-6, 0.0], help="0: to the snap")
    ap.add_argument("--h-min", type=float, default=1e-7)
    a = ap.parse_args(argv)
    print_machine()
    p = problem(a.h_min)
    run(problem=p, method="rodas4", tol=1e-5, t_end=1e-9)  # (compile / load the cache)
    print(f"chi={CHI:g} beta={BETA:g} N={p.N} tip link {p.links.h[0]:.3g}")
    for t_end in a.t_end:
        for tol in a.tol:
            cpu = time.process_time()
            at = run(problem=p, method="rodas4", tol=tol, t_end=t_end or None).dataset.attrs
            cpu = time.process_time() - cpu
            print(f"t_end={'snap' if not t_end else f'{t_end:g}':>6} tol={tol:g}: evaluations {at['n_rhs']}, steps "
                  f"{at['n_steps']} ({at['n_rejected']} rejected), smallest {at['dt_min_accepted']:.3g}, cpu {cpu:.2f} s, "
                  f"v_peak {at['v_peak']:.10g}", flush=True)


if __name__ == "__main__":
    main()
