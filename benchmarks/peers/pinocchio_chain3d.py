"""The 3D chain with an out-of-plane kick, solved by Pinocchio and by this project, side by side.

The problem (nondimensional: length L = 1, mass 1, g = 1 along +y, y downward): the
paper's level catenary of end separation ``chi`` (default 0.25), N equal links, with the
out-of-plane velocity ``eps sin(pi s/L) zhat`` added (s the arclength from the held end,
default eps = 1e-2; :meth:`snapping.spatial.Problem3D.perturbed`), the chain's masses
lumped consistently (``Links.uniform(N, lumping="shared")``: 1/N at every node, 1/(2N) at
the free end), the held end fixed at the origin. No bending, no drag.

The same discrete chain in both codes:

* this project: exactly inextensible links (unit link directions, the tridiagonal tension
  system), error-controlled DOP853 with projection and dense-output peaks
  (:func:`snapping.spatial.run3d`);
* Pinocchio (``pin``, import ``pinocchio``): a kinematic tree of N rigid bodies, body k
  (k = 1..N) the link from node N - k + 1 to node N - k, joined to its parent by a
  spherical joint (the first at the held end, fixed in the world), carrying the point mass
  of node N - k at its far end (lever ``h (1, 0, 0)`` in the body's frame) and a rotational
  inertia ``J = m h^2`` about its own axis only. A point mass has no inertia about the
  link's axis, which would make the articulated-body inertia singular; the axial inertia
  fixes that without changing the motion: spherical joints at points on the axis exert no
  axial torque, the inertia is axisymmetric, so the spin about the link's axis stays what it
  started at (zero) and a spin-free rigid link moves exactly as the massless link of the
  point-mass chain. J must stay at the link's own scale: a Runge-Kutta stage's state carries
  a spin of the step's size, and its gyroscopic torque J w_s e' acts on the transverse
  inertia m h^2 (J = M L^2 at N = 200 blows up in the first step at any dt); at J = m h^2
  the articulated inertias are ill-conditioned (the spin's acceleration comes out at 1e-8 of
  the others near the root), but the node accelerations agree with the tension solve to
  1e-9 (tested). Forward dynamics by the articulated-body algorithm (``pin.aba``, O(N)
  operations); but ``model.createData()`` for this tree takes memory growing as N^3 (6.7 GB
  at N = 200, measured by ``--memory``), so N = 500 (about 100 GB) does not fit here.
  Time stepping: classical RK4 at a fixed step, on the Lie group (Runge-Kutta-Munthe-Kaas:
  in each step the configuration is ``q = integrate(q0, xi)`` with ``xi' = dexp^{-1}_xi(v)``
  per spherical joint, and ``pin.integrate`` makes each stage's and the step's
  configuration; order 4, unit quaternions to round-off). Pinocchio has no error-controlled
  integrator; a fixed step is what its users write. (Scipy's DOP853 over ABA would need the
  Lie-group re-basing inside scipy's stepper; not done here.)

Peaks: the free end's (tip's) largest speed and its time, from the cubic Hermite
interpolant of the tip speed and its derivative (``v . a/|v|``) between Pinocchio's steps,
and the out-of-plane amplitude ``max_j |z_j|`` at that time (quadratic through the three
steps around it); for this project, ``run3d``'s peak of the largest node speed (the tip's,
checked: ``v_end_snap``) located on the dense output. Errors against this project's
reference at ``--ref-tol`` (1e-12).

Usage::

    python benchmarks/peers/pinocchio_chain3d.py                  # N = 200, 500
    python benchmarks/peers/pinocchio_chain3d.py --quick          # N = 20, seconds
    python benchmarks/peers/pinocchio_chain3d.py --N 200 --dt 4e-5,2e-5,1e-5 --budget 300
    python benchmarks/peers/pinocchio_chain3d.py --memory 25,50,100,200,300

Needs the optional ``peers`` extra (``pip install pin``) for the Pinocchio side; ``--help``
and the problem setup work without it.
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
LEVELS = (1e-3, 1e-5)
#: the project's tolerances tried for the cost at matched accuracy
PROJECT_TOLS = (1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
#: Pinocchio's fixed steps tried (halvings of the first)
PIN_DTS = (1e-4, 5e-5, 2.5e-5, 1.25e-5, 6.25e-6)
REF_TOL = 1e-12
EPS = 1e-2
AXIS = np.array([1.0, 0.0, 0.0])  # the link's direction (held end -> free end) in its body's frame


# ---------------------------------------------------------------- the problem, in both codes
def project_problem(chi: float, N: int, eps: float = EPS):
    """This project's problem: the catenary, consistent lumping, the velocity kick ``eps sin``."""
    from snapping.simulate import Links
    from snapping.spatial import Problem3D

    return Problem3D.catenary(chi, links=Links.uniform(N, lumping="shared")).perturbed(eps, "sin")


def _rotation_to(a, b):
    """The rotation of least angle taking the unit vector a to the unit vector b."""
    v = np.cross(a, b)
    c = float(np.dot(a, b))
    s = float(np.linalg.norm(v))
    if s < 1e-15:
        if c > 0.0:
            return np.eye(3)
        p = np.array([0.0, 1.0, 0.0]) if abs(a[1]) < 0.9 else np.array([0.0, 0.0, 1.0])
        k = np.cross(a, p)
        k /= np.linalg.norm(k)
        return 2.0 * np.outer(k, k) - np.eye(3)
    K = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    return np.eye(3) + K + K @ K * ((1.0 - c) / s ** 2)


def build_pinocchio(p):
    """(model, data, q0, v0, node_frames) of Pinocchio for the Problem3D ``p`` (fixed held end):
    ``node_frames[j]`` the frame id at node j (0 the free end; node N, the held end, is the
    first joint's origin)."""
    import pinocchio as pin

    N = p.N
    h, m = p.links.h, p.links.m
    model = pin.Model()
    model.gravity = pin.Motion(p.gravity * np.asarray(p.g_dir, dtype=float), np.zeros(3))
    frames = [0] * (N + 1)
    parent = 0
    R_par = np.eye(3)
    qs, vs = [], []
    omega_par = np.zeros(3)
    for k in range(1, N + 1):
        j = N - k  # the link (and its far node) this body carries
        place = pin.SE3.Identity() if k == 1 else pin.SE3(np.eye(3), h[j + 1] * AXIS)
        jid = model.addJoint(parent, pin.JointModelSpherical(), place, f"joint{k}")
        J = m[j] * h[j] ** 2  # the link's own scale (see the module's docstring)
        model.appendBodyToJoint(jid, pin.Inertia(float(m[j]), h[j] * AXIS, np.diag([J, 0.0, 0.0])),
                                pin.SE3.Identity())
        if k == 1:
            frames[N] = model.addFrame(pin.Frame(f"node{N}", jid, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
        frames[j] = model.addFrame(pin.Frame(f"node{j}", jid, 0, pin.SE3(np.eye(3), h[j] * AXIS),
                                             pin.FrameType.OP_FRAME))
        # the body's orientation: AXIS onto the link, node j+1 -> node j; no spin
        d = p.r[j] - p.r[j + 1]
        b = d / np.linalg.norm(d)
        R = _rotation_to(AXIS, b)
        R_rel = R_par.T @ R
        qs.append(pin.Quaternion(R_rel).coeffs())  # (x, y, z, w)
        u = (p.v[j] - p.v[j + 1]) / h[j]  # the link direction's rate
        omega = np.cross(b, u)  # the link's angular velocity, normal to it (no spin)
        vs.append(R.T @ (omega - omega_par))  # the joint's velocity: relative, in the child's frame
        parent, R_par, omega_par = jid, R, omega
    data = model.createData()
    return model, data, np.concatenate(qs), np.concatenate(vs), frames


def node_positions(model, data, q, frames):
    """(N + 1, 3) node positions of configuration q."""
    import pinocchio as pin

    pin.framesForwardKinematics(model, data, q)
    return np.array([data.oMf[f].translation for f in frames])


def node_accelerations(model, data, q, v, a, frames):
    """(N + 1, 3) node accelerations (classical, world axes) of (q, v, a)."""
    import pinocchio as pin

    pin.forwardKinematics(model, data, q, v, a)
    pin.updateFramePlacements(model, data)
    return np.array([pin.getFrameClassicalAcceleration(model, data, f, pin.LOCAL_WORLD_ALIGNED).linear
                     for f in frames])


def project_accelerations(p):
    """(N + 1, 3) node accelerations of this project's chain at its start (``rhs3d``)."""
    from snapping.spatial import chain3d as C

    N = p.N
    y = p.initial_state()
    w = C.Work(N)
    f = np.empty_like(y)
    C.rhs3d(N, 0.0, y, f, w.T, w.cp, w.dp, *p.model())
    ed = f[3 * N:6 * N].reshape(3, N).T  # e_j''
    acc = np.zeros((N + 1, 3))
    for j in range(N - 1, -1, -1):  # d_j = r_{j+1} - r_j: a_j = a_{j+1} - h_j e_j''
        acc[j] = acc[j + 1] - p.links.h[j] * ed[j]
    return acc


# ---------------------------------------------------------------- Pinocchio's time stepping
def dexpinv(xi, v):
    """``J_r(xi)^{-1} v`` per joint (xi, v: (n, 3)), the inverse right Jacobian of SO(3)'s
    exponential: ``v + xi x v/2 + c(theta) xi x (xi x v)``, ``c = 1/theta^2 -
    (1 + cos theta)/(2 theta sin theta)`` (1/12 + theta^2/720 for small theta)."""
    th2 = np.einsum("ij,ij->i", xi, xi)
    th = np.sqrt(th2)
    small = th < 1e-3
    ths = np.where(small, 1.0, th)
    c = np.where(small, 1.0 / 12.0 + th2 / 720.0, 1.0 / ths ** 2 - (1.0 + np.cos(ths)) / (2.0 * ths * np.sin(ths)))
    xv = np.cross(xi, v)
    return v + 0.5 * xv + c[:, None] * np.cross(xi, xv)


@dataclass
class Result:
    code: str
    N: int
    setting: str
    count: int  # right-hand-side evaluations (project) or ABA calls (Pinocchio)
    wall: float
    v_peak: float
    t_peak: float
    z_snap: float
    err: float = float("nan")
    aba_only: float = float("nan")  # Pinocchio: its ABA calls' CPU time alone (count x one call's time)


def hermite_max(t0, t1, s0, s1, d0, d1):
    """Largest value on [t0, t1] of the cubic Hermite interpolant (values s, slopes d) and its time."""
    hh = t1 - t0
    # s(x) = s0 + d0 hh x + c2 x^2 + c3 x^3, x in [0, 1]
    c2 = 3.0 * (s1 - s0) - (2.0 * d0 + d1) * hh
    c3 = -2.0 * (s1 - s0) + (d0 + d1) * hh
    cands = [0.0, 1.0]
    A, B, Cc = 3.0 * c3, 2.0 * c2, d0 * hh
    if abs(A) > 1e-300:
        disc = B * B - 4.0 * A * Cc
        if disc >= 0.0:
            r = math.sqrt(disc)
            cands += [(-B + r) / (2.0 * A), (-B - r) / (2.0 * A)]
    elif abs(B) > 1e-300:
        cands.append(-Cc / B)
    best = (-math.inf, t0)
    for x in cands:
        if 0.0 <= x <= 1.0:
            val = s0 + d0 * hh * x + c2 * x * x + c3 * x ** 3
            if val > best[0]:
                best = (val, t0 + x * hh)
    return best


def forward_dynamics(model, data, kind: str = "aba"):
    """``a(q, v)`` of Pinocchio's model: ``"aba"`` (``pin.aba``, O(N)) or ``"crba"`` (the
    joint-space inertia ``pin.crba`` and the bias ``pin.rnea(q, v, 0)``, a dense Cholesky
    solve: O(N^3), accurate where ABA is not on this chain)."""
    import pinocchio as pin
    from scipy.linalg import cho_factor, cho_solve

    zero = np.zeros(model.nv)
    if kind == "aba":
        return lambda q, v: pin.aba(model, data, q, v, zero).copy()

    def crba(q, v):
        M = pin.crba(model, data, q)  # (upper triangle)
        b = pin.rnea(model, data, q, v, zero)
        return cho_solve(cho_factor(M, lower=False, overwrite_a=True, check_finite=False), -b, check_finite=False)

    return crba


def run_pinocchio(p, dt: float, t_max: float = 3.0, stop_fraction: float = 0.5, budget: float = math.inf,
                  dynamics: str = "aba") -> Result:
    """RK4 (Munthe-Kaas, ``pin.integrate``) at the fixed step dt until the tip speed has fallen
    below ``stop_fraction`` of its peak (the project's stop rule); forward dynamics
    ``dynamics`` (:func:`forward_dynamics`)."""
    import pinocchio as pin

    w = time.process_time()
    model, data, q, v, frames = build_pinocchio(p)
    N = p.N
    tau = np.zeros(model.nv)
    tip = frames[0]
    integ = pin.integrate
    fd = forward_dynamics(model, data, dynamics)

    def tip_state(q, v, a):
        pin.forwardKinematics(model, data, q, v, a)
        pin.updateFramePlacement(model, data, tip)
        vt = pin.getFrameVelocity(model, data, tip, pin.LOCAL_WORLD_ALIGNED).linear
        at = pin.getFrameClassicalAcceleration(model, data, tip, pin.LOCAL_WORLD_ALIGNED).linear
        s = float(np.linalg.norm(vt))
        return s, float(vt @ at) / s if s > 0.0 else 0.0

    c = time.process_time()
    for _ in range(50 if dynamics == "aba" else 3):
        fd(q, v)
    t_call = (time.process_time() - c) / (50 if dynamics == "aba" else 3)
    w += time.process_time() - c  # (not part of the run's cost)
    a = fd(q, v)
    n_aba = 1
    s, ds = tip_state(q, v, a)
    hist = [(0.0, s, ds, q.copy(), v.copy())]  # the last three samples
    best = (s, 0, None)  # (speed, step, window of samples around it)
    t, n, peak_hist = 0.0, 0, None
    n_max = int(math.ceil(t_max / dt))
    h2 = 0.5 * dt
    for n in range(1, n_max + 1):
        # stage 1 at (q, v): a known
        k1x, k1v = v, a
        x2 = h2 * k1x
        v2 = v + h2 * k1v
        a2 = fd(integ(model, q, x2), v2)
        k2x = dexpinv(x2.reshape(-1, 3), v2.reshape(-1, 3)).ravel()
        x3 = h2 * k2x
        v3 = v + h2 * a2
        a3 = fd(integ(model, q, x3), v3)
        k3x = dexpinv(x3.reshape(-1, 3), v3.reshape(-1, 3)).ravel()
        x4 = dt * k3x
        v4 = v + dt * a3
        a4 = fd(integ(model, q, x4), v4)
        k4x = dexpinv(x4.reshape(-1, 3), v4.reshape(-1, 3)).ravel()
        q = integ(model, q, (dt / 6.0) * (k1x + 2.0 * k2x + 2.0 * k3x + k4x))
        v = v + (dt / 6.0) * (k1v + 2.0 * a2 + 2.0 * a3 + a4)
        t = n * dt
        a = fd(q, v)
        n_aba += 4
        s, ds = tip_state(q, v, a)
        hist.append((t, s, ds, q.copy(), v.copy()))
        if len(hist) > 3:
            hist.pop(0)
        if not math.isfinite(s) or s > 1e3:
            raise FloatingPointError(f"Pinocchio's RK4 went unstable at t = {t:.4g} (N = {N}, dt = {dt:.3g})")
        if s > best[0]:
            best = (s, n, None)
        elif best[2] is None and n == best[1] + 1:
            best = (best[0], best[1], list(hist))
            peak_hist = best[2]
        if best[0] > 0.5 and s < stop_fraction * best[0]:
            break
        if n % 2000 == 0 and time.process_time() - w > budget:
            raise TimeoutError(f"Pinocchio's RK4 at dt = {dt:.3g} passed the budget of {budget:g} s at t = {t:.3g}")
    w = time.process_time() - w
    if peak_hist is None:
        raise RuntimeError("the tip speed did not peak before t_max")
    (ta, sa, da, qa, va), (tb, sb, db, qb, vb), (tc, sc, dc, qc, vc) = peak_hist
    vp, tp = max(hermite_max(ta, tb, sa, sb, da, db), hermite_max(tb, tc, sb, sc, db, dc))
    zs = [float(np.abs(node_positions(model, data, qq, frames)[:, 2]).max()) for qq in (qa, qb, qc)]
    cz = np.polyfit([ta - tb, 0.0, tc - tb], zs, 2)
    z = float(np.polyval(cz, tp - tb))
    tag = "" if dynamics == "aba" else f" {dynamics}"
    only = n_aba * t_call if dynamics == "aba" else float("nan")  # (CRBA: 3 calls are too few to time)
    return Result("Pinocchio", N, f"RK4{tag} dt={dt:.3g}", n_aba, w, vp, tp, z, aba_only=only)


def run_project(p, tol: float) -> Result:
    from snapping.spatial import run3d

    w = time.process_time()
    r = run3d(p, tol=tol)
    w = time.process_time() - w
    ok = "" if r["status"] == "ok" and r["stop_reason"] == "snap" else f" {r['stop_reason']}"
    return Result("snapping", p.N, f"tol={tol:g}{ok}", int(r["n_rhs"]), w, r["v_peak"], r["t_snap_v"],
                  r["z_amp_snap"])


# ---------------------------------------------------------------- memory
def rss_mib() -> float:
    """The resident set of this process now (MiB, Linux /proc)."""
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2 ** 20


def projected_data_mib(N: int, chi: float = 0.25, n0: int = 100) -> float:
    """Pinocchio's model + data memory at N (MiB), projected as N^3 from a measurement at n0
    (``--memory``: exponent 3.0-3.1 from N = 50 to 200)."""
    p = project_problem(chi, n0)
    r0 = rss_mib()
    model, data, *_ = build_pinocchio(p)
    r1 = rss_mib()
    del model, data
    return max(r1 - r0, 1.0) * (N / n0) ** 3


def available_mib() -> float:
    """Memory available to a new allocation now (MiB, Linux /proc/meminfo)."""
    with open("/proc/meminfo") as fh:
        for line in fh:
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) / 1024
    return math.inf


def memory(Ns, chi=0.25) -> None:
    """Resident memory added by Pinocchio's model + data of N bodies (``model.createData()``),
    and one ABA call's CPU time; the growth exponent between successive N."""
    import pinocchio as pin

    print("Pinocchio's memory (resident set added by model + data, MiB) and one ABA call's CPU time:")
    print(f"  {'N':>6}{'model+data':>12}{'exponent':>10}{'ABA us':>9}")
    prev = None
    for N in Ns:
        p = project_problem(chi, N)
        r0 = rss_mib()
        try:
            model, data, q, v, _ = build_pinocchio(p)
        except MemoryError:
            print(f"  {N:>6}  MemoryError in model.createData() (this machine: "
                  f"{os.sysconf('SC_PHYS_PAGES') * os.sysconf('SC_PAGE_SIZE') / 2 ** 30:.0f} GiB)")
            break
        r1 = rss_mib()
        tau = np.zeros(model.nv)
        c = time.process_time()
        for _ in range(100):
            pin.aba(model, data, q, v, tau)
        c = (time.process_time() - c) / 100
        ex = f"{math.log((r1 - r0) / prev[1]) / math.log(N / prev[0]):10.2f}" if prev else f"{'':>10}"
        print(f"  {N:>6}{r1 - r0:>12.1f}{ex}{c * 1e6:>9.0f}")
        prev = (N, r1 - r0)
        del model, data
    print()


def aba_accuracy(Ns, chi=0.25, step=1e-3) -> None:
    """Pinocchio's ABA against its own CRBA + a dense solve (``M a = -rnea(q, v, 0)``) and
    against this project's tension solve, at the kicked catenary moved by ``step`` along its
    velocity (out of the plane: at the planar start itself ABA is accurate at every N)."""
    import pinocchio as pin
    from snapping.spatial import Problem3D

    print(f"Pinocchio's ABA at the start moved by {step:g} along its velocity (max |node acceleration| error):")
    print(f"  {'N':>6}{'ABA - tension solve':>22}{'CRBA - tension solve':>22}{'|a| max':>10}")
    for N in Ns:
        p = project_problem(chi, N)
        model, data, q, v, frames = build_pinocchio(p)
        tau = np.zeros(model.nv)
        q = pin.integrate(model, q, step * v)
        a_aba = pin.aba(model, data, q, v, tau).copy()
        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        a_crba = np.linalg.solve(M, -pin.rnea(model, data, q, v, tau))
        r = node_positions(model, data, q, frames)
        pin.forwardKinematics(model, data, q, v)
        pin.updateFramePlacements(model, data)
        vel = np.array([pin.getFrameVelocity(model, data, f, pin.LOCAL_WORLD_ALIGNED).linear for f in frames])
        ref = project_accelerations(Problem3D(p.links, r - r[-1], vel - vel[-1]))
        e1 = np.abs(node_accelerations(model, data, q, v, a_aba, frames) - ref).max()
        e2 = np.abs(node_accelerations(model, data, q, v, a_crba, frames) - ref).max()
        print(f"  {N:>6}{e1:>22.2e}{e2:>22.2e}{np.abs(ref).max():>10.3g}")
        del model, data
    print()


# ---------------------------------------------------------------- reporting
def machine():
    try:
        from bench_simulate import print_machine

        print_machine()
    except ImportError:  # pragma: no cover - the benchmarks folder moved
        print(f"machine: {os.uname().nodename}, load {os.getloadavg()[0]:.2f}\n")
    try:
        from importlib.metadata import version

        print(f"  pin            {version('pin')}\n")
    except Exception:
        print("  pin            not installed\n")


def table(rows):
    print(f"  {'code':<11}{'N':>5}  {'setting':<18}{'evals/ABA':>11}{'cpu s':>9}{'v_tip peak':>15}{'t_peak':>10}"
          f"{'z_amp snap':>12}{'rel err':>10}{'ABA-only s':>11}")
    for r in rows:
        print(f"  {r.code:<11}{r.N:>5}  {r.setting:<18}{r.count:>11d}{r.wall:>9.3f}{r.v_peak:>15.10f}"
              f"{r.t_peak:>10.6f}{r.z_snap:>12.6g}{r.err:>10.1e}"
              + (f"{r.aba_only:>11.3f}" if r.code == "Pinocchio" else ""))


def matched(rows, level):
    out = {}
    for code in ("snapping", "Pinocchio"):
        ok = [r for r in rows if r.code == code and r.err <= level]
        out[code] = min(ok, key=lambda r: r.wall) if ok else None
    return out


def compare(chi, N, eps, tols, dts, budget, ref_tol=REF_TOL, dynamics="aba"):
    p = project_problem(chi, N, eps)
    ref = run_project(p, ref_tol)
    rows = [run_project(p, tol) for tol in tols]
    spent = 0.0
    need, have = projected_data_mib(N, chi), available_mib()
    if need > 0.7 * have:
        print(f"  (Pinocchio at N = {N} not run: model.createData() would take about {need / 1024:.0f} GiB (N^3 "
              f"from N = 100), {have / 1024:.0f} GiB available)")
        dts = []
    for dt in dts:
        if spent > budget:
            print(f"  (Pinocchio dt = {dt:.3g} skipped: the budget of {budget:g} s is spent)")
            continue
        try:
            r = run_pinocchio(p, dt, budget=budget - spent, dynamics=dynamics)
        except MemoryError:
            print(f"  (Pinocchio at N = {N}: MemoryError in model.createData(); see --memory)")
            break
        except FloatingPointError as e:  # a smaller step may be stable
            print(f"  ({e})")
            continue
        except TimeoutError as e:
            print(f"  ({e})")
            spent = budget + 1.0
            continue
        spent += r.wall
        rows.append(r)
    for r in rows:
        r.err = abs(r.v_peak / ref.v_peak - 1.0)
    print(f"chi = {chi:g}, N = {N}, eps = {eps:g} (sin); reference: this project at tol = {ref_tol:g}: v_tip peak "
          f"{ref.v_peak:.12f} at t = {ref.t_peak:.8f}, z_amp at the snap {ref.z_snap:.8g} ({ref.count} evaluations, "
          f"{ref.wall:.2f} s)")
    table(rows)
    for level in LEVELS:
        m = matched(rows, level)
        a, b = m["snapping"], m["Pinocchio"]
        if a and b:
            print(f"  at {level:g}: snapping {a.wall:.4f} s ({a.setting}), Pinocchio {b.wall:.2f} s ({b.setting}): "
                  f"speed-up {b.wall / a.wall:,.0f}x" + ("" if math.isnan(b.aba_only) else
                  f"; against Pinocchio's ABA calls alone ({b.aba_only:.3f} s, a lower bound for a compiled "
                  f"RK4 loop): {b.aba_only / a.wall:,.0f}x"))
        else:
            who = " and ".join(c for c, r in m.items() if r is None)
            print(f"  at {level:g}: not reached by {who} within the runs above")
    print()
    return rows


def _floats(s):
    return [float(x) for x in s.split(",") if x]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--chi", type=float, default=0.25, help="end separation / length (default 0.25)")
    ap.add_argument("--eps", type=float, default=EPS, help=f"out-of-plane velocity kick (default {EPS:g})")
    ap.add_argument("--N", default="200,500", help="links, comma-separated (default 200,500)")
    ap.add_argument("--dt", default=",".join(f"{d:g}" for d in PIN_DTS), help="Pinocchio's RK4 steps")
    ap.add_argument("--tols", default=",".join(f"{t:g}" for t in PROJECT_TOLS), help="this project's tolerances")
    ap.add_argument("--budget", type=float, default=900.0, help="CPU seconds for Pinocchio per N (default 900)")
    ap.add_argument("--ref-tol", type=float, default=REF_TOL, help=f"the reference's tolerance (default {REF_TOL:g})")
    ap.add_argument("--memory", default="", help="only Pinocchio's memory and ABA time at these N (e.g. 200,1000)")
    ap.add_argument("--aba-check", default="", help="only ABA's accuracy against the tension solve at these N "
                                                     "(e.g. 40,60,80,100,160)")
    ap.add_argument("--dynamics", choices=("aba", "crba"), default="aba",
                    help="Pinocchio's forward dynamics: aba (O(N); default) or crba (+ dense Cholesky, O(N^3))")
    ap.add_argument("--quick", action="store_true", help="N = 20, two steps, two tolerances: seconds")
    a = ap.parse_args(argv)
    sys.stdout.reconfigure(line_buffering=True)
    try:
        import pinocchio  # noqa: F401
    except ImportError:
        print("pin (Pinocchio) is not installed: pip install 'snapping[peers]' (or pip install pin)")
        return 1
    machine()
    print(f"uptime: {os.popen('uptime').read().strip()}\n")
    if a.memory:
        memory([int(x) for x in a.memory.split(",")], a.chi)
        return 0
    if a.aba_check:
        aba_accuracy([int(x) for x in a.aba_check.split(",")], a.chi)
        return 0
    Ns, dts, tols = [int(x) for x in a.N.split(",") if x], _floats(a.dt), _floats(a.tols)
    if a.quick:
        Ns, dts, tols, a.ref_tol = [20], [4e-4, 2e-4], [1e-5, 1e-8], 1e-11
    run_project(project_problem(a.chi, 5, a.eps), 1e-4)  # compile before timing
    for N in Ns:
        compare(a.chi, N, a.eps, tols, dts, a.budget, a.ref_tol, a.dynamics)
    print(f"uptime: {os.popen('uptime').read().strip()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
