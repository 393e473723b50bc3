"""The falling catenary with bending, solved by PyElastica and by this project, side by side.

The problem (nondimensional: length L = 1, mass per length lambda = 1, g = 1, time
sqrt(L/g)): the paper's level catenary of end separation ``chi`` (default 0.25), N equal
links, released from rest; bending stiffness ``B = beta lambda g L^3``, no natural
curvature; the held end a pinned free hinge (position fixed, rotation free); no damping,
no drag. Gravity along +y (y downward, the project's convention).

The same discrete chain in both codes: nodes at the project's catenary nodes (chords
exactly 1/N), node masses 1/N with half of that at the free end (``Links.uniform(N,
lumping="shared")``, PyElastica's own lumping), the bending energy B theta^2/(2 l) at every
interior node (theta the turning angle, l the node's share of arclength, Voronoi length in
PyElastica). What differs is the model of the line and the time stepping:

* this project: exactly inextensible links, link angles, error-controlled
  ``method="fast"`` (:func:`snapping.simulate.run`);
* PyElastica (``pyelastica``, import ``elastica``): a Cosserat rod, extensible and
  shearable, with rotary inertia of its cross-section, stepped by the explicit symplectic
  ``PositionVerlet`` at a fixed step. Its stretch stiffness ``EA`` is a parameter; the rod's
  radius follows from B = E pi r^4/4 and EA = E pi r^2 (r = 2 sqrt(B/EA)), its density from
  lambda = rho pi r^2, and the shear stiffness is set equal to the stretch stiffness
  (alpha_c G A = EA). The stable step is set by the shear-rotation mode of an element,
  omega ~ EA/sqrt(lambda B) (dt ~ 1.2 sqrt(B)/EA, measured), and by the axial wave
  (dt < h/sqrt(EA/lambda)); the script uses the smaller, times a safety factor.

As EA -> infinity (and dt -> 0) the rod's peaks converge to the inextensible chain's at the
same N: the error against the project's exact solution of the same chain (tol 1e-11) is
PyElastica's extensibility + rotary inertia + time-step error. The chain's own
discretisation error (N -> infinity) is the same for both and is shown separately.

Peaks: the free end's (tip's) largest speed and its time (the vertex of the parabola through
the three samples around the maximum), the tip's acceleration at the snap (largest over
t > 0.5 t_snap; at t = 0 the release from a catenary that is not in bending equilibrium
kicks the tip with an acceleration that grows with N), and the rod's largest strain.

Usage::

    python benchmarks/peers/pyelastica_catenary.py                # beta = 1e-3, N = 50, 100 (~10 min)
    python benchmarks/peers/pyelastica_catenary.py --quick        # N = 20, a few seconds
    python benchmarks/peers/pyelastica_catenary.py --beta 1e-4 --N 50 --ea 1e2,1e3
    python benchmarks/peers/pyelastica_catenary.py --continuum 50,100,200,400   # the project's N-convergence

Needs the optional ``peers`` extra (``pip install pyelastica``) for the PyElastica side;
``--help`` and the problem setup work without it.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from dataclasses import dataclass

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir))

#: the accuracy levels at which the costs are compared (relative error of the peak tip speed)
LEVELS = (1e-2, 1e-3)
#: the project's tolerances tried for the cost at matched accuracy
PROJECT_TOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
#: the tolerance of the reference solve of each chain
REF_TOL = 1e-11
#: PyElastica's step as a fraction of the measured stability limit
SAFETY = 0.6


# ---------------------------------------------------------------- the problem, in both codes
def project_problem(chi: float, N: int, beta: float):
    """This project's problem: the catenary, ``Links.uniform(N, lumping="shared")``, bending
    ``beta``, the held end a free hinge. Released from the catenary itself (``start="catenary"``,
    not the rest shape that is the default of a line with bending): PyElastica's rod is built
    on the same nodes."""
    from snapping.simulate import Body, Links, Problem

    return Problem.catenary(chi, links=Links.uniform(N, lumping="shared"), body=Body(bending=beta), start="catenary")


@dataclass(frozen=True)
class RodParameters:
    """PyElastica's rod for bending ``beta`` and stretch stiffness ``ea`` (nondimensional,
    lambda = g = L = 1)."""

    beta: float
    ea: float

    @property
    def radius(self) -> float:
        return 2.0 * math.sqrt(self.beta / self.ea)

    @property
    def area(self) -> float:
        return math.pi * self.radius ** 2

    @property
    def youngs_modulus(self) -> float:
        return self.ea / self.area

    @property
    def density(self) -> float:
        return 1.0 / self.area

    @property
    def shear_modulus(self) -> float:  # alpha_c G A = EA, PyElastica's alpha_c = 27/28
        return self.youngs_modulus * 28.0 / 27.0

    def stable_dt(self, N: int) -> float:
        """The step this script uses: SAFETY times the smaller of the shear-rotation limit
        (1.2 sqrt(B)/EA, found by trial: EA = 1e3 and 1e4 at beta = 1e-3) and the axial
        limit h/c."""
        return SAFETY * min(1.2 * math.sqrt(self.beta) / self.ea, (1.0 / N) / math.sqrt(self.ea))


def rod_geometry(p):
    """Positions (3, N+1) and directors (3, 3, N) of a planar rod through the problem's nodes
    (index 0 the free end; d1 = e_z, d3 the tangent from node j to j+1, d2 = d3 x d1)."""
    N = p.links.N
    pos = np.zeros((3, N + 1))
    pos[0], pos[1] = p.x, p.y
    d = np.diff(pos, axis=1)
    t = d / np.linalg.norm(d, axis=0)
    dirs = np.zeros((3, 3, N))
    dirs[0, 2, :] = 1.0
    dirs[2] = t
    dirs[1] = np.cross(t.T, dirs[0].T).T
    return pos, dirs


def build_pyelastica(chi: float, N: int, beta: float, ea: float):
    """(simulator, rod) of PyElastica for the problem: the rod through the project's catenary
    nodes, pinned (position only) at node N, gravity +y."""
    import elastica as ea_

    prm = RodParameters(beta, ea)
    pos, dirs = rod_geometry(project_problem(chi, N, beta))

    class Sim(ea_.BaseSystemCollection, ea_.Constraints, ea_.Forcing):
        pass

    sim = Sim()
    rod = ea_.CosseratRod.straight_rod(N, pos[:, 0].copy(), dirs[2, :, 0].copy(), np.array([0.0, 0.0, 1.0]), 1.0,
                                       prm.radius, prm.density, youngs_modulus=prm.youngs_modulus,
                                       shear_modulus=prm.shear_modulus, position=pos, directors=dirs)
    sim.append(rod)
    sim.constrain(rod).using(ea_.FixedConstraint, constrained_position_idx=(-1,))
    sim.add_forcing_to(rod).using(ea_.GravityForces, acc_gravity=np.array([0.0, 1.0, 0.0]))
    sim.finalize()
    return sim, rod


# ---------------------------------------------------------------- peaks
def vertex(t, v):
    """Largest value of the samples v(t) and its time: the vertex of the parabola through the
    three samples around the largest (the sample itself at either end)."""
    t, v = np.asarray(t, dtype=float), np.asarray(v, dtype=float)
    k = int(np.argmax(v))
    if k == 0 or k == v.size - 1:
        return float(v[k]), float(t[k])
    c2, c1, c0 = np.polyfit(t[k - 1:k + 2] - t[k], v[k - 1:k + 2], 2)
    if c2 >= 0.0:
        return float(v[k]), float(t[k])
    tv = -c1 / (2.0 * c2)
    return float(c0 - c1 * c1 / (4.0 * c2)), float(t[k] + tv)


@dataclass
class Result:
    code: str
    N: int
    setting: str  # "tol=..." or "EA=..., dt=..."
    count: int  # right-hand-side evaluations (project) or steps (PyElastica, one force evaluation each)
    wall: float
    v_peak: float
    t_peak: float
    a_snap: float
    strain: float = 0.0
    err: float = float("nan")


def run_project(chi: float, N: int, beta: float, tol: float) -> Result:
    from snapping.simulate import run

    w = time.process_time()
    p = project_problem(chi, N, beta)
    ds = run(p, method="fast", tol=tol, progress=False).dataset
    w = time.process_time() - w
    t = ds.t.values
    vp, tp = vertex(t, ds.v_end.values)
    late = t > 0.5 * tp
    ap, _ = vertex(t[late], ds.a_end.values[late])
    return Result("snapping", N, f"tol={tol:g} ({ds.attrs['method']})", int(ds.attrs["n_rhs"]), w, vp, tp, ap)


def run_pyelastica(chi: float, N: int, beta: float, ea: float, dt: float | None = None, t_max: float = 3.0,
                   stop_fraction: float = 0.5) -> Result:
    """PositionVerlet at the fixed step dt (default: :meth:`RodParameters.stable_dt`) until
    the tip speed has fallen below ``stop_fraction`` of its peak (the project's stop rule)."""
    import elastica as ea_

    dt = RodParameters(beta, ea).stable_dt(N) if dt is None else dt
    w = time.process_time()
    sim, rod = build_pyelastica(chi, N, beta, ea)
    stepper = ea_.PositionVerlet()
    n_max = int(math.ceil(t_max / dt))
    v = np.empty(n_max)
    a = np.empty(n_max)
    vel, acc, dil = rod.velocity_collection, rod.acceleration_collection, rod.dilatation
    strain, peak, t = 0.0, 0.0, 0.0
    n = 0
    for n in range(1, n_max + 1):
        t = stepper.step(sim, t, dt)
        s = math.hypot(vel[0, 0], vel[1, 0])
        v[n - 1] = s
        a[n - 1] = math.hypot(acc[0, 0], acc[1, 0])
        if n % 10 == 0:
            strain = max(strain, float(np.abs(dil - 1.0).max()))
        if not math.isfinite(s) or s > 1e3:
            raise FloatingPointError(f"PyElastica went unstable at t = {t:.4g} (N={N}, EA={ea:g}, dt={dt:.3g})")
        peak = max(peak, s)
        if peak > 0.5 and s < stop_fraction * peak:
            break
    w = time.process_time() - w
    tt = dt * np.arange(1, n + 1)
    vp, tp = vertex(tt, v[:n])
    late = tt > 0.5 * tp
    # accelerations: PositionVerlet evaluates forces at the half step
    ap, _ = vertex(tt[late] - 0.5 * dt, a[:n][late])
    return Result("PyElastica", N, f"EA={ea:g}, dt={dt:.2e}", n, w, vp, tp, ap, strain)


# ---------------------------------------------------------------- reporting
def machine():
    try:
        from bench_simulate import print_machine

        print_machine()
    except ImportError:  # pragma: no cover - the benchmarks folder moved
        print(f"machine: {os.uname().nodename}, load {os.getloadavg()[0]:.2f}\n")
    try:
        from importlib.metadata import version

        print(f"  pyelastica     {version('pyelastica')}\n")
    except Exception:
        print("  pyelastica     not installed\n")


def table(rows: list[Result]) -> None:
    print(f"  {'code':<11}{'N':>5}  {'setting':<30}{'steps/evals':>12}{'cpu s':>9}{'v_tip peak':>14}"
          f"{'t_peak':>9}{'a_tip snap':>11}{'strain':>9}{'rel err':>10}")
    for r in rows:
        st = f"{r.strain:9.1e}" if r.code == "PyElastica" else f"{'0 exact':>9}"
        print(f"  {r.code:<11}{r.N:>5}  {r.setting:<30}{r.count:>12d}{r.wall:>9.3f}{r.v_peak:>14.8f}"
              f"{r.t_peak:>9.5f}{r.a_snap:>11.4g}{st}{r.err:>10.1e}")


def matched(rows: list[Result], level: float):
    """The cheapest (CPU time) run of each code whose error is within ``level``."""
    out = {}
    for code in ("snapping", "PyElastica"):
        ok = [r for r in rows if r.code == code and r.err <= level]
        out[code] = min(ok, key=lambda r: r.wall) if ok else None
    return out


def compare(chi, N, beta, eas, tols, dt_halvings, budget, ref_tol=REF_TOL):
    """The table for one chain (chi, N, beta); returns its rows."""
    ref = run_project(chi, N, beta, ref_tol)
    rows = [run_project(chi, N, beta, tol) for tol in tols]
    t_spent = 0.0
    for ea in eas:
        dts = [RodParameters(beta, ea).stable_dt(N) / 2 ** k for k in range(dt_halvings + 1 if ea == eas[-1] else 1)]
        for dt in dts:
            if t_spent > budget:
                print(f"  (PyElastica EA={ea:g}, dt={dt:.2e} skipped: the budget of {budget:g} s is spent)")
                continue
            try:
                r = run_pyelastica(chi, N, beta, ea, dt)
            except FloatingPointError as e:
                print(f"  ({e})")
                continue
            t_spent += r.wall
            rows.append(r)
    for r in rows:
        r.err = abs(r.v_peak / ref.v_peak - 1.0)
    print(f"chi = {chi:g}, N = {N}, beta = B/(lambda g L^3) = {beta:g}; reference: this project at tol = "
          f"{ref_tol:g}: v_tip peak {ref.v_peak:.10f} at t = {ref.t_peak:.6f}, a_tip at the snap "
          f"{ref.a_snap:.5g} ({ref.count} evaluations, {ref.wall:.2f} s)")
    table(rows)
    for level in LEVELS:
        m = matched(rows, level)
        a, b = m["snapping"], m["PyElastica"]
        if a and b:
            print(f"  at {level:g}: snapping {a.wall:.4f} s ({a.setting}), PyElastica {b.wall:.2f} s ({b.setting}): "
                  f"speed-up {b.wall / a.wall:,.0f}x")
        else:
            who = " and ".join(c for c, r in m.items() if r is None)
            print(f"  at {level:g}: not reached by {who} within the runs above")
    print()
    return rows


def continuum(chi, beta, Ns, tol):
    """The project's peaks as N grows (the spatial discretisation error both codes share)."""
    print(f"the chain's N-convergence (this project, tol = {tol:g}; the same discrete chain as PyElastica's):")
    prev = None
    for N in Ns:
        r = run_project(chi, N, beta, tol)
        d = "" if prev is None else f"  change {r.v_peak / prev - 1.0:+.2e}"
        print(f"  N = {N:5d}: v_tip peak {r.v_peak:.8f} at t = {r.t_peak:.5f}, {r.count} evaluations, "
              f"{r.wall:.2f} s{d}")
        prev = r.v_peak
    print()


def _floats(s):
    return [float(x) for x in s.split(",") if x]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--chi", type=float, default=0.25, help="end separation / length (default 0.25)")
    ap.add_argument("--beta", type=float, default=1e-3, help="bending number B/(lambda g L^3) (default 1e-3)")
    ap.add_argument("--N", default="50,100", help="links, comma-separated (default 50,100)")
    ap.add_argument("--ea", default="1e2,1e3,1e4",
                    help="PyElastica's stretch (= shear) stiffness EA/(lambda g), comma-separated "
                         "(default 1e2,1e3,1e4)")
    ap.add_argument("--tols", default=",".join(f"{t:g}" for t in PROJECT_TOLS), help="this project's tolerances")
    ap.add_argument("--dt-halvings", type=int, default=1,
                    help="extra PyElastica runs at the stiffest EA with dt halved this many times (default 1)")
    ap.add_argument("--budget", type=float, default=600.0, help="CPU seconds for PyElastica per N (default 600)")
    ap.add_argument("--ref-tol", type=float, default=REF_TOL,
                    help=f"tolerance of this project's reference solve (default {REF_TOL:g})")
    ap.add_argument("--continuum", default="", help="also the project's N-convergence at these N (e.g. 50,100,200,400)")
    ap.add_argument("--quick", action="store_true", help="N = 20, EA = 1e2, 3e2: a few seconds")
    a = ap.parse_args(argv)
    sys.stdout.reconfigure(line_buffering=True)  # progress shows when the output goes to a file
    Ns = [int(x) for x in a.N.split(",") if x]
    eas, tols = _floats(a.ea), _floats(a.tols)
    if a.quick:
        Ns, eas, tols, a.dt_halvings = [20], [1e2, 3e2], [1e-4, 1e-6], 0
    try:
        import elastica  # noqa: F401
    except ImportError:
        print("pyelastica is not installed: pip install 'snapping[peers]' (or pip install pyelastica)")
        return 1
    machine()
    print(f"uptime: {os.popen('uptime').read().strip()}\n")
    # compile both codes' kernels before timing anything
    run_project(a.chi, 10, a.beta, 1e-4)
    run_pyelastica(a.chi, 10, a.beta, 1e2, t_max=1e-3)
    for N in Ns:
        compare(a.chi, N, a.beta, eas, tols, a.dt_halvings, a.budget, a.ref_tol)
    if a.continuum:
        continuum(a.chi, a.beta, [int(x) for x in a.continuum.split(",")], 1e-9)
    print(f"uptime: {os.popen('uptime').read().strip()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
