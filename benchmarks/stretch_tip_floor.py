"""Benchmark: one stretching cell by ``rodas4-links`` with its free end's links floored at ``HMIN`` (issue 24).

Usage: ``PYTHONPATH=src python benchmarks/stretch_tip_floor.py CHI C K HMIN TOL MAX_RHS`` (K the fold level
of ``level_parameters(8, 0.5, first=-4)``; HMIN 0: the level's own h_min). The cell's links
(``regimes.cell_problem``, no method: unfloored) with ``h_min`` raised to HMIN, matched start, grid
damping 4, the stop floor of the study, tol ``stretch_tol(TOL, C)``. Prints one JSON line (peaks,
evaluations, steps, CPU, status, peak guard's note, load) and appends it to
``benchmarks/results/stretch_tip_floor.jsonl``: the measurements behind ``regimes_spec.STRETCH_TIP_TIME``.
"""
import sys, time, json, os
from snapping.continuum import level_parameters
from snapping.regimes import cell_problem
from snapping.regimes_spec import STRETCH_DAMPING, STRETCH_STOP_FLOOR, stretch_tol
from snapping.simulate.elastic import Elastic, solve
# args: chi c k hmin tol maxrhs
chi, c, k, hmin, tol, maxrhs = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5]), int(sys.argv[6])
lv = dict(level_parameters(8, 0.5, first=-4)[k + 4])
if hmin > 0: lv["h_min"] = max(lv["h_min"], hmin)
p = cell_problem(chi, "stretching", 1.0 / c, lv)
t0 = time.process_time()
ds = solve(p, Elastic.from_wave_speed(c, grid_damping=STRETCH_DAMPING), tol=stretch_tol(tol, c), method="rodas4-links",
           stop_floor=STRETCH_STOP_FLOOR, start="matched", max_rhs=maxrhs).dataset
a = ds.attrs
r = dict(chi=chi, c=c, k=k, hmin=lv["h_min"], N=int(p.links.N), h0=float(p.links.h[0]) if hasattr(p.links,'h') else None, tol=tol, status=str(a["status"]), v=float(a["v_peak"]), a=float(a["a_peak"]), s=float(a["sigma_peak"]),
         nrhs=int(a["n_rhs"]), steps=int(a["n_steps"]), cpu=round(time.process_time()-t0,2), note=str(a.get("peak_note","")), load=os.getloadavg()[0])
print(json.dumps(r)); open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "results", "stretch_tip_floor.jsonl"), "a").write(json.dumps(r)+"\n")
