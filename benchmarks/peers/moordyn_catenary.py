"""SKETCH for issue 22: the falling catenary in MoorDyn (PyPI ``moordyn``), an elastic line.

Not yet the issue's benchmark: this project has no elastic chain on main yet, so the
comparison here is MoorDyn's elastic line against this project's *inextensible* chain (the
limit c -> infinity). It shows that MoorDyn can pose the problem, what it gives, and what it
costs; the side-by-side at c/sqrt(gL) = 30 and 300 waits for the elastic model.

The problem in MoorDyn (SI: L = 1 m, lambda = 1 kg/m, g = 9.81 m/s^2; MoorDyn's own g): one
line of N segments between a Fixed point (the held end, at the origin) and a Free point of no
mass (the free end, at (chi, 0, 0)); EA = lambda g L (c/sqrt(gL))^2; no drag, no added mass,
no internal damping, water density 0 (no buoyancy), deep water (no seabed). MoorDyn places
the line on its own *elastic* static catenary (its initial-condition solver) with both ends
held, then ``Step`` releases the free point. The start therefore differs from the project's
catenary by the static strain (~ T/EA ~ (c^2 / (gL))^-1). MoorDyn's default time scheme
(RK2) at a fixed step ``dt`` (``--dt``; stable below about 2 pi / omega_n, omega_n = 2 (N/L)
sqrt(EA/lambda)).

Usage::

    python benchmarks/peers/moordyn_catenary.py --c 30 --N 50 --dt 1e-4
    python benchmarks/peers/moordyn_catenary.py --quick
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time

import numpy as np

G = 9.81

INPUT = """--------------------- MoorDyn Input File ------------------------------------
Falling catenary (snapping benchmarks/peers/moordyn_catenary.py)
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA     BA/-zeta    EI    Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)    (N-s/-)     (N-m^2) (-)   (-)    (-)     (-)
chain      {diam:.6g}   1.0    {ea:.10g}   0    0     0      0      0       0
---------------------- POINTS --------------------------------
ID    Attachment  X       Y     Z      M      V      CdA   CA
(#)   (-)         (m)     (m)   (m)    (kg)   (m^3)  (m^2) (-)
1     Fixed       0       0     0      0      0      0     0
2     Free        {chi:.17g}    0     0      0      0      0     0
---------------------- LINES --------------------------------------
ID   LineType  AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)  (name)    (#)      (#)      (m)       (-)      (-)
1    chain     1        2        1.0       {N}       -
---------------------- OPTIONS -----------------------------------------
{dt:.6g}     dtM
1000     WtrDpth
0.0      WtrDnsty
0        dtIC
---------------------- OUTPUTS -----------------------------------------
END
"""


def run_moordyn(chi: float, N: int, c: float, dt: float, t_max: float = 3.0, stop_fraction: float = 0.5):
    """(peak tip speed / sqrt(gL), its time / sqrt(L/g), steps, CPU s) of MoorDyn's line."""
    import moordyn

    ea = G * c * c  # lambda = L = 1
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "lines.txt")
        with open(path, "w") as fh:
            fh.write(INPUT.format(diam=1e-3, ea=ea, chi=chi, N=N, dt=dt))
        w = time.process_time()
        s = moordyn.Create(path)
        moordyn.SetVerbosity(s, moordyn.LEVEL_ERR)
        if moordyn.Init(s, [], []) != 0:
            raise RuntimeError("MoorDyn's Init failed")
        tip = moordyn.GetPoint(s, 2)
        n_max = int(math.ceil(t_max * math.sqrt(1.0 / G) / dt))
        v = np.empty(n_max)
        t, peak, n = 0.0, 0.0, 0
        for n in range(1, n_max + 1):
            moordyn.Step(s, [], [], t, dt)
            t += dt
            u = moordyn.GetPointVel(tip)
            v[n - 1] = math.sqrt(u[0] ** 2 + u[1] ** 2 + u[2] ** 2)
            peak = max(peak, v[n - 1])
            if peak > 0.5 * math.sqrt(G) and v[n - 1] < stop_fraction * peak:
                break
        w = time.process_time() - w
        moordyn.Close(s)
    k = int(np.argmax(v[:n]))
    return v[k] / math.sqrt(G), (k + 1) * dt * math.sqrt(G), n, w


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--N", type=int, default=50)
    ap.add_argument("--c", type=float, default=30.0, help="wave speed sqrt(EA/lambda) / sqrt(gL) (default 30)")
    ap.add_argument("--dt", type=float, default=1e-4, help="MoorDyn's step in seconds (default 1e-4)")
    ap.add_argument("--quick", action="store_true", help="N = 20, c = 30, dt = 2e-4")
    a = ap.parse_args(argv)
    if a.quick:
        a.N, a.c, a.dt = 20, 30.0, 2e-4
    try:
        import moordyn  # noqa: F401
    except ImportError:
        print("moordyn is not installed: pip install moordyn")
        return 1
    from snapping.simulate import Links, Problem, run

    vp, tp, n, w = run_moordyn(a.chi, a.N, a.c, a.dt)
    p = Problem.catenary(a.chi, links=Links.uniform(a.N, lumping="shared"))
    w2 = time.process_time()
    ds = run(p, tol=1e-10, progress=False).dataset
    w2 = time.process_time() - w2
    k = int(np.argmax(ds.v_end.values))
    print(f"chi = {a.chi:g}, N = {a.N}, c/sqrt(gL) = {a.c:g}")
    print(f"  MoorDyn (elastic, RK2, dt = {a.dt:g} s): tip speed peak {vp:.6f} sqrt(gL) at t = {tp:.5f} "
          f"sqrt(L/g); {n} steps, {w:.2f} s CPU")
    print(f"  snapping (inextensible, tol 1e-10): tip speed peak {float(ds.v_end.values[k]):.6f} at t = "
          f"{float(ds.t.values[k]):.5f}; {int(ds.attrs['n_rhs'])} evaluations, {w2:.2f} s CPU")
    return 0


if __name__ == "__main__":
    sys.exit(main())
