"""One stretching cell of the regime study at one fold level, its cost and where its steps go (stretch01).

The elastic line of the study's cell (chi, c) on fold level K (``snapping.regimes.cell_problem``: K = -4
is the study's coarsest), from START, by RODAS4 at TOL with grid damping ZETA, stopped after MAX_RHS
evaluations: its peaks, evaluations, steps, steps with a slack link, first slack time, smallest step and
CPU seconds, then the steps and median step up to fractions of the run. (The tolerance is TOL as given:
the study's ``stretch_tol`` is not applied.) This is how the study's grid damping (4) and tolerance
rule were chosen (``snapping.regimes_spec``).

Usage::

    PYTHONPATH=src python benchmarks/stretch_cell.py CHI C K START TOL ZETA MAX_RHS
    PYTHONPATH=src python benchmarks/stretch_cell.py 0.3 442 -3 matched 1e-6 4 1.5e6
"""
import sys, time, os
from snapping.continuum import level_parameters
from snapping.regimes import cell_problem
from snapping.simulate.elastic import Elastic, solve
chi=float(sys.argv[1]); c=float(sys.argv[2]); k=int(sys.argv[3]); start=sys.argv[4]; tol=float(sys.argv[5]); damp=float(sys.argv[6]); mx=int(float(sys.argv[7]))
lv=level_parameters(8,0.5,first=-4)
pr=cell_problem(chi,'stretching',1/c,lv[k+4],damping=damp)
# warm compile
solve(cell_problem(0.5,'stretching',0.1,{'n_links':4,'frac':.25}),Elastic.from_wave_speed(10.,grid_damping=1.),tol=1e-5,method='rodas4',stop_floor=1.0,start=start)
t=time.process_time()
ds=solve(pr,Elastic.from_wave_speed(c,grid_damping=damp),tol=tol,method='rodas4',stop_floor=1.0,start=start,max_rhs=mx).dataset
a=ds.attrs
print(f"chi {chi} c {c} k {k} N {pr.links.N} {start} tol {tol} zeta {damp}: v {a['v_peak']:.6f} a {a['a_peak']:.5g} s {a['sigma_peak']:.5g} rhs {a['n_rhs']} steps {a['n_steps']} slacksteps {a['n_slack_steps']} tslack {a['t_first_slack']:.3g} dtmin {a['dt_min_accepted']:.2g} tfinal {a['t_final']:.4g} tsnap {a['t_snap_v']:.4g} cpu {time.process_time()-t:.2f} {a['status']} {a['stop_reason']} load {os.getloadavg()[0]:.1f}",flush=True)
import numpy as np
st=ds['t'].values if 't' in ds else None
if st is not None and 'n_slack' in ds:
    ns=ds['n_slack'].values; dt=np.diff(st)
    for q in (0.1,0.3,0.5,0.7,0.9,1.0):
        m=(st[1:]<=q*st[-1])
        print(f"  up to {q:.1f} t_final: steps {m.sum()} median dt {np.median(dt[m]) if m.any() else 0:.2g} slack steps {(ns[1:][m]>0).sum()}")
