"""The start of a line with bending: the catenary against the static equilibrium (issue 21).

The experiment is a line hanging at rest, held at both ends, whose free end is released.
With bending stiffness the rest shape is the heavy elastica, not the catenary
(:mod:`snapping.simulate.equilibrium`); a released catenary is out of moment balance at
its ends and launches grid-scale bending waves that nothing damps (zeta = 0 here). For
each N, beta and start this prints:

* ``jolt``: ``v_max`` at t = 0.05 (the release's waves make it jump at once; the line's
  own fall starts from rest, v ~ t);
* dop853 (``run(..., method="fast", tol=TOL)``) to the fixed ``t_end`` (past the snap for
  every beta, so that both starts are integrated over the same time): ``n_rhs``, steps;
* the stiff solver (:func:`snapping.simulate.stiff.solve`, RODAS4, same tol and t_end):
  evaluations ``n_rhs + n_rhs_extra`` (+ ``n_rhs_refine`` of the peak location), steps;
* the automatic stop of dop853 (no t_end): where it stopped, ``t_snap_v`` and ``v_peak``.

Counts are the primary measure (wall times on a shared machine are noisy).

Usage (N list, beta list, tol, t_end, the largest beta the stiff solver is run at: its cost
with undamped waves grows fast)::

    python benchmarks/bench_rest.py 100,300 1e-6,1e-4,1e-2 1e-7 1.3
    python benchmarks/bench_rest.py 300 1e-2 1e-7 1.3 0      # dop853 only
"""

import sys
import time

from snapping.simulate import Body, Problem, run
from snapping.simulate import stiff as ST

CHI = 0.25


def jolt(p):
    ds = run(p, method="fast", t_end=0.05, progress=False).dataset
    return float(ds["v_max"].values[-1])


def main():
    Ns = [int(a) for a in (sys.argv[1] if len(sys.argv) > 1 else "100").split(",")]
    betas = [float(a) for a in (sys.argv[2] if len(sys.argv) > 2 else "1e-6,1e-4,1e-2").split(",")]
    tol = float(sys.argv[3]) if len(sys.argv) > 3 else 1e-7
    t_end = float(sys.argv[4]) if len(sys.argv) > 4 else 1.3
    stiff_max = float(sys.argv[5]) if len(sys.argv) > 5 else float("inf")
    print(f"chi = {CHI}, no damping, tol {tol:g}, fixed t_end {t_end:g}\n", flush=True)
    print("| N | beta | start | jolt v(0.05) | dop853 rhs (steps) | stiff rhs +ref (steps) | dop853/stiff | "
          "auto stop: t_end, t_snap_v, v_peak | wall dop/stiff s |")
    print("|---|---|---|---|---|---|---|---|---|", flush=True)
    for N in Ns:
        for beta in betas:
            for start in ("catenary", "equilibrium"):
                p = Problem.catenary(CHI, N, body=Body(bending=beta), start=start)
                j = jolt(p)
                t0 = time.perf_counter()
                a = run(p, method="fast", tol=tol, t_end=t_end, progress=False).dataset.attrs
                wd = time.perf_counter() - t0
                if beta <= stiff_max:
                    o = ST.solve(p, t_end, tol, records=False)
                else:
                    o = {"n_rhs": 0, "n_rhs_extra": 0, "n_rhs_refine": float("nan"), "n_steps": "-", "wall": 0.0}
                srhs = o["n_rhs"] + o["n_rhs_extra"]
                ds = run(p, method="fast", tol=tol, progress=False).dataset
                au = ds.attrs
                print(f"| {N} | {beta:g} | {start} | {j:.3f} | {a['n_rhs']} ({a['n_steps']}) | {srhs} "
                      f"+{o['n_rhs_refine']} ({o['n_steps']}) | {a['n_rhs'] / (srhs + o['n_rhs_refine']):.2f} | "
                      f"{float(ds['t'].values[-1]):.3f}, {au['t_snap_v']:.4f}, {au['v_peak']:.4f} | "
                      f"{wd:.1f}/{o['wall']:.1f} |", flush=True)


if __name__ == "__main__":
    main()
