"""The elastic falling catenary (issue 22), solved by PyElastica and by this project, side by side.

The problem (``elastic_common.py``; nondimensional L = lambda = g = 1): the level catenary
chi = 0.25 of N links of rest length 1/N, node masses 1/N (half at the free end), axial
stiffness EA = c^2, tension-only in this project, no damping; released from rest from this
project's start (``--start``: ``stretched``, the static equilibrium; ``matched``, each link at
the rigid chain's tension just after release), the held end fixed.

PyElastica (``pyelastica``, import ``elastica``): a Cosserat rod through the same nodes, the
same rest lengths 1/N and node masses (PyElastica's own lumping: half an element at each
node), stretch stiffness EA; its shear stiffness is set equal to EA (alpha_c G A = EA) and its
bending stiffness B as small as the step allows: PositionVerlet at a fixed step dt is stable
only below about 1.2 sqrt(B)/EA (the shear-rotation mode of an element, whose rotary inertia
rho I = lambda B/EA follows from the radius r = 2 sqrt(B/EA)) and below h/c (the axial wave),
so the script takes ``B = (dt EA / 1.2 / SAFETY)^2`` (``--bend-safety``): the softest rod
stable at that step. What differs from this project's line, besides the time stepping:

* PyElastica's rod carries compression (this project's links go slack below their rest length);
* its axial force is EA (e - 1)/e for a stretch e = l/h (the internal stress EA (e - 1) is
  divided by the dilatation e), not EA (e - 1): a relative difference of the strain, 1/c^2
  at the static tensions;
* it has bending B (forced by stability: B -> 0 as dt -> 0), shear and rotary inertia.

The rod is built on the problem's unstretched catenary (chords exactly 1/N, so rest lengths,
masses and inertias are those of the unstretched rod), then its nodes are moved to the
stretched start and its directors turned to the stretched chords (no shear strain at t = 0).

Peaks: the largest node speed (samples after every step; the vertex of the parabola through
the three samples around the largest) and the largest axial force (PyElastica's internal
stress / e along d3, at the half step where PositionVerlet evaluates forces), up to the
reference's end (this project's stop at the snap).

Usage::

    python benchmarks/peers/pyelastica_elastic.py --quick               # N = 20, c = 10: seconds
    python benchmarks/peers/pyelastica_elastic.py --N 100 --c 30         # one point (minutes)
    python benchmarks/peers/pyelastica_elastic.py --N 400 --c 300 --dt 3.9e-6 --method dop853
    python benchmarks/peers/pyelastica_elastic.py --help

Needs the optional ``peers`` extra for the PyElastica side; ``--help`` works without it.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import elastic_common as E  # noqa: E402

#: the step as a fraction of the axial limit h/c (PositionVerlet: 2/omega_max = h/c)
AXIAL_SAFETY = 0.8
#: B chosen so that dt = BEND_SAFETY * 1.2 sqrt(B)/EA
BEND_SAFETY = 0.8


def bending_for(dt: float, ea: float, safety: float = BEND_SAFETY) -> float:
    """The smallest bending stiffness B (units of lambda g L^3) at which PositionVerlet at ``dt``
    stays stable: dt = safety * 1.2 sqrt(B)/EA."""
    return (dt * ea / (1.2 * safety)) ** 2


def build_pyelastica(chi: float, N: int, c: float, B: float, start: str = "stretched"):
    """(simulator, rod) of PyElastica for the elastic catenary: rest lengths 1/N, node masses
    1/N (1/(2N) at the free end), stretch = shear stiffness EA = c^2, bending B; nodes at the
    stretched start, directors along its chords, the held end (node N) pinned, gravity +y."""
    import elastica as ea_

    ea = c * c
    r = 2.0 * math.sqrt(B / ea)  # B = E pi r^4/4, EA = E pi r^2
    area = math.pi * r * r
    E_ = ea / area
    p = E.problem(chi, N)
    pos0 = np.zeros((3, N + 1))
    pos0[0], pos0[1] = p.x, p.y
    xs, ys, vxs, vys = E.start_state(chi, N, c, start)
    pos = np.zeros((3, N + 1))
    pos[0], pos[1] = xs, ys

    def directors(q):
        d = np.diff(q, axis=1)
        t = d / np.linalg.norm(d, axis=0)
        dirs = np.zeros((3, 3, N))
        dirs[0, 2, :] = 1.0
        dirs[2] = t
        dirs[1] = np.cross(t.T, dirs[0].T).T
        return dirs

    class Sim(ea_.BaseSystemCollection, ea_.Constraints, ea_.Forcing):
        pass

    sim = Sim()
    d0 = directors(pos0)
    rod = ea_.CosseratRod.straight_rod(N, pos0[:, 0].copy(), d0[2, :, 0].copy(), np.array([0.0, 0.0, 1.0]), 1.0, r,
                                       1.0 / area, youngs_modulus=E_, shear_modulus=E_ * 28.0 / 27.0, position=pos0,
                                       directors=d0)
    rod.position_collection[:] = pos
    rod.director_collection[:] = directors(pos)
    rod.velocity_collection[0], rod.velocity_collection[1] = vxs, vys
    sim.append(rod)
    sim.constrain(rod).using(ea_.FixedConstraint, constrained_position_idx=(-1,))
    sim.add_forcing_to(rod).using(ea_.GravityForces, acc_gravity=np.array([0.0, 1.0, 0.0]))
    sim.finalize()
    return sim, rod


def run_pyelastica(chi: float, N: int, c: float, dt: float, B: float | None = None, t_end: float | None = None,
                   stop_fraction: float = 0.5, start: str = "stretched") -> E.Result:
    """PositionVerlet at the fixed step ``dt`` to ``t_end`` (the reference's end), or without
    it until the speed has fallen below ``stop_fraction`` of its running peak (after t = 0.8);
    B defaults to :func:`bending_for`."""
    import elastica as ea_

    B = bending_for(dt, c * c) if B is None else B
    w = time.process_time()
    sim, rod = build_pyelastica(chi, N, c, B, start)
    stepper = ea_.PositionVerlet()
    n_max = int(math.ceil((3.0 if t_end is None else t_end) / dt - 1e-9))
    v = np.empty(n_max)
    T = np.empty(n_max)
    vel, stress, dil = rod.velocity_collection, rod.internal_stress, rod.dilatation
    peak, t, n, fmin = 0.0, 0.0, 0, 0.0
    for n in range(1, n_max + 1):
        t = stepper.step(sim, t, dt)
        s = math.sqrt(float((vel[0, :N] ** 2 + vel[1, :N] ** 2).max()))
        v[n - 1] = s
        f = stress[2] / dil
        T[n - 1] = float(f.max())
        fmin = min(fmin, float(f.min()))
        if not math.isfinite(s) or s > 1e3:
            raise FloatingPointError(f"PyElastica went unstable at t = {t:.4g} (N={N}, c={c:g}, dt={dt:.3g}, "
                                     f"B={B:.3g})")
        peak = max(peak, s)
        if t_end is None and t > 0.8 and s < stop_fraction * peak:
            break
    w = time.process_time() - w
    tt = dt * np.arange(1, n + 1)
    vp, tp = E.vertex(tt, v[:n])
    sp, ts = E.vertex(tt - 0.5 * dt, T[:n])
    return E.Result("PyElastica", N, c, f"dt={dt:.3g} B={B:.2g}", n, w, vp, tp, sp, ts,
                    f"largest compression {-fmin:.3g} (this project's links go slack instead)", t, start=start)


def axial_dt(N: int, c: float) -> float:
    return AXIAL_SAFETY / (N * c)


def compare(chi, N, c, dts, method, budget, tols=E.PROJECT_TOLS, project_budget=300.0, with_ref=True,
            start="stretched"):
    ref = E.reference(chi, N, c, start=start) if with_ref else None
    if ref:
        E.header(ref, chi)
    else:
        print(f"chi = {chi:g}, N = {N}, c/sqrt(gL) = {c:g}: no reference (--no-reference); PyElastica runs to its snap")
    rows = E.project_rows(chi, N, c, ref, method=method, tols=tols, budget=project_budget, start=start) if ref else []
    spent = 0.0
    for dt in dts:
        if spent > budget:
            print(f"  (PyElastica dt={dt:.3g} skipped: the budget of {budget:g} s is spent)")
            continue
        try:
            r = run_pyelastica(chi, N, c, dt, t_end=ref.t_end if ref else None, start=start)
        except FloatingPointError as e:
            print(f"  ({e})")
            continue
        spent += r.cpu
        rows.append(E.score(r, ref) if ref else r)
        if E.error(r) <= min(E.LEVELS):
            break
    E.table(rows)
    for r in rows:
        if r.code == "PyElastica":
            print(f"  PyElastica {r.setting}: {r.extra}")
    E.matched(rows, "PyElastica", ref=ref)
    print(flush=True)
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    E.add_arguments(ap, "PyElastica")
    ap.add_argument("--dt", default="",
                    help="PyElastica's steps, comma-separated (default: the axial limit 0.8 h/c, then halved "
                         "--halvings times); B follows each step")
    ap.add_argument("--halvings", type=int, default=3, help="default steps: the axial limit halved this many times")
    ap.add_argument("--quick", action="store_true", help="N = 20, c = 10, two steps (h/(20 c), h/(40 c)): seconds")
    a = ap.parse_args(argv)
    sys.stdout.reconfigure(line_buffering=True)
    Ns, cs, tols = E.apply_arguments(a)
    quick_dts = []
    if a.quick:  # c = 10: a rod soft enough in bending (B ~ 1e-4) at steps of 1e-4
        Ns, cs, tols, a.method = [20], [10.0], [1e-4, 1e-6], "dop853"
        E.LEVELS = (1e-2, 1e-3)
        quick_dts = [axial_dt(20, 10.0) / 16, axial_dt(20, 10.0) / 32]
    from snapping.simulate.elastic import METHODS

    for m in a.method.lower().split(",") + [E.REF_METHOD]:
        if m not in METHODS:
            print(f"--method {m!r} is not one of {tuple(METHODS)}", file=sys.stderr)
            return 2
    try:
        import elastica  # noqa: F401
    except ImportError:
        print("pyelastica is not installed: pip install 'snapping[peers]' (or pip install pyelastica)")
        return 1
    E.machine("pyelastica")
    run_pyelastica(a.chi, 10, 30.0, 1e-4, t_end=1e-3)  # compile before timing
    for N in Ns:
        for c in cs:
            dts = quick_dts or [float(x) for x in a.dt.split(",") if x] or \
                [axial_dt(N, c) / 2 ** k for k in range(a.halvings + 1)]
            compare(a.chi, N, c, dts, a.method.lower(), a.budget, tols, with_ref=not a.no_reference, start=a.start)
    print(f"uptime: {os.popen('uptime').read().strip()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
