"""Two real lines beside the ideal chain (issue 21, "Done when"): a bullwhip cracked by a
stroke of its handle and a fly line falling from a catenary, with their energy balance.

* **Bullwhip** (:mod:`snapping.lines` ``bullwhip``: a leather cone, lambda ~ d^2, EI ~ d^4,
  drag, a 1 g cracker with its drag area): released at rest, held at end separation
  chi = 0.25 (its static equilibrium), its handle clamped in the catenary's direction (it
  holds the thong's direction through the bending stiffness) and moved as a cracking stroke: the handle jerked back (``PinMotion.flick``,
  peak 10 g over 0.3 sqrt(L/g) = 0.15 s, the handle moving back by 0.14 L = 35 cm and
  stopping) while it turns by 2 radians (a prescribed clamp angle, smooth, at rest at both
  ends: :func:`stroke`).
* **Fly line** (``fly-line``: 30 ft of a WF-5 floating line, tapered, with a dry fly's mass and
  drag): released at rest at chi = 0.25 (its static equilibrium, within 1e-3 L of the
  catenary) from a still rod tip.

Each beside the ideal chain of the same geometry: the same links (the same tapered masses and
tip mass), the same start and held-end motion, B = 0 and no drag (a hinge: no clamp). The
peaks in SI: the largest speed over the chain at the snap (``v_peak``), the free end's largest
speed over the run (``v_tip``), the peak acceleration and the peak tension (N; units of
lambda g L with the line's mean lambda = M/L).

Then the energy balance of the fly line's drag run, max over the run of
``|KE + PE + bending - pin work + dissipated - E0| / E0`` (the Dataset's
``energy - pin_work + dissipated``), at several tolerances: it shrinks with the tolerance.

Usage::

    python examples/real_lines.py                    # N = 200 (whip and fly line), tol 1e-6, 1e-8, 1e-10
    python examples/real_lines.py --N 100 --quick    # coarse, seconds
    python examples/real_lines.py --whip-levels 100,200,400   # the whip refined (a minute)
    python examples/real_lines.py --whip-levels 100,200 --method stiff   # the real lines by RODAS4

Each line starts at rest (the default with bending: its static equilibrium, held at both
ends; the ideal chain's is its catenary). The real lines run by ``--method`` (default
``fast``: dop853 here, since their shortest bending waves are undamped, its step limited by
dt ~ h^2 sqrt(lambda/B)); the ideal chains by ``fast`` (dop853). The table says which start
and method each run took.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from snapping import lines
from snapping.simulate import PinMotion, Problem, run

G = 9.81
CHI = 0.25


def balance(ds) -> float:
    """max over the run of |E - W + D - E(0)| / E(0): ``energy`` (kinetic + gravity + bending),
    ``pin_work`` and ``dissipated`` of a body run."""
    b = np.asarray(ds["energy"] - ds["pin_work"] + ds["dissipated"], dtype=float)
    return float(np.max(np.abs(b - b[0])) / abs(b[0]))


def stroke(N: int, accel: float = 10.0, period: float = 0.3, turn: float = 2.0, length: float | None = None):
    """The bullwhip's cracking stroke for ``N`` links: (links, pin motion, clamp samples (t, angle))."""
    whip = lines.get("bullwhip")
    links = whip.links(N, length)
    start = Problem.catenary(CHI, links=links)
    a0 = math.atan2(start.y[-2] - start.y[-1], start.x[-2] - start.x[-1])  # the thong leaves the handle here
    t = np.linspace(0.0, period, 9)
    angle = a0 + turn * 0.5 * (1.0 - np.cos(math.pi * t / period))  # smooth, at rest at both ends
    return links, PinMotion.flick((-accel, 0.0), period), (t, angle)


def problems(name: str, N: int, **kw):
    """(the real line's Problem, the ideal chain's) for the showcase run of line ``name``."""
    line = lines.get(name)
    if name == "bullwhip":
        links, pin, clamp = stroke(N, **kw)
        real = Problem.catenary(CHI, links=links, pin=pin, body=line.body(clamp=clamp))
    else:
        links, pin = line.links(N), None
        real = Problem.catenary(CHI, links=links, body=line.body())
    return real, Problem.catenary(CHI, links=links, pin=pin)


def peaks(result, line) -> dict:
    """The run's peaks in SI for the catalogue length of ``line``."""
    s, ds = result.summary(), result.dataset
    L, M = line.length, line.mass()
    u = math.sqrt(G * L)
    return {"v_peak": s["v_peak"] * u, "v_tip": float(ds["v_end"].max()) * u, "a_peak": s["a_peak"] * G,
            "sigma_peak": s["sigma_peak"] * M * G, "t_snap": s["t_snap_v"] * math.sqrt(L / G), "n_rhs": s["n_rhs"]}


def showcase(N: int, tols=(1e-6, 1e-8, 1e-10), out=print, method: str = "fast") -> dict:
    """Run and print the table (the real lines by ``method``, the ideal chains by ``fast``, that
    is dop853); returns the numbers."""
    rows, res = [], {}
    for name, title in (("bullwhip", "bullwhip, cracking stroke"), ("fly-line", "fly line, falling catenary")):
        real, ideal = problems(name, N)
        for label, p in ((title, real), ("  ideal chain, same geometry", ideal)):
            t0 = time.perf_counter()
            r = run(p, progress=False, method=method if p is real else "fast")
            pk = peaks(r, lines.get(name))
            pk["wall"] = time.perf_counter() - t0
            pk["method"], pk["start"] = r.dataset.attrs["method"], r.summary().get("start_rest", "catenary")
            res[(name, "ideal" if p is ideal else "real")] = pk
            rows.append((label, pk))
    out(f"Real lines beside the ideal chain (chi = {CHI}, N = {N}, tol 1e-6, real lines: method {method!r})")
    out(f"{'run':32s} {'v_peak m/s':>11s} {'v_tip m/s':>10s} {'a_peak m/s2':>12s} {'sigma_peak N':>13s} "
        f"{'t_snap s':>9s} {'start':>11s} {'method':>7s} {'n_rhs':>8s} {'wall s':>7s}")
    for label, pk in rows:
        out(f"{label:32s} {pk['v_peak']:11.4g} {pk['v_tip']:10.4g} {pk['a_peak']:12.4g} {pk['sigma_peak']:13.4g} "
            f"{pk['t_snap']:9.4f} {pk['start']:>11s} {pk['method']:>7s} {pk['n_rhs']:8d} {pk['wall']:7.2f}")
    out("")
    out(f"Energy balance of the fly line's drag run (N = {N}): max |KE + PE + bending - pin work + dissipated - E0|"
        f" / E0")
    out(f"{'tol':>8s} {'balance':>10s} {'dissipated/E0':>14s} {'n_rhs':>8s}")
    real, _ = problems("fly-line", N)
    t_end = 1.1 * res[("fly-line", "real")]["t_snap"] / math.sqrt(lines.get("fly-line").length / G)
    for tol in tols:  # (to the same end, a little after the snap: the same dissipated energy)
        ds = run(real, tol=tol, t_end=t_end, progress=False, method=method).dataset
        e0 = float(ds["energy"][0])
        res[("balance", tol)] = balance(ds)
        out(f"{tol:8.0e} {res[('balance', tol)]:10.3g} {float(ds['dissipated'][-1]) / e0:14.6f} "
            f"{int(ds.attrs['n_rhs']):8d}")
    return res


def whip_convergence(Ns=(100, 200, 400), out=print, method: str = "fast") -> dict:
    """The bullwhip's cracking stroke refined: its SI peaks at each N."""
    whip, res = lines.get("bullwhip"), {}
    out(f"The bullwhip's stroke refined (tol 1e-6, method {method!r})")
    out(f"{'N':>5s} {'v_tip m/s':>10s} {'a_peak m/s2':>12s} {'sigma_peak N':>13s} {'t(sigma max) s':>15s} "
        f"{'method':>7s} {'n_rhs':>8s} {'wall s':>7s}")
    for N in Ns:
        t0 = time.perf_counter()
        r = run(problems("bullwhip", N)[0], progress=False, method=method)
        wall = time.perf_counter() - t0
        pk = peaks(r, whip)
        k = int(np.argmax(r.dataset["sigma_max"].values))
        pk["t_sigma"] = float(r.dataset["t"][k]) * math.sqrt(whip.length / G)
        res[N] = pk
        pk["method"], pk["wall"] = r.dataset.attrs["method"], wall
        out(f"{N:5d} {pk['v_tip']:10.4g} {pk['a_peak']:12.4g} {pk['sigma_peak']:13.4g} {pk['t_sigma']:15.4f} "
            f"{pk['method']:>7s} {pk['n_rhs']:8d} {wall:7.2f}")
    return res


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--N", type=int, default=200, help="links of each line (default 200)")
    p.add_argument("--quick", action="store_true", help="tolerances 1e-6, 1e-8 only")
    p.add_argument("--whip-levels", default=None, metavar="N1,N2,...",
                   help="instead: the bullwhip's stroke at these N (e.g. 100,200,400)")
    p.add_argument("--method", default="fast", choices=("fast", "dop853", "stiff", "rodas4"),
                   help="the real lines' method (default fast: dop853 or rodas4, chosen per run; "
                        "the ideal chains always run fast)")
    a = p.parse_args(argv)
    if a.whip_levels:
        whip_convergence([int(v) for v in a.whip_levels.split(",")], method=a.method)
        return 0
    showcase(a.N, (1e-6, 1e-8) if a.quick else (1e-6, 1e-8, 1e-10), method=a.method)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
