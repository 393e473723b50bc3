"""Diagnostic: which links of a stretching cell go slack, and the step sizes, step by step (issue 24).

Usage: ``PYTHONPATH=src python benchmarks/stretch_tip_diag.py CHI C K TOL STEPS`` (K the fold level of
``level_parameters(8, 0.5, first=-4)``): the cell's unfloored links, matched start, grid damping 4,
``LinksStepper`` stepped STEPS times; prints the tip links' start strains, then per step the time,
step size, evaluations, rejections, the slack links (strain <= 0) and the first links' strains.
``0.5 442 1 1e-6 3000``: the stall of docs/guide/regimes.md ("The tip-link floor and the full scan").
"""
import sys, time, numpy as np
from snapping.continuum import level_parameters
from snapping.regimes import cell_problem
from snapping.regimes_spec import STRETCH_DAMPING
from snapping.simulate.elastic import Elastic
from snapping.simulate.elastic_model import ElasticLine
from snapping.simulate.elastic_links_rodas import LinksStepper
from snapping.simulate.elastic_rodas import C_H, C_NFEV, C_NREJ
chi, c, k, tol, nmax = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5])
lv = level_parameters(8, 0.5, first=-4)[k + 4]
p = cell_problem(chi, "stretching", 1.0 / c, lv)
line = ElasticLine(p, Elastic.from_wave_speed(c, grid_damping=STRETCH_DAMPING))
z0 = line.start("matched")
h = line.h
print("N", line.N, "h[0:6]", h[:6], "h_min", h.min(), "lv", lv)
st = LinksStepper(line, 0.0, z0, 10.0, tol)
zl = st.zl
N = line.N
e0 = zl[0:4*N:4]/h - 1
print("start strains tip links:", e0[:8])
print("start tension-ish: e*c^2 ", (e0*c*c)[:8])
t0 = time.process_time()
for n in range(nmax):
    msg = st.step()
    if msg: print(msg); break
    zl = st.zl
    e = zl[0:4*N:4]/h - 1
    slack = np.nonzero(e <= 0)[0]
    if n % max(1, nmax//40) == 0 or n < 10:
        vmax = np.max(np.hypot(st.yn[2:4*N+2:4], st.yn[3:4*N+2:4])) if False else 0
        print(f"step {n} t={st.t:.3e} h={st.ctl[C_H]:.2e} nfev={st.ctl[C_NFEV]:.0f} rej={st.ctl[C_NREJ]:.0f} "
              f"slack={slack[:6].tolist()}({slack.size}) e[0:4]={np.array2string(e[:4], precision=2)} "
              f"ldot0={zl[2]:.2e} thd0={zl[3]:.2e}")
print("cpu", time.process_time()-t0)
