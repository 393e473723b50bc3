"""Diagnostic: when a stretching cell's peaks happen relative to the speed peak and the slack links (issue 24).

Usage: ``PYTHONPATH=src python benchmarks/stretch_peak_phase.py CHI C K`` (K the fold level of
``level_parameters(8, 0.5, first=-4)``): the cell's ``rodas4-links`` run as the study runs it (tip
links floored), then from its per-step records the step of the speed peak, of the acceleration and
tension peaks, the first slack link and the slack links after it. ``0.3 442.71632328565266 1``,
``0.5 38.41511522329253 1``, ``0.1 7.529275877145769 0``: docs/guide/regimes.md.
"""
import sys, numpy as np
from snapping.continuum import level_parameters
from snapping.regimes import cell_problem
from snapping.regimes_spec import STRETCH_DAMPING, STRETCH_STOP_FLOOR, stretch_tol
from snapping.simulate.elastic import Elastic, solve
chi, c, k = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
lv = level_parameters(8, 0.5, first=-4)[k + 4]
p = cell_problem(chi, "stretching", 1.0 / c, lv, method="rodas4-links")
ds = solve(p, Elastic.from_wave_speed(c, grid_damping=STRETCH_DAMPING), tol=stretch_tol(1e-6, c), method="rodas4-links",
           stop_floor=STRETCH_STOP_FLOOR, start="matched").dataset
a = ds.attrs
print({q: a.get(q) for q in ("v_peak", "a_peak", "sigma_peak", "t_peak", "t_a_peak", "n_rhs", "n_steps", "status", "peak_note")})
print([v for v in ds.data_vars][:60])
print({k: a[k] for k in a if "a_peak" in k or "slack" in k or "ring" in k})
t = ds["time"].values if "time" in ds.coords else ds[ds.dt.dims[0]].values
ns, dt, am, sam = ds.n_slack.values, ds.dt.values, ds.a_max.values, ds.s_a_max.values
print("t_snap-ish", t[np.argmax(ds.v_max.values)], "first slack", a["t_first_slack"], "steps after first slack", (t >= a["t_first_slack"]).sum(), "of", t.size)
i = np.argmax(am); print("a_max peak at t", t[i], "s", sam[i], "n_slack there", ns[i], "v_max", ds.v_max.values[i])
m = t >= a["t_first_slack"]
pass
pass
sm = ds.sigma_max.values; j = np.argmax(sm); iv = np.argmax(ds.v_max.values)
print("sigma_max peak at step", j, "v peak at step", iv, "of", t.size, "n_slack there", ns[j], "v_max there", ds.v_max.values[j], "sigma at v peak", sm[iv])
