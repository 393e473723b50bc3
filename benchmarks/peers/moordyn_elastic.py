"""The elastic falling catenary (issue 22), solved by MoorDyn and by this project, side by side.

The problem (``elastic_common.py``; nondimensional L = lambda = g = 1): the level catenary
chi = 0.25 of N links of rest length 1/N, node masses 1/N (half at the free end), axial
stiffness EA = c^2, tension-only, no damping; released from rest from this project's start
(``--start``: ``stretched``, the static equilibrium; ``matched``, each link at the rigid chain's
tension just after release), the held end fixed.

MoorDyn (PyPI ``moordyn``, MoorDyn-C v2): one line of N segments, unstretched length 1,
mass 1 per length, EA = c^2, between a Fixed point (the held end, the origin) and a Free
point of no mass of its own (the free end); no internal damping (BA = 0), no drag and no
added mass (Cd = Ca = 0), water density 0 (no buoyancy), deep water (no seabed), gravity
``g = 1`` (MoorDyn's option), z = -y. MoorDyn's line is the same discrete model as this
project's: lumped node masses (half a segment's at each end: the free point's mass is its
node's, 1/(2N)), segments that carry EA (l/h - 1) when stretched and nothing when slack.

The start: MoorDyn's own initial condition (its catenary) is replaced by this project's
start (``elastic_common.start_state``: nodes and velocities): ``Init_NoIC``, then its state (saved with ``SaveState``: the free
point's and the line's inner nodes' positions and velocities) is rewritten with the start's
nodes and loaded back with ``LoadState``; the script checks the positions MoorDyn then
reports against the start (round-off).

Time stepping: MoorDyn's fixed-step explicit schemes (``--scheme``: ``rk2``, its default,
or ``rk4``, ...), one ``Step`` call per step (the step ``dtM`` in the input file is the same),
sampling the free point's speed and the line's largest tension (``GetLineMaxTen``) after
every step; peaks: the vertex of the parabola through the three samples around the largest,
up to the reference's end (this project's stop at the snap). The per-step
sampling costs Python calls (27% of the sampled run at N = 100, RK4): :func:`stepping_cpu`
times MoorDyn's stepping alone, what ``elastic_table.py`` compares.

Usage::

    python benchmarks/peers/moordyn_elastic.py --quick                 # N = 20, c = 30: seconds
    python benchmarks/peers/moordyn_elastic.py --N 100 --c 30          # one point
    python benchmarks/peers/moordyn_elastic.py --N 400 --c 300 --dt 1e-6 --method dop853
    python benchmarks/peers/moordyn_elastic.py --help

Needs the optional ``peers`` extra (``pip install moordyn``) for the MoorDyn side.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import elastic_common as E  # noqa: E402

INPUT = """--------------------- MoorDyn Input File ------------------------------------
Elastic falling catenary (snapping benchmarks/peers/moordyn_elastic.py)
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA     BA/-zeta    EI    Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)    (N-s/-)     (N-m^2) (-)   (-)    (-)     (-)
elastic    1e-3    1.0    {ea!r}   0    0     0      0      0       0
---------------------- POINTS --------------------------------
ID    Attachment  X       Y     Z      M      V      CdA   CA
(#)   (-)         (m)     (m)   (m)    (kg)   (m^3)  (m^2) (-)
1     Fixed       0       0     0      0      0      0     0
2     Free        {x0!r}    0     {z0!r}      0      0      0     0
---------------------- LINES --------------------------------------
ID   LineType  AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)  (name)    (#)      (#)      (m)       (-)      (-)
1    elastic   1        2        1.0       {N}       -
---------------------- OPTIONS -----------------------------------------
{dt!r}     dtM
{scheme}   tScheme
1.0      g
1000     WtrDpth
0.0      WtrDnsty
0        dtIC
---------------------- OUTPUTS -----------------------------------------
END
------------------------- need this line --------------------------------------
"""

#: the first step as a fraction of h/c (omega_max = 2 c/h, the segments' fastest mode: RK2 goes unstable at 0.5 h/c)
AXIAL_SAFETY = 0.25


@contextlib.contextmanager
def quiet_stdout():
    """MoorDyn-C prints its banner and progress (``t = ...``) on the C stdout: send it to /dev/null."""
    sys.stdout.flush()
    fd = os.dup(1)
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    try:
        yield
    finally:
        os.dup2(fd, 1)
        os.close(fd)
        os.close(null)


def _blocks(buf: bytes, offset: int):
    """The (start, rows, cols) of each instance in a MoorDyn state file (MoorDyn-C 2.x:
    'MoorDyn' + 2 version bytes, u64 size, u64 instances, then per instance u64 rows, u64
    cols and rows x cols doubles: a point (1 x 6: position, velocity), a line (inner nodes x 6))."""
    a = np.frombuffer(buf, dtype="<u8", offset=offset)
    out, k = [], 0
    while k < a.size:
        r, c = int(a[k]), int(a[k + 1])
        out.append((k + 2, r, c))
        k += 2 + r * c
    return out


def build_moordyn(chi: float, N: int, c: float, dt: float, scheme: str, workdir: str, start: str = "stretched"):
    """(system, point, line) of MoorDyn at this project's ``start`` (see the module docstring)."""
    import moordyn

    x, y, vx, vy = E.start_state(chi, N, c, start)
    path = os.path.join(workdir, "line.txt")
    with open(path, "w") as fh:
        fh.write(INPUT.format(ea=c * c, x0=float(x[0]), z0=float(-y[0]), N=N, dt=dt, scheme=scheme))
    with quiet_stdout():
        s = moordyn.Create(path)
        moordyn.SetVerbosity(s, moordyn.LEVEL_ERR)
        if moordyn.Init_NoIC(s, [], []) != 0:
            raise RuntimeError("MoorDyn's Init_NoIC failed")
        st = os.path.join(workdir, "state.bin")
        moordyn.SaveState(s, st)
    with open(st, "rb") as fh:
        buf = bytearray(fh.read())
    off = 9 + 16  # 'MoorDyn' + 2 version bytes, u64 size, u64 instances
    f = np.frombuffer(buf, dtype="<f8", offset=off).copy()
    blocks = _blocks(bytes(buf), off)
    if len(blocks) != 3 or blocks[1][1:] != (1, 6) or blocks[2][1:] != (N - 1, 6):
        raise RuntimeError(f"unexpected MoorDyn state layout {blocks}")
    k1 = blocks[1][0]
    f[k1:k1 + 6] = [x[0], 0.0, -y[0], vx[0], 0.0, -vy[0]]  # the free point
    k2 = blocks[2][0]
    for i in range(1, N):  # line node i (from the fixed end A) is this project's node N - i
        j = N - i
        f[k2 + 6 * (i - 1):k2 + 6 * i] = [x[j], 0.0, -y[j], vx[j], 0.0, -vy[j]]
    buf[off:] = f.tobytes()
    with open(st, "wb") as fh:
        fh.write(bytes(buf))
    with quiet_stdout():
        moordyn.LoadState(s, st)
    return s, moordyn.GetPoint(s, 2), moordyn.GetLine(s, 1)


def start_check(chi: float, N: int, c: float, scheme: str = "rk2", dt: float = 1e-9, start: str = "stretched"):
    """Largest |MoorDyn's node position - the start| after one step of ``dt`` (the positions it
    reports are those of its last step), and MoorDyn's node masses (lumped)."""
    import moordyn

    x, y, _, _ = E.start_state(chi, N, c, start)
    with tempfile.TemporaryDirectory() as d:
        s, pt, ln = build_moordyn(chi, N, c, dt, scheme, d, start)
        with quiet_stdout():
            moordyn.Step(s, [], [], 0.0, dt)
            P = np.array([moordyn.GetLineNodePos(ln, i) for i in range(N + 1)])[::-1]
            M = np.array([moordyn.GetLineNodeM(ln, i)[0][0] for i in range(N + 1)])[::-1]
            moordyn.Close(s)
    return float(max(np.abs(P[:, 0] - x).max(), np.abs(-P[:, 2] - y).max(), np.abs(P[:, 1]).max())), M


def run_moordyn(chi: float, N: int, c: float, dt: float, scheme: str = "rk2", t_end: float | None = None,
                stop_fraction: float = 0.5, start: str = "stretched") -> E.Result:
    """MoorDyn at the fixed step ``dt`` to ``t_end`` (the reference's end), or without it until
    the free end's speed has fallen below ``stop_fraction`` of its running peak (after t = 0.8)."""
    import moordyn

    n_max = int(math.ceil((3.0 if t_end is None else t_end) / dt - 1e-9))
    v = np.empty(n_max)
    T = np.empty(n_max)
    E.start_state(chi, N, c, start)  # the given data (cached): not timed
    with tempfile.TemporaryDirectory() as d, quiet_stdout():
        w = time.process_time()
        s, pt, ln = build_moordyn(chi, N, c, dt, scheme, d, start)
        step, vel, maxten = moordyn.Step, moordyn.GetPointVel, moordyn.GetLineMaxTen
        peak, t, n, bad = 0.0, 0.0, 0, False
        for n in range(1, n_max + 1):
            step(s, [], [], t, dt)
            t = n * dt
            u = vel(pt)
            sp = math.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
            v[n - 1] = sp
            T[n - 1] = maxten(ln)
            if not math.isfinite(sp) or sp > 1e3:
                bad = True
                break
            peak = max(peak, sp)
            if t_end is None and t > 0.8 and sp < stop_fraction * peak:
                break
        w = time.process_time() - w
        moordyn.Close(s)
    if bad:
        raise FloatingPointError(f"MoorDyn went unstable at t = {t:.4g} (N={N}, c={c:g}, dt={dt:.3g}, {scheme})")
    tt = dt * np.arange(1, n + 1)
    vp, tp = E.vertex(tt, v[:n])
    sp_, ts = E.vertex(tt, T[:n])
    return E.Result("MoorDyn", N, c, f"{scheme} dt={dt:.3g}", n, w, vp, tp, sp_, ts, start=start)


def advance(s, dt: float, n_steps: int, chunk: int) -> None:
    """``n_steps`` steps of ``dt`` of the MoorDyn system ``s`` from t = 0, ``chunk`` steps a
    ``Step`` call (MoorDyn divides a call's interval into its steps of ``dtM = dt``)."""
    import moordyn

    n, t = 0, 0.0
    while n < n_steps:
        m = min(chunk, n_steps - n)
        moordyn.Step(s, [], [], t, m * dt)
        n += m
        t = n * dt


def stepping_cpu(chi: float, N: int, c: float, dt: float, scheme: str, n_steps: int, start: str = "stretched",
                 repeats: int = 1) -> list:
    """CPU seconds of MoorDyn's own work for ``n_steps`` steps of ``dt`` (``repeats`` runs): the
    same build as :func:`run_moordyn` (input file, ``Init_NoIC``, the start loaded), then
    ``Step`` called for ``CHUNK`` steps at a time (MoorDyn divides a call's interval into its
    ``dtM`` steps: the same states as one call a step, to round-off), with nothing sampled
    between the calls. :func:`run_moordyn`'s time also holds the Python calls that sample the
    peaks after every step (27% of it at N = 100, RK4 at h/c): this is MoorDyn's cost without them."""
    import moordyn

    E.start_state(chi, N, c, start)  # the given data (cached): not timed
    out = []
    for _ in range(repeats):
        with tempfile.TemporaryDirectory() as d, quiet_stdout():
            w = time.process_time()
            s, pt, ln = build_moordyn(chi, N, c, dt, scheme, d, start)
            advance(s, dt, n_steps, CHUNK)
            out.append(time.process_time() - w)
            moordyn.Close(s)
    return out


def chunk_check(chi: float, N: int, c: float, dt: float, scheme: str, n_steps: int, start: str = "stretched") -> float:
    """Largest difference of the free point's position and velocity after ``n_steps`` steps taken
    one ``Step`` call a step and ``CHUNK`` steps a call (:func:`stepping_cpu`): round-off when
    MoorDyn divides a call's interval into the same steps."""
    import moordyn

    out = []
    for k in (1, CHUNK):
        with tempfile.TemporaryDirectory() as d, quiet_stdout():
            s, pt, ln = build_moordyn(chi, N, c, dt, scheme, d, start)
            advance(s, dt, n_steps, k)
            out.append(np.array(list(moordyn.GetPointPos(pt)) + list(moordyn.GetPointVel(pt))))
            moordyn.Close(s)
    return float(np.abs(out[0] - out[1]).max())


#: steps a ``Step`` call of :func:`stepping_cpu` (MoorDyn subdivides the call's interval into them)
CHUNK = 1000


def axial_dt(N: int, c: float, scheme: str = "rk2") -> float:
    """The first step of the ladder: AXIAL_SAFETY h/c for RK2, RK4_FIRST h/c for RK4 (its stability
    limit on the line's fastest mode, omega = 2 c/h, is 2.83/omega = 1.41 h/c)."""
    return (RK4_FIRST if scheme.lower() == "rk4" else AXIAL_SAFETY) / (N * c)


#: RK4's first step in units of h/c (0.5 before branch peers3: RK4 was already within 1e-6 of the
#: matched start's peak there, so its ladder started finer than the accuracy needed)
RK4_FIRST = 1.0


def compare(chi, N, c, dts, scheme, method, budget, tols=E.PROJECT_TOLS, project_budget=300.0, with_ref=True,
            start="stretched"):
    ref = E.reference(chi, N, c, start=start) if with_ref else None
    if ref:
        E.header(ref, chi)
    else:
        print(f"chi = {chi:g}, N = {N}, c/sqrt(gL) = {c:g}: no reference (--no-reference); MoorDyn runs to its snap")
    err0, M = start_check(chi, N, c, scheme, start=start)
    print(f"  MoorDyn's start: largest node position - this project's start {err0:.1e}; node masses "
          f"{M[0]:.6g} (free end), {M[1]:.6g}, ..., total {M[:N].sum():.12g}")
    rows = E.project_rows(chi, N, c, ref, method=method, tols=tols, budget=project_budget, start=start) if ref else []
    spent = 0.0
    for dt in dts:
        if spent > budget:
            print(f"  (MoorDyn dt={dt:.3g} skipped: the budget of {budget:g} s is spent)")
            continue
        try:
            r = run_moordyn(chi, N, c, dt, scheme, ref.t_end if ref else None, start=start)
        except FloatingPointError as e:
            print(f"  ({e})")
            continue
        spent += r.cpu
        rows.append(E.score(r, ref) if ref else r)
        if E.error(r) <= min(E.LEVELS):
            break
    E.table(rows)
    E.matched(rows, "MoorDyn", ref=ref)
    print(flush=True)
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    E.add_arguments(ap, "MoorDyn")
    ap.add_argument("--dt", default="",
                    help="MoorDyn's steps, comma-separated (default: 0.25 h/c, then halved --halvings times)")
    ap.add_argument("--halvings", type=int, default=3, help="default steps: 0.25 h/c halved this many times")
    ap.add_argument("--scheme", default="rk2", help="MoorDyn's time scheme (its tScheme option; default rk2)")
    ap.add_argument("--quick", action="store_true", help="N = 20, c = 30, two steps (h/(8 c), h/(16 c)): seconds")
    a = ap.parse_args(argv)
    sys.stdout.reconfigure(line_buffering=True)
    Ns, cs, tols = E.apply_arguments(a)
    quick_dts = []
    if a.quick:
        Ns, cs, tols, a.method = [20], [30.0], [1e-4, 1e-6], "dop853"
        quick_dts = [axial_dt(20, 30.0) / 2, axial_dt(20, 30.0) / 4]
    from snapping.simulate.elastic import METHODS

    for m in a.method.lower().split(",") + [E.REF_METHOD]:
        if m not in METHODS:
            print(f"--method {m!r} is not one of {tuple(METHODS)}", file=sys.stderr)
            return 2
    try:
        import moordyn  # noqa: F401
    except ImportError:
        print("moordyn is not installed: pip install 'snapping[peers]' (or pip install moordyn)")
        return 1
    E.machine("moordyn")
    for N in Ns:
        for c in cs:
            dts = quick_dts or [float(x) for x in a.dt.split(",") if x] or \
                [axial_dt(N, c, a.scheme) / 2 ** k for k in range(a.halvings + 1)]
            compare(a.chi, N, c, dts, a.scheme, a.method.lower(), a.budget, tols, with_ref=not a.no_reference,
                    start=a.start)
    print(f"uptime: {os.popen('uptime').read().strip()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
