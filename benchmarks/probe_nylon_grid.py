"""Where the graded nylon answer's error lives, and what sets its steps (``design10``, issue 24).

Runs the nylon line's full model (every mechanism but stretching) on variants of graded level
``--level`` (:func:`snapping.caps_runs.graded_h`: links along the fold's path ``FOLD_LINK`` l_b
at the fold's scale, ``TIP_LINK`` l_b at the free end, ``HELD_LINK`` l_b on the held arm), by
RODAS4 at :data:`snapping.caps_runs.GRADED_TOL` with :data:`snapping.caps_runs.GRADED_DAMPING`,
as :meth:`snapping.caps_runs.Runs.graded` does, and prints links, CPU, steps, rejections and the
peaks (SI) of each. A variant is a JSON object of:

* ``fold``, ``tip``, ``held``: factors on the three link lengths (0.5: that part refined as the next
  level would, the others not);
* ``gscale``: true to scale the grading's slope ``gamma`` with the level too (by default it is not:
  the transitions are not halved);
* ``below``, ``by``, ``w``: the links refined by the factor ``by`` where x (from the free end) <
  ``below`` (a tanh step of width ``w``);
* ``cap``: the fold's links at most ``cap`` l_b (times the level's factor);
* ``radius``: instead, the links along the fold's path ``radius`` times the fold's smallest radius
  there as measured on level 0 at chi 0.1 (:data:`FOLD_RADIUS`; ``bench_caps.py --profile``), at
  least half the free end's link;
* ``tol``, ``damp``: RODAS4's tolerance and the damping ratio;
* ``nowd``: true to run without the stage terms of the work and dissipation rows (before ``dragexact``,
  with drag, each was one forward difference, a full right side, per stage; now the dissipation row's
  are the drag power's exact gradient, one O(N) pass per step): those two rows come out wrong, the
  dynamics do not; it measures what the rows' stage terms cost;
* ``fd``: true to take those stage terms by forward differences, the route before ``dragexact``.

Usage::

    python benchmarks/probe_nylon_grid.py --chi 0.1 '{}' '{"fold": 0.5}' '{"tip": 0.5}' '{"held": 0.5}'
    python benchmarks/probe_nylon_grid.py --chi 0.1 '{"below": 0.05, "by": 0.5, "w": 0.01}' '{"cap": 0.8}'
    python benchmarks/probe_nylon_grid.py --chi 0.1 --level 1 '{"gscale": true}' '{"damp": 0.1}'
    python benchmarks/probe_nylon_grid.py --chi 0.1 --level 1 '{}' '{"nowd": true}'
    python benchmarks/probe_nylon_grid.py --chi 0.1 --level 1 '{"fd": true}' '{}' '{"fd": true}' '{}'
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import time

import numpy as np

from snapping import caps, estimates
from snapping import caps_runs as CR
from snapping.simulate import grading, run

KEYS = {"fold", "tip", "held", "gscale", "below", "by", "w", "cap", "radius", "tol", "damp", "nowd", "fd"}
#: the nylon line's fold at chi 0.1: its smallest radius (bending lengths) against x from the free end, on
#: graded level 0 at tol 1e-3 (``python benchmarks/bench_caps.py --profile nylon-monofilament --chi 0.1 --levels 0``)
FOLD_RADIUS = ((0.0, 0.01, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6),
               (0.96, 0.96, 1.32, 2.51, 3.49, 4.95, 8.17, 14.27, 14.27))


def links(chi: float, lb: float, level: int, fold=1.0, tip=1.0, held=1.0, gscale=False, below=0.0, by=1.0,
          w=0.02, cap=None, radius=None) -> np.ndarray:
    """Graded level ``level`` (:func:`snapping.caps_runs.graded_h`'s spacing) with the variant's changes."""
    k = 0.5 ** level
    a = estimates.catenary_parameter(chi)
    h_max = min(0.5, CR.HELD_LINK * lb) * k * held
    h_min = min(h_max, CR.TIP_LINK * lb * k * tip)
    frac = min(0.5, max(CR.FOLD_LINK * lb / a, CR.FOLD_FRAC)) * k * fold  # graded_h's floor (``heldarm``)
    gamma = 0.1 * (k if gscale else 1.0)
    xf = 0.6  # grading.fold_following's 1/2 + margin

    def spacing(x):
        f = frac * a * np.power(np.minimum(2.0 * x, 1.0), 0.25)
        if cap is not None:
            f = np.minimum(f, cap * lb * k)
        if radius is not None:
            X, R = FOLD_RADIUS
            f = np.maximum(0.5 * h_min, radius * lb * k * np.exp(np.interp(x, X, np.log(R))))
            target = np.where(x <= xf, f, radius * lb * k * R[-1] + gamma * (x - xf))
        else:
            target = np.where(x <= xf, f, frac * a + gamma * (x - xf))
        lo = 0.5 * h_min if radius is not None else h_min
        s = np.maximum(lo, np.minimum(np.minimum(target, h_max), h_min + gamma * x))
        if below > 0.0:
            s = np.maximum(h_min * min(by, 1.0), s * (by + (1.0 - by) * 0.5 * (1.0 + np.tanh((x - below) / w))))
        return s

    return grading.from_spacing(spacing, h_min * min(by, 1.0) * (0.5 if radius is not None else 1.0))


@contextlib.contextmanager
def _without_wd(on: bool, fd: bool = False):
    """RODAS4's engines made meanwhile drop the W/D rows' stage terms (``rosenbrock.RP_QUAD``, ``RP_QFD``),
    or (``fd``) take them by forward differences, the route before ``dragexact``."""
    if not (on or fd):
        yield
        return
    from snapping.simulate import rosenbrock as RB
    from snapping.simulate.methods import rodas4 as M4

    orig = M4.Engine.__init__

    def init(self, *a, **kw):
        orig(self, *a, **kw)
        if on:
            self.rp[RB.RP_QUAD] = 0.0
            self.rp[RB.RP_QFD] = 0.0
        elif self.rp[RB.RP_QUAD] != 0.0:
            self.rp[RB.RP_QFD] = 1.0

    M4.Engine.__init__ = init
    try:
        yield
    finally:
        M4.Engine.__init__ = orig


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("variants", nargs="*", default=["{}"])
    p.add_argument("--chi", type=float, default=0.1)
    p.add_argument("--level", type=int, default=0)
    a = p.parse_args(argv)
    sp = caps.spec("nylon-monofilament")
    on = tuple(m for m in CR.MECHANISMS[:-1] if sp.has(m))
    lb = CR.bending_length(sp)
    caps.cap("nylon-monofilament", a.chi, N=8, check=False, alone=False, graded=False)  # compile
    print(f"nylon-monofilament, chi = {a.chi:g}, level {a.level}; load {os.getloadavg()[0]:.1f}")
    print("| variant | links | CPU s | steps | rejected | evaluations | T (N) | v (m/s) | a (m/s^2) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for v in a.variants:
        d = json.loads(v)
        bad = set(d) - KEYS
        if bad:
            p.error(f"unknown keys {sorted(bad)} (known: {sorted(KEYS)})")
        tol, damp, nowd = d.pop("tol", CR.GRADED_TOL), d.pop("damp", CR.GRADED_DAMPING), d.pop("nowd", False)
        fd = d.pop("fd", False)
        h = links(a.chi, lb, a.level, **d)
        pr = CR.problem(sp, a.chi, h.size, on, damping=damp, omega_min=0.0, h=h)
        c0 = time.process_time()
        with _without_wd(nowd, fd):
            at = run(pr, method="rodas4", tol=tol, progress=False).dataset.attrs
        cpu = time.process_time() - c0
        si = caps._si(sp, {q: float(at[q]) for q in CR.QUANTITIES})
        print(f"| {v} | {h.size} | {cpu:.2f} | {at['n_steps']} | {at['n_rejected']} | {at['n_rhs']} | "
              f"{si['sigma_peak']:.6g} | "
              f"{si['v_peak']:.5g} | {si['a_peak']:.5g} |", flush=True)
    print(f"load {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
