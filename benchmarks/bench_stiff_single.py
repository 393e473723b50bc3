"""One problem, one tolerance per method: stiff (:mod:`snapping.simulate.stiff`) against
dop853, peaks side by side and their evaluation counts (for sizes where the tolerance
ladder of ``bench_stiff.py`` is too long for a shared machine).

Usage (N, beta, zeta as in bench_stiff.py, tol of dop853, tol of stiff, optional t_end;
without it both stop by the driver's snap rule)::

    python benchmarks/bench_stiff_single.py 1000 1e-2 1 1e-6 1e-6
    python benchmarks/bench_stiff_single.py 1000 1e-2 1 1e-6 1e-6 1.3
"""

import os
import sys
import time

from snapping.simulate import Body, Problem, run
from snapping.simulate import stiff as ST

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_simulate import print_machine  # noqa: E402

N, beta, zeta, tol_d, tol_s = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), float(
    sys.argv[5])
t_end = float(sys.argv[6]) if len(sys.argv) > 6 else None
print_machine()
eta = zeta * beta ** 0.5 / (2 * N * N)
p = Problem.catenary(0.25, N, body=Body(bending=beta, damping=eta))
print(f"chi = 0.25, N = {N}, beta = {beta:g}, eta = {eta:.3g}, t_end = {t_end}", flush=True)
t0 = time.perf_counter()
ds = run(problem=p, method="fast", tol=tol_d, t_end=t_end).dataset
a = ds.attrs
print(f"dop853 tol {tol_d:g}: v {a['v_peak']:.10g} a {a['a_peak']:.10g} sigma {a['sigma_peak']:.10g} t_snap_v "
      f"{a['t_snap_v']:.8g}; rhs {a['n_rhs']}, steps {a['n_steps']}, stop t {float(ds['t'].values[-1]):.4f}, "
      f"wall {time.perf_counter() - t0:.1f} s", flush=True)
o = ST.solve(p, t_end, tol_s, records=False)
print(f"stiff  tol {tol_s:g}: v {o['v_peak']:.10g} a {o['a_peak']:.10g} sigma {o['sigma_peak']:.10g} t_snap_v "
      f"{o['t_snap_v']:.8g}; rhs {o['n_rhs']} (+{o['n_rhs_extra']} W/D rows, +{o['n_rhs_refine']} peaks), "
      f"steps {o['n_steps']} "
      f"(rejected {o['n_rejected']}), jac {o['n_jac']}, lu {o['n_lu']}, solves {o['n_solves']}, stop t {o['t']:.4f}, "
      f"wall {o['wall']:.1f} s", flush=True)
rel = max(abs(o[f"{q}_peak"] - a[f"{q}_peak"]) / a[f"{q}_peak"] for q in ("v", "a", "sigma"))
tot = o["n_rhs"] + o["n_rhs_extra"] + o["n_rhs_refine"]
print(f"largest relative peak difference {rel:.1e}; dop853/stiff rhs (all) {a['n_rhs'] / tot:.2f}")
