"""The design answer's combined stretching factor (caps_runs.stretch_factor_body) by Radau and by RODAS4 at the
answer's tolerance (1e-5), on its two levels (50, 100 uniform links): factors and CPU per line and chi.

Usage::

    PYTHONPATH=src python benchmarks/stretch_body_methods.py
"""

import time

from snapping import caps
from snapping import caps_runs as CR

for line, chi in (("bungee-cord", 0.25), ("bungee-cord", 0.05), ("climbing-rope", 0.15), ("climbing-rope", 0.4)):
    sp = caps.spec(line)
    on = tuple(m for m in ("bending", "drag") if sp.has(m))
    for meth in ("radau", "rodas4"):
        CR.STRETCH_BODY_METHOD = meth
        out = []
        for N in CR.STRETCH_BODY_LEVELS:
            f = CR.stretch_factor_body(sp, chi, N, on, tol=1e-6, combined_tol=CR.STRETCH_BODY_TOL)
            out.append(f"N{N} v {f['v_peak']:.6f} a {f['a_peak']:.6f} T {f['sigma_peak']:.6f} cpu {f['cpu']:.2f}")
        print(line, chi, meth, " | ".join(out), "load", open("/proc/loadavg").read().split()[0], flush=True)
