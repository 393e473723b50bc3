"""Probe for the implicit-scheme question of #6: does an L-stable implicit method (scipy's
Radau IIA, order 5, dense finite-difference Jacobian of the angle form) take N-independent
steps in the smooth fall (chi = 0.25, t in [0, 0.9]), where dop853's steps are ~1/N?

Prints, per N, Radau's accepted steps (and its evaluations, Jacobians, LU factorisations,
wall time), dop853's steps to the same time, and the free-end speed at t = 0.9 against a
dop853 run at tol 1e-12. Dense linear algebra: N <= 800 is practical.

Usage::

    python benchmarks/probe_implicit_steps.py 1e-8 50,100,200,400,800
    python benchmarks/probe_implicit_steps.py 1e-6 100,200,400,800
"""

import os
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

from snapping.simulate import angles as AG
from snapping.simulate import run
from snapping.simulate.chain import initial_state

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_simulate import print_machine  # noqa: E402

print_machine()

T = 0.9
tol = float(sys.argv[1]) if len(sys.argv) > 1 else 1e-8
for N in [int(a) for a in (sys.argv[2].split(",") if len(sys.argv) > 2 else ["50", "100", "200", "400"])]:
    y0 = AG.state_to_angles(initial_state(0.25, N, chords="exact"))
    w = AG.Work(N)
    nf = [0]
    def f(t, y):
        nf[0] += 1
        out = np.empty(2 * N)
        AG.angle_rhs(N, np.ascontiguousarray(y), out, w.c, w.s, w.S, w.cp, w.dp, w.sig)
        return out
    t0 = time.perf_counter()
    sol = solve_ivp(f, (0, T), y0, method="Radau", rtol=tol, atol=tol)
    tr = time.perf_counter() - t0
    # reference and dop853 count: our dop853 to T
    ds = run(0.25, N, tol=tol, chords="exact", method="fast", t_end=T).dataset
    ref = run(0.25, N, tol=1e-12, chords="exact", method="fast", t_end=T).dataset
    yT = sol.y[:, -1]
    # compare free-end speed at T: from angles, v_end = |sum_j theta'_j n_j / N|
    def vend(y):
        th, om = y[:N], y[N:]
        return np.hypot(np.sum(-np.sin(th) * om), np.sum(np.cos(th) * om)) / N
    v_ref = float(ref["v_end"].values[-1])
    print(f"N={N:5d} tol={tol:g}: Radau steps {sol.t.size - 1:6d} (f evals {nf[0]}, jac {sol.njev}, LU {sol.nlu}, {tr:.1f} s), "
          f"dop853 steps {int(ds.attrs['n_steps']):6d}; v_end(T) Radau {vend(yT):.10f} ref {v_ref:.10f}")
