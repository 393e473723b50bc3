"""Prototype: the elastic line's RODAS4 in link coordinates (length and angle of each link), against
the Cartesian node coordinates of ``elastic.solve(..., method="rodas4")`` (issue 22).

The diagnosis (``benchmarks/probe_elastic_steps.py``): a RODAS4 step in Cartesian node
coordinates is linear in the state within its stages' linear solves, so a link that turns by
``theta' h`` in the step is lengthened at second order by ``(theta' h)^2 l/2``, and the stiff
force ``EA/h`` times that is an error the step cannot damp (``f''`` grows as EA): on a stiff
pendulum the Cartesian step rings or blows up from omega h ~ 10 on, the polar one not at all.
Here the same method steps the chain in the variables ``(l_j, theta_j, l_j', theta_j')`` of
each link j (node j to node j + 1; node N the held end, fixed): the stiff force is linear in
``l_j`` and a rotation does not stretch. The equations: ``a_i = (T_i u_i - T_{i-1} u_{i-1})/m_i
+ g e_y``, ``d_j'' = a_{j+1} - a_j`` (``a_N = 0``), ``l_j'' = u_j . d_j'' + l_j theta_j'^2``,
``theta_j'' = (n_j . d_j'' - 2 l_j' theta_j')/l_j``, ``T_j = EA (l_j/h_j - 1)`` when positive
(tension only, linear law, no damping). The Jacobian is exact (complex-step derivatives,
coloured: a link's rows reach its neighbours only), the stages are solved banded. The error
is measured in the node quantities of the Cartesian method (``U_6`` mapped to node positions and
velocities, the same max norm ``|e|/(tol (1 + |y|))``, the same step rule), so the two use one
tolerance with one meaning.

Printed: steps, evaluations and CPU (numpy, not compiled: only the counts compare) of the
prototype to the reference run's end time (the snap), and of the compiled Cartesian run at the
same tol; their peaks (v, a, sigma) against a reference (the compiled Cartesian run at
``--ref-tol``): the largest at step ends, and refined as ``elastic_solve._Peaks`` does (the
prototype: 23 interior states of the steps on either side of each step-end maximum, each
reached by one step from the step's start).

Usage::

    PYTHONPATH=src python benchmarks/elastic_polar_prototype.py --N 200 --c 300 3000 --tol 3e-6 --ref-tol 1e-8
    PYTHONPATH=src python benchmarks/elastic_polar_prototype.py --cell 0.3 442 -3 --tol 1e-6
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np
from scipy.linalg import solve_banded

from snapping.simulate import run
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.elastic_model import ElasticLine
from snapping.simulate.problem import Links, Problem
from snapping.simulate.rosenbrock import A_ST, C_ST, GAMMA

SAFE, FAC_MIN, FAC_MAX = 0.9, 0.2, 6.0


class PolarLine:
    """The line in link coordinates y[4j:4j+4] = (l_j, theta_j, l_j', theta_j')."""

    def __init__(self, line):
        self.N, self.h, self.ea, self.g = line.N, line.h, line.ea, line.g
        self.invm = 1.0 / line.m
        p = line.pin_state(0.0)
        if np.any(p[2:] != 0.0) or line.pin.kind != "fixed":
            raise ValueError("prototype: a fixed held end only")
        self.pin = p
        self.nfev = 0

    def from_cartesian(self, z):
        N = self.N
        x = np.append(z[0:4 * N:4], self.pin[0])
        y = np.append(z[1:4 * N:4], self.pin[1])
        vx = np.append(z[2:4 * N:4], 0.0)
        vy = np.append(z[3:4 * N:4], 0.0)
        dx, dy, dvx, dvy = np.diff(x), np.diff(y), np.diff(vx), np.diff(vy)
        l = np.hypot(dx, dy)
        th = np.arctan2(dy, dx)
        ux, uy = dx / l, dy / l
        out = np.zeros(4 * N)
        out[0::4], out[1::4] = l, th
        out[2::4] = ux * dvx + uy * dvy
        out[3::4] = (-uy * dvx + ux * dvy) / l
        return out

    def nodes(self, q):
        """Node positions and velocities (N free nodes) of the link state q."""
        l, th, ld, thd = q[0::4], q[1::4], q[2::4], q[3::4]
        c, s = np.cos(th), np.sin(th)
        ddx, ddy = l * c, l * s
        dvx, dvy = ld * c - l * thd * s, ld * s + l * thd * c
        rc = lambda a: np.cumsum(a[::-1])[::-1]  # noqa: E731  (sum over k >= i)
        return (self.pin[0] - rc(ddx), self.pin[1] - rc(ddy), -rc(dvx), -rc(dvy))

    def f(self, q):
        """dq/dt (works on complex q for the complex-step Jacobian)."""
        self.nfev += 1
        N = self.N
        l, th, ld, thd = q[0::4], q[1::4], q[2::4], q[3::4]
        ux, uy = np.cos(th), np.sin(th)
        e = l / self.h - 1.0
        T = np.where(e.real > 0.0, self.ea * e, 0.0)
        Fx, Fy = T * ux, T * uy
        ax = np.zeros(N + 1, dtype=q.dtype)
        ay = np.zeros(N + 1, dtype=q.dtype)
        ax[:N] = Fx * self.invm
        ay[:N] = Fy * self.invm + self.g
        ax[1:N] -= Fx[:N - 1] * self.invm[1:]
        ay[1:N] -= Fy[:N - 1] * self.invm[1:]
        ddx, ddy = np.diff(ax), np.diff(ay)
        out = np.zeros_like(q)
        out[0::4], out[1::4] = ld, thd
        out[2::4] = ux * ddx + uy * ddy + l * thd * thd
        out[3::4] = (-uy * ddx + ux * ddy - 2.0 * ld * thd) / l
        return out

    def measures(self, q):
        N = self.N
        x, y, vx, vy = self.nodes(q)
        l, th = q[0::4], q[1::4]
        ux, uy = np.cos(th), np.sin(th)
        e = l / self.h - 1.0
        T = np.where(e > 0.0, self.ea * e, 0.0)
        ax = T * ux * self.invm
        ay = T * uy * self.invm + self.g
        ax[1:] -= T[:N - 1] * ux[:N - 1] * self.invm[1:]
        ay[1:] -= T[:N - 1] * uy[:N - 1] * self.invm[1:]
        return float(np.hypot(vx, vy).max()), float(np.hypot(ax, ay).max()), float(T.max())

    def jac_band(self, q):
        """The Jacobian in band storage (bandwidths 7, 7), complex-step, 12 colours."""
        n = q.size
        ab = np.zeros((15, n))
        for col in range(3):
            for comp in range(4):
                qc = q.astype(complex)
                idx = np.arange(4 * col + comp, n, 12)
                qc[idx] += 1e-30j
                d = self.f(qc).imag / 1e-30
                for k in idx:  # (the rows of links j - 1, j, j + 1 only: farther ones see other links)
                    j = k // 4
                    rows = np.arange(max(0, 4 * (j - 1)), min(n, 4 * (j + 2)))
                    ab[7 + rows - k, k] = d[rows]
        return ab

    def cart_error(self, q, U):
        """The node position and velocity errors of the link-coordinate error U (linearised)."""
        l, th, ld, thd = q[0::4], q[1::4], q[2::4], q[3::4]
        dl, dth, dld, dthd = U[0::4], U[1::4], U[2::4], U[3::4]
        c, s = np.cos(th), np.sin(th)
        ex = dl * c - l * dth * s
        ey = dl * s + l * dth * c
        evx = dld * c - ld * dth * s - (dl * thd + l * dthd) * s - l * thd * dth * c
        evy = dld * s + ld * dth * c + (dl * thd + l * dthd) * c - l * thd * dth * s
        rc = lambda a: np.cumsum(a[::-1])[::-1]  # noqa: E731
        out = np.zeros_like(U)
        out[0::4], out[1::4], out[2::4], out[3::4] = -rc(ex), -rc(ey), -rc(evx), -rc(evy)
        return out

    def cart(self, q):
        x, y, vx, vy = self.nodes(q)
        out = np.zeros(4 * self.N)
        out[0::4], out[1::4], out[2::4], out[3::4] = x, y, vx, vy
        return out


def one_step(pl, q, f0, ab, hs):
    """One RODAS4 step of size hs from q (f0, ab: f and the banded Jacobian there): (q1, U_6)."""
    n = q.size
    W = -ab.copy()
    W[7] += 1.0 / (GAMMA * hs)
    U = np.zeros((7, n))
    for st in range(6):
        if st == 0:
            b = f0.copy()
        else:
            b = pl.f(q + sum(A_ST[st, j] * U[1 + j] for j in range(st)))
            b += sum(C_ST[st, j] / hs * U[1 + j] for j in range(st))
        U[1 + st] = solve_banded((7, 7), W, b)
    return q + sum(A_ST[5, j] * U[1 + j] for j in range(5)) + U[6], U[6]


def rodas_polar(pl, q, t_end, tol, h=1e-4, samples=24):
    """RODAS4 with the step rule of ``elastic_rodas.rodas_accept`` (Gustafsson's predictive
    controller), the error in node quantities. Returns steps, rejections, the step-end maxima
    of v, a and sigma, and the peaks refined as ``elastic_solve._Peaks`` does: in the steps on
    either side of each step-end maximum, ``samples - 1`` interior states, each reached by one
    step from the step's start."""
    t, nstep, nrej = 0.0, 0, 0
    hacc, erracc = -1.0, 0.0
    best = np.array(pl.measures(q))
    ibest = np.zeros(3, dtype=int)
    f0 = pl.f(q)
    ab = pl.jac_band(q)
    hist = []
    while t < t_end:
        reject = False
        while True:
            last = t + 1.01 * h >= t_end
            hs = t_end - t if last else h
            q1, U6 = one_step(pl, q, f0, ab, hs)
            y0c, y1c = pl.cart(q), pl.cart(q1)
            e = pl.cart_error(q, U6)
            err = float(np.max(np.abs(e) / (tol * (1.0 + np.maximum(np.abs(y0c), np.abs(y1c))))))
            if not np.isfinite(err):
                nrej += 1
                h = 0.1 * hs
                reject = True
                continue
            fac = min(1.0 / FAC_MIN, max(1.0 / FAC_MAX, err ** 0.25 / SAFE))
            hnew = hs / fac
            if err <= 1.0:
                if hacc > 0.0:
                    facg = (hacc / hs) * (err * err / erracc) ** 0.25 / SAFE
                    facg = min(1.0 / FAC_MIN, max(1.0 / FAC_MAX, facg))
                    hnew = hs / max(fac, facg)
                hacc, erracc = hs, max(1e-2, err)
                if reject:
                    hnew = min(hnew, hs)
                hist.append((t, q, f0, ab, hs))
                q, t, h = q1, (t_end if last else t + hs), hnew
                nstep += 1
                f0 = pl.f(q)
                ab = pl.jac_band(q)
                m = np.array(pl.measures(q))
                up = m > best
                best = np.where(up, m, best)
                ibest = np.where(up, len(hist), ibest)  # (the step ending at the maximum: hist[ibest - 1])
                break
            nrej += 1
            reject = True
            h = hnew
    nfev = pl.nfev
    refined = best.copy()
    for k in range(3):
        for i in (ibest[k] - 1, ibest[k]):
            if 0 <= i < len(hist):
                t0, q0, f00, ab0, hs = hist[i]
                for x in range(1, samples):
                    qs, _ = one_step(pl, q0, f00, ab0, hs * x / samples)
                    refined[k] = max(refined[k], pl.measures(qs)[k])
    pl.nfev = nfev
    return nstep, nrej, best, refined


def cell(a):
    """One stretching cell (``snapping.regimes.cell_problem``, the tip links 1.7e-5 long at
    level -3), matched start, undamped: the Cartesian run (stop rule, ``stop_floor=1``) and the
    prototype to its end, at each tol."""
    from snapping.continuum import level_parameters
    from snapping.regimes import cell_problem

    chi, c, k = a.cell
    lv = level_parameters(8, 0.5, first=-4)
    p = cell_problem(chi, "stretching", 1.0 / c, lv[int(k) + 4], damping=0.0)
    line = ElasticLine(p, Elastic.from_wave_speed(c))
    print(f"machine: {platform.node()} {platform.processor() or platform.machine()}, {os.cpu_count()} cpus, load "
          f"{os.getloadavg()[0]:.1f}; cell chi {chi} c {c:g} level {int(k)}: N = {line.N}, shortest link "
          f"{line.h.min():.2g}, matched start")
    for tol in a.tol:
        for zeta in a.cell_zeta:
            t0 = time.process_time()
            cs = solve(p, Elastic.from_wave_speed(c, grid_damping=zeta), tol=tol, method="rodas4", start="matched",
                       stop_floor=1.0, max_rhs=a.max_rhs).summary()
            print(f"  Cartesian tol {tol:g} zeta {zeta:g}: steps {cs['n_steps']} n_rhs {cs['n_rhs']} slack steps "
                  f"{cs['n_slack_steps']} cpu {time.process_time() - t0:.1f} s {cs['status']} ({cs['stop_reason']}) "
                  f"t_final {cs['t_final']:.5f} peaks v {cs['v_peak']:.7g} a {cs['a_peak']:.7g} "
                  f"sigma {cs['sigma_peak']:.7g}", flush=True)
        pl = PolarLine(line)
        q0 = pl.from_cartesian(line.start("matched"))
        t0 = time.process_time()
        ns, nr, best, refined = rodas_polar(pl, q0, cs["t_final"], tol)
        print(f"  polar     tol {tol:g} undamped: steps {ns} (rejected {nr}) n_rhs {6 * (ns + nr) + ns} cpu "
              f"{time.process_time() - t0:.1f} s (numpy) peaks (refined) v {refined[0]:.7g} a {refined[1]:.7g} "
              f"sigma {refined[2]:.7g}", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", type=int, default=200)
    ap.add_argument("--c", type=float, nargs="+", default=[300.0, 3000.0])
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--tol", type=float, nargs="+", default=[3e-6])
    ap.add_argument("--ref-tol", type=float, default=1e-8)
    ap.add_argument("--cell", type=float, nargs=3, default=None, metavar=("CHI", "C", "K"),
                    help="instead: the stretching study's cell (fold-graded links at level K, as "
                         "benchmarks/stretch_cell.py), undamped, against the Cartesian run at --tol")
    ap.add_argument("--max-rhs", type=int, default=1_500_000)
    ap.add_argument("--cell-zeta", type=float, nargs="+", default=[0.0],
                    help="grid damping of the Cartesian run(s) in --cell (the study's is 4); the prototype is undamped "
                         "and runs to the last one's end")
    a = ap.parse_args(argv)
    if a.cell:
        return cell(a)
    print(f"machine: {platform.node()} {platform.processor() or platform.machine()}, {os.cpu_count()} cpus, load "
          f"{os.getloadavg()[0]:.1f}; N = {a.N}, chi = {a.chi}, matched start, no damping")
    p = Problem.catenary(a.chi, links=Links.uniform(a.N, lumping="shared"))
    run(problem=p, method="fast", tol=1e-10)
    t0 = time.process_time()
    fs = run(problem=p, method="fast", tol=1e-10).summary()
    print(f"  fast (inextensible, tol 1e-10): steps {fs['n_steps']} n_rhs {fs['n_rhs']} cpu "
          f"{time.process_time() - t0:.3f} s", flush=True)
    for c in a.c:
        el = Elastic.from_wave_speed(c)
        line = ElasticLine(p, el)
        t0 = time.process_time()
        ref = solve(p, el, tol=a.ref_tol, method="rodas4", start="matched")
        rs = ref.summary()
        pk = np.array([rs["v_peak"], rs["a_peak"], rs["sigma_peak"]])
        print(f"  c = {c:g} reference (Cartesian, tol {a.ref_tol:g}): steps {rs['n_steps']} n_rhs {rs['n_rhs']} cpu "
              f"{time.process_time() - t0:.1f} s t_final {rs['t_final']:.6f} peaks v {pk[0]:.8g} a {pk[1]:.8g} "
              f"sigma {pk[2]:.8g}", flush=True)
        for tol in a.tol:
            t0 = time.process_time()
            cr = solve(p, el, tol=tol, method="rodas4", start="matched", t_end=rs["t_final"])
            cs = cr.summary()
            ds = cr.dataset
            cb = np.array([ds["v_max"].values.max(), ds["a_max"].values.max(), ds["sigma_max"].values.max()])
            cp = np.array([cs["v_peak"], cs["a_peak"], cs["sigma_peak"]])
            print(f"    Cartesian tol {tol:g}: steps {cs['n_steps']} n_rhs {cs['n_rhs']} (x fast "
                  f"{cs['n_rhs'] / fs['n_rhs']:.2f}) cpu {time.process_time() - t0:.2f} s; against the reference's "
                  "peaks: step-end maxima " + " ".join(f"{x:+.2e}" for x in cb / pk - 1.0) + ", refined "
                  + " ".join(f"{x:+.2e}" for x in cp / pk - 1.0), flush=True)
            pl = PolarLine(line)
            q0 = pl.from_cartesian(line.start("matched"))
            t0 = time.process_time()
            ns, nr, best, refined = rodas_polar(pl, q0, rs["t_final"], tol)
            print(f"    polar     tol {tol:g}: steps {ns} (rejected {nr}) n_rhs {6 * (ns + nr) + ns} (+{12 * ns} "
                  f"complex for the Jacobians; x fast {(6 * (ns + nr) + ns) / fs['n_rhs']:.2f}) cpu "
                  f"{time.process_time() - t0:.1f} s (numpy); against the reference's peaks: step-end maxima "
                  + " ".join(f"{x:+.2e}" for x in best / pk - 1.0) + ", refined "
                  + " ".join(f"{x:+.2e}" for x in refined / pk - 1.0), flush=True)


if __name__ == "__main__":
    main()
