"""Diagnostic: where the acceleration and tension peaks fall relative to the speed peak (issue 24,
branch snappeaks), the evidence for the snap's window of :mod:`snapping.simulate.snap_window`.

Usage: ``PYTHONPATH=src python benchmarks/snap_window_lags.py [ideal] [elastic]``

* ``ideal``: the inextensible chain (fast method, tol 1e-6) on fold levels -4 ... 0 at chi 0.1,
  0.2, 0.3, 0.5: the lag t_peak - t_snap_v of a_peak and sigma_peak and v_max there over v_peak;
* ``elastic``: the stretching study's runs (``rodas4-links``, tip links floored, matched start,
  grid damping 4, tol 1e-6 scaled) at fold level -1 of chi 0.3, c = 1000 / 442.7 / 7.53 and chi 0.5,
  c = 38.4: the run's peaks, the snap's, the window's end after the speed peak and the first slack link.
"""
import sys

import numpy as np

from snapping import regimes as R
from snapping.continuum import level_parameters
from snapping.regimes_spec import STRETCH_DAMPING, STRETCH_STOP_FLOOR, stretch_tol
from snapping.simulate import run
from snapping.simulate.elastic import Elastic, solve

LEVELS = level_parameters(8, 0.5, first=-4)


def ideal():
    for k in (-4, -3, -2, -1, 0):
        for chi in (0.1, 0.2, 0.3, 0.5):
            ds = run(R.cell_problem(chi, None, 0.0, LEVELS[k + 4]), method="fast", tol=1e-6, progress=False).dataset
            a, t, v = ds.attrs, ds.t.values, ds.v_max.values
            vs = np.interp(a["t_snap_sigma"], t, v) / a["v_peak"]
            va = np.interp(a["t_snap_a"], t, v) / a["v_peak"]
            print(f"level {k} chi {chi} links {ds.sizes['link']}: sigma lag {a['t_snap_sigma'] - a['t_snap_v']:.3g} "
                  f"(v/v_peak {vs:.4f}); a lag {a['t_snap_a'] - a['t_snap_v']:.3g} (v/v_peak {va:.4f})", flush=True)


def elastic():
    for chi, c in ((0.3, 1000.0), (0.3, 442.71632328565266), (0.3, 7.529275877145769), (0.5, 38.41511522329253)):
        p = R.cell_problem(chi, "stretching", 1.0 / c, LEVELS[3], method="rodas4-links")
        a = solve(p, Elastic.from_wave_speed(c, grid_damping=STRETCH_DAMPING), tol=stretch_tol(1e-6, c),
                  method="rodas4-links", stop_floor=STRETCH_STOP_FLOOR, start="matched").dataset.attrs
        tv = a["t_snap_v"]
        print(f"chi {chi} c {c:.4g} links {p.links.N}: v_peak {a['v_peak']:.6g}; run a_peak {a['a_peak']:.6g} "
              f"(lag {a['t_snap_a'] - tv:.3g}), sigma_peak {a['sigma_peak']:.6g} (lag {a['t_snap_sigma'] - tv:.3g}); "
              f"snap a {a['a_peak_snap']:.6g}, sigma {a['sigma_peak_snap']:.6g}, window end +{a['t_snap_end'] - tv:.3g}; "
              f"first slack {a['t_first_slack'] - tv:+.3g}", flush=True)


if __name__ == "__main__":
    what = sys.argv[1:] or ["ideal", "elastic"]
    if "ideal" in what:
        ideal()
    if "elastic" in what:
        elastic()
