"""The combined model (extensible line + the line's bending and drag) on a catalogue line, against the
inextensible real model, on uniform links: does stretching resolve the snap where the links do not?

Usage::

    PYTHONPATH=src python benchmarks/rope_combined.py CHI N1 N2 ...          # the climbing rope
    LINE=bungee-cord PYTHONPATH=src python benchmarks/rope_combined.py 0.25 50 100 200
    METHOD=rodas4 GRADED=1 PYTHONPATH=src python benchmarks/rope_combined.py 0.1 0 1   # graded levels 0, 1

``METHOD``: the combined run's method (default radau; rodas4 takes a body since branch rodasbody);
``GRADED=1``: the numbers after CHI are levels of ``caps_runs.graded_h`` (graded links), not N;
``SKIP_RIGID=1``: no inextensible run.

Prints per N the combined run's peaks (Radau tol 1e-6, start "matched", grid damping 1; nondimensional),
its strain peak, evaluations and CPU, and the inextensible run with the same body (RODAS4 tol 1e-4).
"""

import math
import os
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from snapping import caps  # noqa: E402
from snapping.caps_runs import _run, bending_length, graded_h, problem  # noqa: E402
from snapping.simulate.elastic import Elastic, solve  # noqa: E402

chi = float(sys.argv[1])
Ns = [int(x) for x in sys.argv[2:]]
sp = caps.spec(os.environ.get("LINE", "climbing-rope"))
ea = sp.ea / (sp.mass * sp.g)
c = math.sqrt(ea)  # (lambda = 1)
print(f"{os.environ.get('LINE', 'climbing-rope')}: L {sp.length} m, c {c:.4g} sqrt(gL) = {c * math.sqrt(sp.g * sp.length):.4g} m/s; chi {chi}",
      flush=True)
method = os.environ.get("METHOD", "radau")
graded = os.environ.get("GRADED", "") == "1"
for N in Ns:
    if graded:
        h = graded_h(chi, bending_length(sp), N)
        p = problem(sp, chi, h.size, ("bending", "drag"), h=h)
        print(f"graded level {N}: {h.size} links, h {h.min():.3g} .. {h.max():.3g}; method {method}", flush=True)
        N = h.size
    else:
        p = problem(sp, chi, N, ("bending", "drag"), lumping="shared")
    t = time.process_time()
    a = solve(p, Elastic(ea=ea, grid_damping=1.0), tol=1e-6, method=method, start="matched").dataset.attrs
    print(f"N {N} combined: {a['status']} v {a['v_peak']:.5g} a {a['a_peak']:.5g} sigma {a['sigma_peak']:.5g} "
          f"kappa {a['kappa_peak']:.5g} strain {a.get('strain_peak', float('nan')):.3g} n_rhs {a['n_rhs']} "
          f"CPU {time.process_time() - t:.1f} s", flush=True)
    if os.environ.get("SKIP_RIGID", "") == "1":
        continue
    t = time.process_time()
    q = _run(p, "rodas4", 1e-4)
    print(f"N {N} inextensible: v {q['v_peak']:.5g} a {q['a_peak']:.5g} sigma {q['sigma_peak']:.5g} "
          f"kappa {q['kappa_peak']:.5g} CPU {time.process_time() - t:.1f} s", flush=True)
