"""What a step costs: the compiled pieces of the stiff method (RODAS4,
:mod:`snapping.simulate.rosenbrock`) against one evaluation of the right-hand side and one
DOP853 step (:func:`snapping.simulate.rk.rk_step`), on a chain with a body (chi 0.25, beta
1e-4, damping ratio 1), in CPU time per call (``time.process_time``: less sensitive than
wall time to a shared machine's load) and in evaluations of the right-hand side.

Usage::

    python benchmarks/bench_stiff_costs.py 100,300,1000
"""

import os
import sys
import time

import numpy as np

from snapping.simulate import Body, Problem
from snapping.simulate import models as MD
from snapping.simulate import rk as R
from snapping.simulate import rosenbrock as RB
from snapping.simulate.methods import rodas4 as RO

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_simulate import print_machine  # noqa: E402


def per_call(fn, seconds=0.2, repeats=5):
    """CPU time per call: the least of ``repeats`` timings of ~``seconds`` each (a shared
    machine only ever slows a call down)."""
    fn()
    n, t0 = 0, time.process_time()
    while time.process_time() - t0 < seconds:
        fn()
        n += 1
    best = (time.process_time() - t0) / n
    for _ in range(repeats - 1):
        t0 = time.process_time()
        for _ in range(n):
            fn()
        best = min(best, (time.process_time() - t0) / n)
    return best


def main():
    Ns = [int(a) for a in (sys.argv[1] if len(sys.argv) > 1 else "100,300,1000").split(",")]
    print_machine()
    print("| N | rhs (us) | dop853 step (rhs) | rodas4 step (rhs) | rodas4/dop853 | of which: Jacobian | LU | "
          "one stage solve |")
    print("|---|---|---|---|---|---|---|---|")
    for N in Ns:
        p = Problem.catenary(0.25, N, body=Body(bending=1e-4, damping=1e-2 / (2 * N * N)))
        eng = RO.Engine(p.initial_angles(), 0.0, mdl=p.model(), tol=1e-6, dt0=None, t_end=1.0, stop_fraction=0.0,
                        thin=0.0, max_link_error=0.5, snapshot_times=())
        w, mdl = eng.w, eng.mdl
        y0 = eng.Y1[0].copy()
        n = y0.size
        f = np.zeros(n)
        t_rhs = per_call(lambda: MD.model_rhs(N, 0.0, y0, f, w.c, w.s, w.S, w.cp, w.dp, w.sig, mdl))
        Kst = np.zeros((R.NSX, n))
        MD.model_rhs(N, 0.0, y0, Kst[0], w.c, w.s, w.S, w.cp, w.dp, w.sig, mdl)
        y1, tmp = np.zeros(n), np.zeros(n)
        t_dop = per_call(lambda: R.rk_step(N, 0.0, 1e-4, y0, y1, Kst, tmp, w.c, w.s, w.S, w.cp, w.dp, w.sig, 1e-6,
                                           mdl))
        St = np.zeros((RB.NSTG, n))
        St[RB.S_F0] = eng.KK[0, RB.S_F1]
        t_ros = per_call(lambda: RB.rodas_step(N, 0.0, 1e-4, y0, y1, St, eng.ft, eng.Dj, eng.ab, eng.piv, eng.ytmp,
                                               eng.btmp, eng.rhs, eng.tmp, w.c, w.s, w.S, w.cp, w.dp, w.sig, 1e-6, mdl,
                                               eng.barr, eng.rp, eng.cnt))
        t_jac = per_call(lambda: RB.jacobian_at(N, 0.0, y0, St[0], w.sig, eng.Dj, mdl, eng.barr, eng.rp))
        RB.assemble(N, eng.Dj, 2.5e-5, eng.ab)
        ab0 = eng.ab.copy()

        def lu():
            eng.ab[...] = ab0
            RB.band_lu(eng.ab, 2 * N, RB.KL, RB.KU, eng.piv)

        t_lu = per_call(lambda: RB.assemble(N, eng.Dj, 2.5e-5, eng.ab)) + per_call(lu)
        b, U = np.random.default_rng(0).normal(size=n), np.zeros(n)
        t_sol = per_call(lambda: RB._stage_solve(N, eng.Dj, 2.5e-5, eng.ab, eng.piv, b, U, eng.rhs, eng.tmp))
        step = t_ros + t_jac + t_rhs  # (a step, its Jacobian and the evaluation at its end)
        print(f"| {N} | {1e6 * t_rhs:.1f} | {t_dop / t_rhs:.1f} | {step / t_rhs:.1f} | {step / t_dop:.2f} | "
              f"{t_jac / t_rhs:.1f} | "
              f"{t_lu / t_rhs:.1f} | {t_sol / t_rhs:.1f} |", flush=True)
    print(f"\nload after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
