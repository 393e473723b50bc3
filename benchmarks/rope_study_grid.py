"""The combined model (the extensible line with the line's body) on the stretching study's fold grading: does a
line whose fold is capped by stretching keep that cap when its bending and drag ride along?

Usage::

    PYTHONPATH=src python benchmarks/rope_study_grid.py CHI LEVELS [MECHS]    # the climbing rope
    PYTHONPATH=src python benchmarks/rope_study_grid.py 0.1 0,1 none,drag,bending,bending+drag
    EI_FACTOR=0.01 PYTHONPATH=src python benchmarks/rope_study_grid.py 0.1 0 bending+drag
    LINE=bungee-cord PYTHONPATH=src python benchmarks/rope_study_grid.py 0.25 0,1

LEVELS: levels of :func:`snapping.continuum.level_parameters` from ``first=-1`` (the stretching study's grading,
``snapping.simulate.grading.fold_following``, no tip floor: at chi 0.1, 947, 1857, 3680 links); MECHS: a comma list
of ``+``-joined mechanisms of the line's inextensible model (``none``: the elastic line alone). The runs are the
stretching study's (``Elastic(ea, grid_damping=4)``, start ``"matched"``, ``stop_floor=1``, the snap's a and sigma
peaks) by RODAS4 at tol 1e-6, a bending line's fast waves grid-damped as the design answer's
(:func:`snapping.caps_runs.method_for`). ``EI_FACTOR`` scales the line's EI. Prints per run the peaks
(nondimensional), the fold's curvature peak, the strain peak, evaluations, CPU and the load.
"""

import math
import os
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from snapping import caps  # noqa: E402
from snapping.caps_runs import method_for, problem  # noqa: E402
from snapping.continuum import level_parameters  # noqa: E402
from snapping.simulate import grading  # noqa: E402
from snapping.simulate.elastic import Elastic, solve  # noqa: E402

chi = float(sys.argv[1])
levels = [int(x) for x in sys.argv[2].split(",")]
mechs = [() if x == "none" else tuple(x.split("+")) for x in (sys.argv[3] if len(sys.argv) > 3 else "none,bending+drag").split(",")]
name = os.environ.get("LINE", "climbing-rope")
sp = caps.spec(name)
if os.environ.get("EI_FACTOR"):
    sp = caps.spec(name, ei=sp.ei * float(os.environ["EI_FACTOR"]))
ea = sp.ea / (sp.mass * sp.g)
print(f"{name}: c {math.sqrt(ea):.4g} sqrt(gL), EI {sp.ei:.4g} N m2, chi {chi}", flush=True)
for k in levels:
    lv = level_parameters(k + 1, 0.5, first=-1)[-1]
    h = grading.fold_following(chi, frac=lv["frac"], h_min=lv["h_min"], h_max=lv["h_max"])
    for on in mechs:
        p = problem(sp, chi, h.size, on, h=h)
        stiff, _, omega_min = method_for(p, 1e-6)
        if stiff == "rodas4":
            p = problem(sp, chi, h.size, on, h=h, damping=1.0, omega_min=omega_min)
        t = time.process_time()
        a = solve(p, Elastic(ea=ea, grid_damping=4.0), tol=1e-6, method="rodas4", start="matched",
                  stop_floor=1.0).dataset.attrs
        print(f"level {k} links {h.size} (tip {h.min():.3g}) {'+'.join(on) or 'none'}: {a['status']} v {a['v_peak']:.6g} "
              f"a {a['a_peak_snap']:.6g} sigma {a['sigma_peak_snap']:.6g} kappa {a['kappa_peak']:.5g} "
              f"strain {a['strain_peak']:.3g} n_rhs {a['n_rhs']} CPU {time.process_time() - t:.1f} s "
              f"load {open('/proc/loadavg').read().split()[0]} {a.get('peak_note', '')}", flush=True)
