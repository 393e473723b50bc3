"""Diagnostic: where a stretching cell's tension peaks against the snap's windows (issue 24, branch stretch1pct).

Usage: ``PYTHONPATH=src python benchmarks/stretch_taut.py CHI C K [CHI C K ...]`` (K the fold level of
``level_parameters(8, 0.5, first=-4)``, the study's levels are -1 ... 3). Runs the cell as the study runs
it (``rodas4-links``, tip links floored, matched start, grid damping 4, ``stretch_tol``) and prints, in
time after the speed peak (t sqrt(g/L)): the 0.9 window's end and the tension there, the first slack
link after the peak, the largest tension before it (the taut snap's: value, time, v_max over its peak,
where along the line s from the held end, and whether it is a turning point, i.e. not the window's last
step), the run's own tension peak, and the wave's crossing time L/c. Measured (docs/guide/regimes.md,
"The taut snap's tension"): ``0.5 38.41511522329253 -1``, ``0.3 442.71632328565266 -1``,
``0.1 7.529275877145769 -1`` and others.
"""
import sys
import time

import numpy as np

from snapping.continuum import level_parameters
from snapping.regimes import cell_problem
from snapping.regimes_spec import STRETCH_DAMPING, STRETCH_STOP_FLOOR, stretch_tol
from snapping.simulate.elastic import Elastic, solve


def one(chi, c, k):
    lv = level_parameters(8, 0.5, first=-4)[k + 4]
    p = cell_problem(chi, "stretching", 1.0 / c, lv, method="rodas4-links")
    t0 = time.process_time()
    ds = solve(p, Elastic.from_wave_speed(c, grid_damping=STRETCH_DAMPING), tol=stretch_tol(1e-6, c),
               method="rodas4-links", stop_floor=STRETCH_STOP_FLOOR, start="matched").dataset
    a = ds.attrs
    t, v, sm, ns = ds.t.values, ds.v_max.values, ds.sigma_max.values, ds.n_slack.values
    iv = int(np.argmax(v))
    je = int(np.searchsorted(t, a["t_snap_end"]))
    after = np.flatnonzero((t >= t[iv]) & (ns > 0))
    jf = int(after[0]) if after.size else t.size - 1
    jm = int(np.argmax(sm[:jf + 1]))
    print(f"chi {chi:g} c {c:.4g} level {k} ({p.links.N} links, {time.process_time() - t0:.1f} s CPU): v_peak "
          f"{v[iv]:.5f}; 0.9 window end +{t[je] - t[iv]:.2e}, sigma there {sm[je]:.4f} (sigma_peak_snap "
          f"{a['sigma_peak_snap']:.4f}); first slack after the peak "
          f"{'+%.2e' % (t[jf] - t[iv]) if after.size else 'none (run end +%.2e)' % (t[-1] - t[iv])}; taut max "
          f"{sm[jm]:.4f} at +{t[jm] - t[iv]:.2e}, v/v_peak {v[jm] / v[iv]:.3f}, s {ds.s_sigma_max.values[jm]:.4f}, "
          f"turning point {jm < jf} (sigma_peak_taut {a['sigma_peak_taut']:.4f}); run's sigma_peak "
          f"{a['sigma_peak']:.4f} at +{a['t_snap_sigma'] - t[iv]:.2e}; L/c {1.0 / c:.2e}", flush=True)


if __name__ == "__main__":
    args = sys.argv[1:]
    for i in range(0, len(args), 3):
        one(float(args[i]), float(args[i + 1]), int(args[i + 2]))
