"""The snap window's exact end on one study cell, checked apart (branch window): the run, then the same run with
a snapshot at the window's last step's start, then scipy's brentq on v_max of the states integrated from it
(a fresh ``LinksStepper`` per trial, not ``snap_edge``'s code) and the measures there, against the recorded step.

    PYTHONPATH=src python benchmarks/snap_edge_check.py CHI C LEVEL [TOL_FACTOR]
    PYTHONPATH=src python benchmarks/snap_edge_check.py 0.3 442.71632328565266 0        # 18.8559 vs 19.0827
    PYTHONPATH=src python benchmarks/snap_edge_check.py 0.3 442.71632328565266 0 0.01   # tol 1e-8
"""
import sys
import time

import numpy as np
from snapping import regimes as R
from snapping.regimes_spec import stretch_tol, STRETCH_STOP_FLOOR, STRETCH_MAX_RHS_LINKS
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate import snap_window as SW
chi, c, li = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
tolf = float(sys.argv[4]) if len(sys.argv) > 4 else 1.0
lev = R._levels("fold", {"levels": 5, "first": -1, "n0": 50}, 0.5)[li]
prob = R.cell_problem(chi, "stretching", 1 / c, lev, damping=4.0, method="rodas4-links")
el = Elastic.from_wave_speed(c, grid_damping=4.0)
tol = stretch_tol(1e-6, c) * tolf
kw = dict(tol=tol, method="rodas4-links", stop_floor=STRETCH_STOP_FLOOR, start="matched", max_rhs=STRETCH_MAX_RHS_LINKS)
cpu = time.process_time()
r = solve(prob, el, **kw)
ds = r.dataset; a = ds.attrs
print("N", prob.links.N, "tol", tol, "steps", a["n_steps"], "cpu", round(time.process_time() - cpu, 1))
t = ds.t.values; v = ds.v_max.values; sg = ds.sigma_max.values; ac = ds.a_max.values
je = SW.snap_end(t, v, a["t_snap_v"])
print("v_peak", a["v_peak"], "rec max", v.max(), "rel", a["v_peak"] / v.max() - 1)
print("sigma_peak_snap", a["sigma_peak_snap"], "a_peak_snap", a["a_peak_snap"], "t_snap_end", a["t_snap_end"])
for k in range(je - 3, je + 2):
    print(k, t[k], v[k] / v.max(), sg[k], ac[k])
# the state at t[je-1]: a snapshot there (the run is the same)
r2 = solve(prob, el, snapshot_times=[t[je - 1]], **kw)
d2 = r2.dataset
assert np.array_equal(d2.sigma_max.values, sg)
line = r2.line
kinds = list(d2.snapshot_kind.values) if "snapshot_kind" in d2 else None

from snapping.simulate.elastic_links_rodas import LinksStepper
i = list(d2.snapshot_kind.values).index("requested")
ts = float(d2.t_snapshot.values[i]); assert ts == t[je - 1], (ts, t[je - 1])
z0 = line.pack(d2.x.values[i], d2.y.values[i], d2.vx.values[i], d2.vy.values[i])
def restep(t1):
    st = LinksStepper(line, ts, z0, t1, tol, h0=t1 - ts)
    while st.status == "running":
        st.step()
    return st.y, st.nfev
y1, nf = restep(t[je])
m1 = line.measure(t[je], y1)
print("restep to t[je]: v", m1[0], v[je], "sigma", m1[4], sg[je], "a", m1[2], ac[je], "nfev", nf)
thr = 0.9 * a["v_peak"]
from scipy.optimize import brentq
f = lambda tt: line.measure(tt, restep(tt)[0])[0] - thr
te = brentq(f, t[je - 1], t[je], xtol=1e-15)
me = line.measure(te, restep(te)[0])
print("edge t", te, "v/vp", me[0] / a["v_peak"], "sigma", me[4], "a", me[2], "overshoot sigma", sg[je] / me[4] - 1)
for tt in np.linspace(t[je - 1], t[je], 6):
    mm = line.measure(tt, restep(tt)[0]); print("  ", tt, mm[0] / a["v_peak"], mm[4], mm[2])
