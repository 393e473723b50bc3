"""Which components set dop853's step in the smooth fall (chi = 0.25, N = 1000, t = 0.5).

Rebuilds the angle state from the run's snapshot at t = 0.5, takes one DOP853 step of the
size the run used there (and 2x, 4x), and prints where the scaled error estimate is largest:
angles or angular rates, and which links (0 = the free end) with their tensions.

Usage::

    python benchmarks/probe_step_error.py
"""

import os
import sys

import numpy as np

from snapping.simulate import angles as AG
from snapping.simulate import general as G
from snapping.simulate import rk as R
from snapping.simulate import run

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_simulate import print_machine  # noqa: E402

print_machine()

N = 1000
ds = run(0.25, N, tol=1e-8, chords='exact', method='fast', snapshot_times=(0.5,)).dataset
i = int(np.argmin(abs(ds['t_snapshot'].values - 0.5)))
sn = ds.isel(snapshot=i)
x, y, vx, vy = (sn[k].values for k in ('x', 'y', 'vx', 'vy'))
dx, dy, dvx, dvy = np.diff(x), np.diff(y), np.diff(vx), np.diff(vy)
th = np.unwrap(np.arctan2(dy, dx)); om = (dx * dvy - dy * dvx) / (dx * dx + dy * dy)
y0 = np.concatenate([th, om])
t = ds['t'].values; dt = ds['dt'].values
h = float(np.median(dt[(t > 0.45) & (t < 0.55)]))
w = AG.Work(N); n = 2 * N
Kst = np.zeros((R.NS + 1, n)); y1 = np.zeros(n); yt = np.zeros(n)
AG.angle_rhs(N, y0, Kst[0], w.c, w.s, w.S, w.cp, w.dp, w.sig)
tol = 1e-8
for hh in (h, 2 * h, 4 * h):
    err = R.rk_step(N, 0.0, hh, y0, y1, Kst, yt, w.c, w.s, w.S, w.cp, w.dp, w.sig, tol, G.uniform_model(N))
    e5 = sum(R.E5_RK[j] * Kst[j] for j in range(R.NS)); e3 = sum(R.E3_RK[j] * Kst[j] for j in range(R.NS))
    sc = tol * (1 + np.maximum(abs(y0), abs(y1)))
    e5s, e3s = e5 / sc, e3 / sc
    e = abs(hh) * e5s**2 / np.sqrt(e5s**2 + 0.01 * e3s**2 + 1e-300)
    k = int(np.argmax(e))
    part = 'angle' if k < N else 'rate'
    j = k % N
    print(f"h*N={hh*N:.3f} err={err:.3g} worst component: {part} of link {j} (0 = free end), e={e[k]:.3g}; "
          f"angles max {e[:N].max():.3g}, rates max {e[N:].max():.3g}; rates: links 0-20 {e[N:N+20].max():.3g}, "
          f"20-200 {e[N+20:N+200].max():.3g}, 200-600 {e[N+200:N+600].max():.3g}, 600-1000 {e[N+600:].max():.3g}")
    top = np.argsort(e[N:])[-5:]
    print('   top rate links', top, 'tension there', w.sig[top])
