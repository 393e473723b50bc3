"""Probe: what sets the elastic line's RODAS4 steps as the wave speed c grows (issue 22).

chi, N, c, start, tol as given (default: chi = 0.25, matched start, no damping), to the snap.
The run is first made by ``elastic.solve(..., method="rodas4")`` (its evaluations, steps and
CPU time, and the inextensible fast run's, tol 1e-10); then the same steps are retaken one at
a time with :class:`~snapping.simulate.elastic_rodas.RodasStepper` (the compiled loop takes
the same steps) and each accepted step's error estimate ``U_6`` is taken apart:

- the component that sets the scaled max norm: its node, position or velocity, and, at that
  node, whether the error lies along the link (longitudinal: the stiff, stretching motion) or
  across it (the bending, slow motion);
- the largest scaled error of each class (positions along / across, velocities along /
  across) and the links' stretch error ``u_j . (dr_{j+1} - dr_j)`` against their stretch
  ``l_j - h_j``.

Printed per tenth of the run (steps, rejected steps, median step, the fast run's steps in the
same interval, the dominant class, where along the line it is), then, with ``--hscan``, the
error norm of single steps of sizes h * 2^k from the state at the middle of the run and near
the snap, per class: its slope in h (4 for a non-stiff local error of the embedded order-3
formula; less is order reduction). Per step also ``rho``, the largest over the links of
``(theta'_j h)^2 / (2 e_j)``: a step linear in the state moves a link's end across it by
``theta'_j h l_j`` (theta'_j its turning rate), which lengthens it at second order by
``(theta'_j h)^2 l_j / 2``, against its stretch ``e_j l_j``. With ``--fixed H ...`` the run is
instead made with fixed steps (no error control) to ``--t-fixed``, printing the largest stretch
rate at five times (the line's own, from a converged run, is about 1e-9 at c = 3000). With
``--pendulum WH ...`` a stiff pendulum (one mass on a two-sided spring, released horizontal) is
stepped by the same RODAS4 with fixed steps omega h, in Cartesian coordinates and in polar ones.
With ``--ringing TOL ...`` runs at those tolerances are compared at ten times (the largest
stretch rate of each; speed, position and tension differences from the tightest).

Usage::

    PYTHONPATH=src python benchmarks/probe_elastic_steps.py --N 200 --c 30 300 3000 --tol 3e-6
    PYTHONPATH=src python benchmarks/probe_elastic_steps.py --N 1000 --c 300 --tol 3e-6 --hscan
    PYTHONPATH=src python benchmarks/probe_elastic_steps.py --N 200 --c 3000 --fixed 2e-5 5e-5 1e-4 2e-4
    PYTHONPATH=src python benchmarks/probe_elastic_steps.py --c 1000 --pendulum 1 3 10 30 100 1000
    PYTHONPATH=src python benchmarks/probe_elastic_steps.py --N 200 --c 3000 --ringing 1e-8 3e-6

CPU times are process times (a shared machine); evaluations are the primary measure.
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

from snapping.simulate import run
from snapping.simulate import elastic_rodas as ER
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.elastic_model import ElasticLine
from snapping.simulate.problem import Links, Problem

CLASSES = ("pos_long", "pos_trans", "vel_long", "vel_trans", "WD")


def decompose(line, y0, y1, U, tol, hstep):
    """Scaled error per class and per link for one step's estimate ``U`` (``y0 -> y1``)."""
    N = line.N
    sc = tol * (1.0 + np.maximum(np.abs(y0), np.abs(y1)))
    s = np.abs(U) / sc
    x, yy = y1[0:4 * N:4], y1[1:4 * N:4]
    pin = line.pin_state(0.0)
    xn, yn = np.append(x, pin[0]), np.append(yy, pin[1])
    dx, dy = np.diff(xn), np.diff(yn)
    ln = np.hypot(dx, dy)
    ux, uy = dx / ln, dy / ln  # link j's direction, from node j to j + 1 (node i's "tangent": link i)
    ex, ey, evx, evy = (U[k:4 * N:4] for k in range(4))
    sp = sc[0:4 * N:4]  # (x and y scales are alike; the along/across split uses the x one)
    sv = sc[2:4 * N:4]
    pl = np.abs(ex * ux + ey * uy) / sp
    pt = np.abs(-ex * uy + ey * ux) / sp
    vl = np.abs(evx * ux + evy * uy) / sv
    vt = np.abs(-evx * uy + evy * ux) / sv
    # stretch error of each link, and the link's stretch
    dex, dey = np.append(ex, 0.0), np.append(ey, 0.0)
    dl = np.abs(ux * np.diff(dex) + uy * np.diff(dey))
    stretch = ln - line.h
    # the rotation in the step against the stretch: a step linear in the state moves a link's
    # end across it by (theta' h) l, which lengthens it by (theta' h)^2 l/2 at second order
    vxn = np.append(y0[2:4 * N:4], pin[2])
    vyn = np.append(y0[3:4 * N:4], pin[3])
    x0n, y0n = np.append(y0[0:4 * N:4], pin[0]), np.append(y0[1:4 * N:4], pin[1])
    d0x, d0y = np.diff(x0n), np.diff(y0n)
    l0 = np.hypot(d0x, d0y)
    om = (d0x * np.diff(vyn) - d0y * np.diff(vxn)) / l0**2
    e0 = l0 / line.h - 1.0
    rho = (om * hstep) ** 2 / (2.0 * np.maximum(e0, 1e-300))
    k = int(np.argmax(s))
    cls = 4 if k >= 4 * N else (0 if k % 4 < 2 else 2)
    if cls != 4:
        i = k // 4
        cls = cls + (0 if (pl[i] if cls == 0 else vl[i]) >= (pt[i] if cls == 0 else vt[i]) else 1)
    return {"err": float(s.max()), "cls": cls, "node": (k // 4 if k < 4 * N else -1),
            "max": (pl.max(), pt.max(), vl.max(), vt.max(), s[4 * N:].max()),
            "dl_rel": float(np.max(dl / np.maximum(np.abs(stretch), 1e-300))),
            "dl_h": float(np.max(dl / line.h)), "jdl": int(np.argmax(dl)),
            "rho": float(rho.max()), "jrho": int(np.argmax(rho))}


def probe(p, c, tol, start, zeta, hscan, fast_t):
    el = Elastic.from_wave_speed(c, grid_damping=zeta)
    t0 = time.process_time()
    r = solve(p, el, tol=tol, method="rodas4", start=start)
    cpu = time.process_time() - t0
    a = r.dataset.attrs
    line = ElasticLine(p, el)
    z0 = line.start(start)
    t_final = float(a["t_final"])
    st = ER.RodasStepper(line, 0.0, z0, t_final, tol)
    rows, states = [], []
    while st.status == "running":
        nrej0 = st.nrej
        t_old = st.t
        st.step()
        d = decompose(line, st.y0d, st.y, st.St[6], tol, st.t - t_old)
        d.update(t=st.t, h=st.t - t_old, rej=st.nrej - nrej0)
        rows.append(d)
        states.append((t_old, st.y0d.copy(), st.t - t_old))
        if st.status == "failed":
            break
    print(f"  c = {c:g}: solve n_rhs {a['n_rhs']} steps {a['n_steps']} cpu {cpu:.2f} s t_final {t_final:.6f} "
          f"(retaken: {len(rows)} steps, {st.nrej} rejected, n_rhs {st.nfev}) v {a['v_peak']:.8g} a {a['a_peak']:.8g} "
          f"sigma {a['sigma_peak']:.8g} slack steps {a['n_slack_steps']}")
    t = np.array([d["t"] for d in rows])
    h = np.array([d["h"] for d in rows])
    rej = np.array([d["rej"] for d in rows])
    cls = np.array([d["cls"] for d in rows])
    node = np.array([d["node"] for d in rows])
    mx = np.array([d["max"] for d in rows])
    dlr = np.array([d["dl_rel"] for d in rows])
    dlh = np.array([d["dl_h"] for d in rows])
    rho = np.array([d["rho"] for d in rows])
    jrho = np.array([d["jrho"] for d in rows])
    N = line.N
    print(f"  {'t/tf':>9} {'steps':>6} {'fast':>5} {'rej':>5} {'med h':>9} {'dominant class (share)':>24} "
          f"{'node/N (med)':>12} {'pos_l':>8} {'pos_t':>8} {'vel_l':>8} {'vel_t':>8} {'dl/stretch':>10} {'dl/h':>8} {'rho':>8} {'j/N':>6}")
    edges = np.linspace(0.0, 1.0, 11)
    for lo, hi in zip(edges[:-1], edges[1:]):
        m = (t > lo * t_final) & (t <= hi * t_final)
        nf = int(np.sum((fast_t > lo * t_final) & (fast_t <= hi * t_final)))
        if not m.any():
            continue
        cc = np.bincount(cls[m], minlength=5)
        dom = int(np.argmax(cc))
        med = np.median(mx[m], axis=0)
        print(f"  {lo:.1f}-{hi:.1f} {m.sum():>6} {nf:>5} {rej[m].sum():>5} {np.median(h[m]):>9.2e} "
              f"{CLASSES[dom]:>14} ({cc[dom] / m.sum():.2f}) {np.median(node[m]) / N:>12.3f} "
              f"{med[0]:>8.2e} {med[1]:>8.2e} {med[2]:>8.2e} {med[3]:>8.2e} {np.median(dlr[m]):>10.2e} "
              f"{np.median(dlh[m]):>8.1e} {np.median(rho[m]):>8.2e} {np.median(jrho[m]) / N:>6.3f}")
    cc = np.bincount(cls, minlength=5)
    print("  all steps: " + ", ".join(f"{CLASSES[k]} {cc[k] / len(cls):.2f}" for k in range(5)))
    if hscan:
        for frac in (0.5, 0.97):
            i = int(np.searchsorted(t, frac * t_final))
            i = min(i, len(states) - 1)
            t0s, y0s, h0 = states[i]
            print(f"  h-scan from t = {t0s:.5f} (accepted h {h0:.3e}); scaled error per class "
                  f"[pos_l pos_t vel_l vel_t] and the slopes between rows:")
            prev = None
            for k in range(-4, 4):
                hh = h0 * 2.0 ** k
                s2 = ER.RodasStepper(line, t0s, y0s, t0s + hh, tol, h0=hh)
                s2.ctl[ER.C_H] = hh
                # one attempt, not the accept loop: rodas_step directly
                z1 = np.zeros_like(y0s)
                ctl = s2.ctl.copy()
                pins = np.zeros((7, 4))
                for q in range(6):
                    ER.pin_at(t0s, s2.pinpar, s2.pintab, pins[q])
                ER.rodas_step(N, t0s, hh, y0s, s2.ft, True, pins, *s2.args(), s2.B, s2.gW, s2.gD,
                              int(s2.dsp[0]), int(s2.dsp[1]), s2.F, s2.ab, s2.piv, False, s2.St, s2.ytmp, s2.btmp,
                              s2.w, z1, s2.c23, tol, *s2.work, ctl)
                d = decompose(line, y0s, z1, s2.St[6], tol, hh)
                v = np.array(d["max"][:4])
                sl = "" if prev is None else "  slopes " + " ".join(f"{x:5.2f}" for x in np.log2(v / prev))
                print(f"    h {hh:.3e} (x{2.0 ** k:g}): " + " ".join(f"{x:9.2e}" for x in v) + sl)
                prev = v


def fixed_steps(p, c, zeta, start, hs, t1):
    """RODAS4 with fixed steps (no error control) from the start to ``t1``: the largest stretch
    rate |u_j . (v_{j+1} - v_j)| at five times, the reference's being ~1e-9 (the quasi-static
    stretching): where it grows the steps, not the line, ring."""
    line = ElasticLine(p, Elastic.from_wave_speed(c, grid_damping=zeta))
    z0 = line.start(start)
    w1 = np.pi * line.wave_speed / (2.0 * float(np.sum(line.h)))
    for h in hs:
        t0 = time.process_time()
        st = ER.RodasStepper(line, 0.0, z0, t1, 1e3, h0=h)
        marks, k, out = np.linspace(0.0, t1, 6)[1:], 0, []
        while st.status == "running" and k < len(marks):
            st.ctl[ER.C_H] = h
            st.ctl[ER.C_HACC] = -1.0
            st.step()
            if st.t >= marks[k] - 1e-12:
                _, _, ed = line.link_state(st.t, st.y)
                out.append(f"{np.nanmax(np.abs(ed * line.h)):.1e}")
                k += 1
        print(f"  fixed h {h:.1e} (omega_1 h {w1 * h:.2f}), c = {c:g}: largest stretch rate at t = "
              f"{', '.join(f'{x:.2f}' for x in marks[:len(out)])}: {' '.join(out)} (cpu {time.process_time() - t0:.1f} s)",
              flush=True)


def ringing(p, c, zeta, start, tols):
    """Runs at several tolerances with snapshots at ten times: the largest stretch rate
    |u_j . (v_{j+1} - v_j)| of each (the line's own, quasi-static, from the tightest), and the
    others' differences from the tightest in node speed, position and tension (relative to the
    largest tension)."""
    ts = np.array([0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9, 1.0, 1.1, 1.15])
    out = {}
    for tol in sorted(tols):
        t0 = time.process_time()
        r = solve(p, Elastic.from_wave_speed(c, grid_damping=zeta), tol=tol, method="rodas4", start=start,
                  snapshot_times=ts)
        ds, a = r.dataset, r.dataset.attrs
        k = ds.snapshot_kind.values == "requested"
        x, y, vx, vy, T = (ds[n].values[k] for n in ("x", "y", "vx", "vy", "tension"))
        dx, dy = np.diff(x, axis=1), np.diff(y, axis=1)
        ln = np.hypot(dx, dy)
        sd = (dx * np.diff(vx, axis=1) + dy * np.diff(vy, axis=1)) / ln
        out[tol] = (x, y, vx, vy, T)
        print(f"  c = {c:g} tol {tol:g}: n_rhs {a['n_rhs']} cpu {time.process_time() - t0:.1f} s; largest stretch rate "
              f"at t = {', '.join(f'{t:g}' for t in ts)}: " + " ".join(f"{v:.1e}" for v in np.abs(sd).max(axis=1)),
              flush=True)
    ref = out[min(tols)]
    for tol in sorted(tols)[1:]:
        x, y, vx, vy, T = out[tol]
        print(f"    tol {tol:g} - tol {min(tols):g}: |dv| " + " ".join(
            f"{v:.1e}" for v in np.hypot(vx - ref[2], vy - ref[3]).max(axis=1)) + "; |dr| " + " ".join(
            f"{v:.1e}" for v in np.hypot(x - ref[0], y - ref[1]).max(axis=1)) + "; |dT|/max T " + " ".join(
            f"{v:.1e}" for v in np.abs(T - ref[4]).max(axis=1) / ref[4].max(axis=1)))


def _rodas_step(f, y, h):
    """One RODAS4 step (the tableau of :mod:`snapping.simulate.rosenbrock`, as
    :func:`elastic_rodas.rodas_step` takes it) of the small autonomous system ``f`` with its
    exact Jacobian (complex-step derivatives)."""
    from snapping.simulate.rosenbrock import A_ST, C_ST, GAMMA

    n = y.size
    J = np.zeros((n, n))
    for i in range(n):
        yc = y.astype(complex)
        yc[i] += 1e-30j
        J[:, i] = f(yc).imag / 1e-30
    W = np.eye(n) / (GAMMA * h) - J
    U = np.zeros((7, n))
    for s in range(6):
        arg = y + sum(A_ST[s, j] * U[1 + j] for j in range(s))
        U[1 + s] = np.linalg.solve(W, f(arg) + sum(C_ST[s, j] / h * U[1 + j] for j in range(s)))
    return y + sum(A_ST[5, j] * U[1 + j] for j in range(5)) + U[6]


def pendulum(c, whs, t1=1.1):
    """The stiff pendulum (unit mass on a two-sided spring of rest length 1, omega = c, released
    horizontal at rest) stepped by RODAS4 with fixed steps omega h, in Cartesian coordinates
    (x, y, vx, vy: the elastic line's) and in polar ones (r, theta, r', theta': the stretch a
    state variable): the largest radial speed |r'| to t1 (the line's own, quasi-static: about
    3 g/c^2 ~ 3e-6 at c = 1000)."""
    k = c * c

    def cart(z):
        x, y, vx, vy = z
        r = np.sqrt(x * x + y * y)
        T = k * (r - 1.0)
        return np.array([vx, vy, -T * x / r, -T * y / r - 1.0])

    def polar(z):  # theta from the downward vertical
        r, th, rd, thd = z
        return np.array([rd, thd, r * thd ** 2 - k * (r - 1.0) + np.cos(th), (-2.0 * rd * thd - np.sin(th)) / r])

    for wh in whs:
        h = wh / c
        n = int(t1 / h) + 1
        zc, zp = np.array([1.0, 0.0, 0.0, 0.0]), np.array([1.0, np.pi / 2, 0.0, 0.0])
        mc = mp = 0.0
        for _ in range(n):
            zc, zp = _rodas_step(cart, zc, h), _rodas_step(polar, zp, h)
            x, y, vx, vy = zc
            mc = max(mc, abs((x * vx + y * vy) / np.hypot(x, y)))
            mp = max(mp, abs(zp[2]))
        print(f"  stiff pendulum c = {c:g}, omega h = {wh:g} ({n} steps to t = {t1}): largest |r'| cartesian "
              f"{mc:.2e}, polar {mp:.2e}", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", type=int, default=200)
    ap.add_argument("--c", type=float, nargs="+", default=[30.0, 300.0, 3000.0])
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--tol", type=float, default=3e-6)
    ap.add_argument("--start", default="matched")
    ap.add_argument("--grid-damping", type=float, default=0.0)
    ap.add_argument("--hscan", action="store_true", help="error against step size at two states")
    ap.add_argument("--fixed", type=float, nargs="+", default=None,
                    help="instead: fixed steps of these sizes (no error control) to --t-fixed")
    ap.add_argument("--t-fixed", type=float, default=0.5)
    ap.add_argument("--ringing", type=float, nargs="+", default=None,
                    help="instead: runs at these tolerances, their stretch rates and differences at ten times")
    ap.add_argument("--pendulum", type=float, nargs="+", default=None,
                    help="instead: the stiff pendulum at c (the first --c) with fixed steps of these omega h")
    a = ap.parse_args(argv)
    print(f"machine: {platform.node()} {platform.processor() or platform.machine()}, {os.cpu_count()} cpus, load "
          f"{os.getloadavg()[0]:.1f}; N = {a.N}, chi = {a.chi}, start = {a.start}, tol = {a.tol}, zeta = "
          f"{a.grid_damping}")
    if a.pendulum:
        pendulum(a.c[0], a.pendulum)
        return
    p = Problem.catenary(a.chi, links=Links.uniform(a.N, lumping="shared"))
    if a.ringing:
        for c in a.c:
            ringing(p, c, a.grid_damping, a.start, a.ringing)
        return
    if a.fixed:
        for c in a.c:
            fixed_steps(p, c, a.grid_damping, a.start, a.fixed, a.t_fixed)
        return
    run(problem=p, method="fast", tol=1e-10)
    t0 = time.process_time()
    fr = run(problem=p, method="fast", tol=1e-10)
    fcpu = time.process_time() - t0
    fs = fr.summary()
    fast_t = fr.dataset["t"].values[1:]
    print(f"  fast (inextensible, tol 1e-10): n_rhs {fs['n_rhs']} steps {fs['n_steps']} cpu {fcpu:.3f} s "
          f"t_final {fast_t[-1]:.6f} v {fs['v_peak']:.8g} a {fs['a_peak']:.8g} sigma {fs['sigma_peak']:.8g}")
    for c in a.c:
        probe(p, c, a.tol, a.start, a.grid_damping, a.hscan, fast_t)


if __name__ == "__main__":
    main()
