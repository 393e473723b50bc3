"""How much grid-scale bending motion a start launches: max |second difference of the link
angular velocity| / max |angular velocity| at a few times (1/N-smooth motion: O(1/N^2);
grid-scale waves: O(1)), catenary against equilibrium start, chi = 0.25, no damping.

Usage: ``python benchmarks/probe_rest_waves.py 100``
"""

import sys

import numpy as np

from snapping.simulate import Body, Problem, run

N = int(sys.argv[1]) if len(sys.argv) > 1 else 100
TIMES = (0.02, 0.1, 0.3, 0.6)
for beta in (1e-4, 1e-2):
    for st in ("catenary", "equilibrium"):
        p = Problem.catenary(0.25, N, body=Body(beta), start=st)
        ds = run(p, t_end=0.61, snapshot_times=list(TIMES), progress=False, tol=1e-9).dataset
        out = []
        for tt in TIMES:
            i = int(np.argmin(np.abs(ds.t_snapshot.values - tt)))
            x, y, vx, vy = (ds[k].values[i] for k in ("x", "y", "vx", "vy"))
            th = np.unwrap(np.arctan2(np.diff(y), np.diff(x)))
            om = (-np.sin(th) * np.diff(vx) + np.cos(th) * np.diff(vy)) * N
            d2 = om[2:] - 2 * om[1:-1] + om[:-2]
            out.append(f"t={tt}: {np.abs(d2).max() / np.abs(om).max():.2e}")
        print(f"N={N} beta={beta:g} {st:12s}", "; ".join(out), flush=True)
