"""Why does a little bending stiffness raise the snap at small chi? (issue 24)

The bending study (``docs/guide/regimes.md``, ``bench_bendconv.py``) found the converged peak tip
speed at chi = 0.1 raised by a small stiffness: x1.729 at beta = 7.2e-8, x1.288 at 1e-8, x1.685 at
5.2e-7; x1.193 at chi = 0.2, x1.030 at 0.3, none at 0.5. This script runs the bent cell of the study
(:func:`snapping.regimes.cell_problem`: rest start, grid damping 1, RODAS4) and, on the SAME links,
the ideal chain and variants that switch one ingredient at a time:

* ``ideal``: no body, the catenary start (DOP853);
* ``bent``: the study's cell (bending, its grid damping, the heavy-elastica rest start);
* ``bent-cat``: the same body released from the catenary instead of its rest shape;
* ``ideal-rest``: the ideal chain released from the bent line's rest shape;
* ``damp-only``: the grid damping alone (bending 0);
* ``bent-z0.5`` / ``bent-z2``: the grid damping ratio halved / doubled;
* ``ideal-late`` / ``bent-late``: as ``ideal`` / ``bent``, run on after the snap until v_max falls to
  ``LATE_STOP`` of its peak or to t = ``LATE_END`` (is the peak the stop rule's?);
* ``tipX`` / ``outX``: bending (and its grid damping) only on the nodes within arclength X of the
  free end / only beyond it, released from the catenary (where along the line does bending act?);
  ``bandA-B``: only on A < r <= B;
* ``ib@T`` / ``bi@T``: the ideal chain to t = T, then the bent line from that state / the bent line
  (``bent-cat``) to T, then the ideal chain (when does bending act?).

Each run's diagnostics (:func:`diagnose`): its peaks and cost (evaluations, CPU by
``time.process_time``); the energy balance (the largest |E + dissipated - E0| over the run, E = kinetic
+ gravity + bending, and the recorded E against kinetic + gravity + bending recomputed here from the
snapshots); the speed budget at the peak (:func:`peak_profile`: the piece moving faster than v_peak/2,
its kinetic energy, mass and profile shape, and the kinetic energy within fixed distances of the free
end); the bending energy (its maximum, its value at the peak); the fold (:func:`fold`: the curvature
maximum's growth exponent ``kappa_max ~ (t* - t)^-p`` over t* - t in [1e-3, 1e-2] and [1e-4, 1e-3], the
paper's regularisation length delta, where the fold's distance from the free end first falls to its
quarter circle pi / (2 kappa_max), its estimate v_delta = sqrt(6 P / delta), P the energy released, and
the bending length sqrt(beta / sigma_max) there against the fold radius); the free end (:func:`tip`: its
lag behind the line's fastest point and its curl in the last 1e-3 before the peak).

Results are kept in a JSON file (``--out``) and reused (rerunning resumes); ``--figure`` draws the
fold's curvature and the free end's speed against t* - t, bent against ideal, and the line near the
free end at eight times (rerunning two runs for their snapshots, kept in ``bending_rise_shapes.json``).

Usage::

    python benchmarks/bending_rise.py                                  # the default set (below)
    python benchmarks/bending_rise.py --table                          # what is done so far
    python benchmarks/bending_rise.py --chi 0.1 --beta 7.2e-8 --k 0 --variants ideal bent bent-cat
    python benchmarks/bending_rise.py --table --figure docs/guide/bending_rise.png
    python benchmarks/bending_rise.py --fold-profile                   # the fold through the fall
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import time
from pathlib import Path

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "results", "bending_rise.json")
VARIANTS = ("ideal", "bent", "bent-cat", "ideal-rest", "damp-only", "bent-z0.5", "bent-z2", "ideal-late", "bent-late",
            "tip0.01", "out0.01", "tip0.001", "out0.001")
#: the '-late' variants: run on until v_max falls to LATE_STOP of its peak (the study's 0.5) or to t = LATE_END
LATE_STOP, LATE_END = 0.1, 1.3
#: the bent runs' RODAS4 tolerance (their peaks are the study's at 1e-7 to 2e-6 relative: 47.2044 against
#: 47.2045 on 947 links, 57.593 and 57.190 as bench_bendconv's on 1857 and 7328) and the ideal's (the study's)
TOL_BENT, TOL_IDEAL = 1e-6, 1e-7
RADII = (1e-5, 3e-5, 1e-4, 3e-4, 1e-3, 1e-2)
#: the tip diagnostics' window (t* - t) and the reach of the tip's turning (arclength from the free end)
TIP_WINDOW, TIP_R = 1e-3, 1e-3
#: the windows of the curvature exponent fits, t* - t
FITS = ((1e-3, 1e-2), (1e-4, 1e-3))


def level(k: int) -> dict:
    from snapping.continuum import level_parameters

    return level_parameters(1, 0.5, first=k)[0]


def problems(chi: float, beta: float, k: int, variant: str):
    """The problem of ``variant`` on the bent cell's links, and the method and tolerance it runs at."""
    from snapping.regimes import GRID_DAMPING, cell_problem, eta_grid
    from snapping.simulate import Body, Links, Problem

    bent = cell_problem(chi, "bending", beta, level(k))
    h = bent.links.h
    variant = variant.replace("-late", "")
    links = Links.graded(h, lumping="shared")
    if variant == "ideal":
        return Problem.catenary(chi, links=links, chords="exact"), "fast", TOL_IDEAL
    if variant == "bent":
        return bent, "rodas4", TOL_BENT
    if variant == "ideal-rest":
        return Problem.nodes(bent.x, bent.y, links=links, name="bent rest shape"), "fast", TOL_IDEAL
    zeta = {"bent-z0.5": 0.5, "bent-z2": 2.0}.get(variant, GRID_DAMPING)
    eta = eta_grid(h, beta, zeta)
    if variant == "bent-cat":
        body = Body(bending=beta, damping=eta)
        return Problem.catenary(chi, links=links, chords="exact", body=body, start="catenary"), "rodas4", TOL_BENT
    if variant == "damp-only":
        return Problem.catenary(chi, links=links, chords="exact", body=Body(damping=eta)), "rodas4", TOL_BENT
    if variant[:3] in ("tip", "out") and variant[3:].replace(".", "", 1).replace("e-", "", 1).isdigit():
        r = np.concatenate([[0.0], np.cumsum(h)])  # each node's distance from the free end (index 0)
        on = (r <= float(variant[3:])) if variant.startswith("tip") else (r > float(variant[3:]))
        body = Body(bending=np.where(on, beta, 0.0), damping=np.where(on, eta, 0.0))
        return Problem.catenary(chi, links=links, chords="exact", body=body, start="catenary"), "rodas4", TOL_BENT
    if variant.startswith("band"):
        lo, hi = (float(x) for x in variant[4:].split("-", 1))
        r = np.concatenate([[0.0], np.cumsum(h)])
        on = (r > lo) & (r <= hi)
        body = Body(bending=np.where(on, beta, 0.0), damping=np.where(on, eta, 0.0))
        return Problem.catenary(chi, links=links, chords="exact", body=body, start="catenary"), "rodas4", TOL_BENT
    if variant in ("bent-z0.5", "bent-z2"):
        return cell_problem(chi, "bending", beta, level(k), damping=zeta), "rodas4", TOL_BENT
    raise SystemExit(f"unknown variant {variant!r}: one of {', '.join(VARIANTS)}, tipX, outX, bandA-B, ib@T, bi@T")


def switched(chi: float, beta: float, k: int, variant: str):
    """``ib@T``: the ideal chain from the catenary to t = T, then the bent line (bending and its grid
    damping switched on) from that state; ``bi@T``: the bent line from the catenary (``bent-cat``) to T,
    then the ideal chain. Returns the second run's problem, method, tolerance, the first run's end time
    and its evaluations and CPU seconds."""
    from snapping.simulate import Problem, run

    first, T = ("ideal" if variant.startswith("ib") else "bent-cat"), float(variant.split("@")[1])
    p1, m1, tol1 = problems(chi, beta, k, first)
    cpu = time.process_time()
    d1 = run(p1, method=m1, tol=tol1, t_end=T, progress=False).dataset
    cpu = time.process_time() - cpu
    kinds = [str(x) for x in d1.snapshot_kind.values]
    s = d1.isel(snapshot=kinds.index("final"))
    pb, mb, tolb = problems(chi, beta, k, "bent-cat")
    body = pb.body if variant.startswith("ib") else None
    p2 = Problem.nodes(s.x.values, s.y.values, links=pb.links, vx=s.vx.values, vy=s.vy.values,
                       name=f"{first} at t = {float(s.t_snapshot):.6g}", body=body)
    if body is None:
        m2, tol2 = "fast", TOL_IDEAL
    else:
        m2, tol2 = mb, tolb
    return p2, m2, tol2, float(s.t_snapshot), int(d1.attrs["n_rhs"]), cpu, float(d1.attrs["energy_initial"])


def energy_check(ds, beta) -> float:
    """The recorded energy against kinetic + gravity + bending recomputed here from every snapshot taken
    at a step's time (the peak's may lie between steps): the largest difference. Gravity is zero for the
    line hanging straight down at rest; bending ``sum beta phi_j^2 / (2 (h_j + h_j+1)/2)`` over the
    joints (phi the turning angle), the schema's formula, written out again here."""
    m, h = ds.node_mass.values, ds.link_length.values
    r = np.concatenate([[0.0], np.cumsum(h)])  # distance of each node from the free end (index 0)
    worst = 0.0
    for j in range(ds.sizes["snapshot"]):
        s = ds.isel(snapshot=j)
        i = int(np.argmin(np.abs(ds.t.values - float(s.t_snapshot))))
        if ds.t.values[i] != float(s.t_snapshot):
            continue
        x, y = s.x.values, s.y.values
        K = 0.5 * float(np.sum(m * (s.vx.values ** 2 + s.vy.values ** 2)))
        U = -float(np.sum(m * y)) + float(np.sum(m * (r[-1] - r)))  # y downward; hanging: depth L - r
        phi = np.diff(np.unwrap(np.arctan2(np.diff(y), np.diff(x))))
        Eb = float(np.sum(beta * phi ** 2 / (h[:-1] + h[1:])))
        worst = max(worst, abs(K + U + Eb - float(ds.energy.values[i])))
    return worst


def peak_profile(ds) -> dict:
    """The speed budget at the peak (the snapshot of kind 'peak'): the fast tip piece, out to
    ``r_half`` from the free end where the speed first falls to half the peak, holds the kinetic energy
    K_half in the mass m_half, and v_peak^2 = (2 K_half / m_half) / shape exactly, shape = the piece's
    mass-weighted mean of (v / v_peak)^2. So bent / ideal, v_peak^2 ratio = energy ratio x (1 / mass
    ratio) x (1 / shape ratio). Also the kinetic energy within fixed distances of the free end."""
    m, h = ds.node_mass.values, ds.link_length.values
    r = np.concatenate([[0.0], np.cumsum(h)])
    kinds = [str(x) for x in ds.snapshot_kind.values]
    s = ds.isel(snapshot=kinds.index("peak"))
    v = np.hypot(s.vx.values, s.vy.values)
    ke = 0.5 * m * v ** 2
    K = float(ke.sum())
    vp = float(v.max())
    n = int(np.argmax(v < 0.5 * vp))  # the first node (from the free end) below half the peak speed
    kh, mh = float(ke[:n].sum()), float(m[:n].sum())
    kap = np.abs(s.curvature.values)
    j = int(np.nanargmax(kap))
    return {"K": K, "K_within": {f"{x:g}": float(ke[r <= x].sum()) for x in RADII},
            "l50": float(r[np.searchsorted(np.cumsum(ke), 0.5 * K)]), "v_tip": float(v[0]), "v_max": vp,
            "r_half": float(r[n]), "n_half": n, "K_half": kh, "m_half": mh, "shape": 2.0 * kh / mh / vp ** 2,
            "kappa": float(kap[j]), "r_kappa": float(r[j]), "t": float(s.t_snapshot)}


def fold(ds, beta: float) -> dict:
    """The fold from the step record: the curvature maximum's growth exponent, the paper's
    regularisation length delta_kappa (the fold's distance from the free end first at or below its
    quarter circle pi / (2 kappa_max)), the estimate v_delta = sqrt(6 P / delta), and the bending
    length sqrt(beta / sigma_max) against the fold radius 1 / kappa_max there."""
    t, km = ds.t.values, ds.kappa_max.values
    dist = 1.0 - ds.s_kappa_max.values
    ts = float(ds.attrs["t_snap_v"])
    P = float(ds.attrs["energy_initial"])
    p = []
    for lo, hi in FITS:
        w = (ts - t >= lo) & (ts - t <= hi)
        p.append(-float(np.polyfit(np.log(ts - t[w]), np.log(km[w]), 1)[0]) if w.sum() > 3 else float("nan"))
    hit = np.flatnonzero(dist <= 0.5 * math.pi / km)
    before = t <= ts
    h0 = float(ds.link_length.values[0])
    out = {"kappa_exponent": p, "dist_min": float(dist[before].min()), "dist_min_links": float(dist[before].min()) / h0,
           "kappa_at": {f"{x:g}": float(np.interp(ts - x, t, km)) for x in (1e-2, 1e-3, 1e-4)}}
    if hit.size:
        i = int(hit[0])
        d = float(dist[i])
        out.update({"delta": d, "t_delta": float(t[i]), "tstar_minus_t_delta": ts - float(t[i]),
                    "v_delta": math.sqrt(6.0 * P / d), "fold_radius": 1.0 / float(km[i]),
                    "sigma_at_delta": float(ds.sigma_max.values[i])})
        if beta > 0:
            out["l_B_at_delta"] = math.sqrt(beta / float(ds.sigma_max.values[i]))
    return out


def history(ds, n: int = 120) -> dict:
    """The step record thinned to ~n steps log-spaced in t* - t (for the figure), 4 digits."""
    t = ds.t.values
    ts = float(ds.attrs["t_snap_v"])
    want = ts - np.logspace(-0.5, -7.0, n)
    i = np.unique(np.clip(np.searchsorted(t, want), 0, t.size - 1))
    i = i[t[i] <= ts]

    def r4(a):
        return [float(f"{x:.4g}") for x in a]
    return {"tstar_minus_t": r4(ts - t[i]), "kappa_max": r4(ds.kappa_max.values[i]), "v_max": r4(ds.v_max.values[i]),
            "v_end": r4(ds.v_end.values[i]), "dist": r4(1.0 - ds.s_kappa_max.values[i])}


def tip(ds) -> dict:
    """Is there a loop at the free end before the peak? From the step record over the final approach
    (t* - t <= TIP_WINDOW, to the peak): the free end's speed against the line's maximum (1: the free
    end is the fastest point throughout), the largest fall of the free end's speed below its running
    maximum (over v_peak), and the time fraction with the fastest point not at the free end. From the
    snapshots before the peak: the largest total turning sum |phi| of the line within TIP_R of the free
    end (about pi: a fold; more: the line curls)."""
    t, ve, vm = ds.t.values, ds.v_end.values, ds.v_max.values
    i = int(np.argmax(vm))
    ts = t[i]
    w = np.flatnonzero((ts - t <= TIP_WINDOW) & (t <= ts))
    run_max = np.maximum.accumulate(ve[w])
    dt = np.diff(t[w], append=t[w][-1])
    inside = ds.s_v_max.values[w] < 1.0 - 1e-9
    h = ds.link_length.values
    r = np.concatenate([[0.0], np.cumsum(h)])
    turn = 0.0
    for j in range(ds.sizes["snapshot"]):
        s = ds.isel(snapshot=j)
        if float(s.t_snapshot) > ts:
            continue
        phi = np.diff(np.unwrap(np.arctan2(np.diff(s.y.values), np.diff(s.x.values))))
        turn = max(turn, float(np.abs(phi[r[1:-1] <= TIP_R]).sum()))
    return {"v_end_over_v_max_min": float((ve[w] / vm[w]).min()), "v_end_dip": float((run_max - ve[w]).max() / vm[i]),
            "inside_fraction": float(dt[inside].sum() / max(dt.sum(), 1e-300)), "tip_turning_max": turn}


def diagnose(ds, beta) -> dict:
    """All diagnostics of one run; ``beta``: the bending stiffness per node (N + 1, free end first) or 0."""
    beta = np.broadcast_to(np.asarray(beta, dtype=float), ds.node_mass.shape)
    a = ds.attrs
    E, E0 = ds.energy.values, float(a["energy_initial"])
    D = ds.dissipated.values if "dissipated" in ds else np.zeros_like(E)
    i = int(np.argmax(ds.v_max.values))
    row = {q: float(a[q]) for q in ("v_peak", "a_peak", "sigma_peak", "kappa_peak", "t_snap_v", "energy_initial")}
    row.update({"N": int(a["N"]), "n_rhs": int(a["n_rhs"]), "method": a["method"], "tol": float(a["tol"]),
                "start_rest": a.get("start_rest", "catenary"), "closure": float(np.abs(E + D - E0).max()),
                "dissipated_at_peak": float(D[i]), "dissipated_final": float(D[-1]),
                "s_v_max_at_peak": float(ds.s_v_max.values[i]), "t_final": float(a["t_final"]),
                "stop_reason": a.get("stop_reason", "")})
    if "bending_energy" in ds:
        Eb = ds.bending_energy.values
        j = int(np.argmax(Eb))
        row.update({"Eb_start": float(Eb[0]), "Eb_max": float(Eb[j]), "t_Eb_max": float(ds.t.values[j]),
                    "Eb_at_peak": float(Eb[i])})
    row["peak"] = peak_profile(ds)
    row["energy_check"] = energy_check(ds, beta[1:-1])  # the joints: the interior nodes
    row["fold"] = fold(ds, float(beta.max()))
    row["history"] = history(ds)
    row["tip"] = tip(ds)
    return row


def key(chi, beta, k, variant):
    return f"{chi:g} {beta:g} {k} {variant}"


def load(path):
    return json.load(open(path)) if os.path.isfile(path) else {}


def run_one(chi, beta, k, variant, path):
    from snapping._files import write_atomic
    from snapping.simulate import run

    db = load(path)
    kk = key(chi, beta, k, variant)
    if kk in db:
        return db[kk]
    off, rhs0, cpu0, e0 = 0.0, 0, 0.0, None
    if "@" in variant:
        prob, method, tol, off, rhs0, cpu0, e0 = switched(chi, beta, k, variant)
    else:
        prob, method, tol = problems(chi, beta, k, variant)
    cpu = time.process_time()
    late = variant.endswith("-late")
    ds = run(prob, method=method, tol=tol, stop_fraction=LATE_STOP if late else 0.5,
             t_end_max=LATE_END if late else 10.0, progress=False).dataset
    cpu = time.process_time() - cpu
    if ds.attrs.get("status") != "completed" or not (late or int(ds.attrs.get("snap_reached", 0))):
        raise RuntimeError(f"{kk}: {ds.attrs.get('status')} {ds.attrs.get('stop_reason')}")
    row = diagnose(ds, prob.body.node_values("bending", prob.links.h) if prob.body is not None else 0.0)
    row["cpu"] = cpu + cpu0
    if "@" in variant:  # the second run's clock starts at the switch
        row.update({"t_switch": off, "t_snap_v": row["t_snap_v"] + off, "t_final": row["t_final"] + off,
                    "n_rhs": row["n_rhs"] + rhs0, "energy_at_switch": row["energy_initial"], "energy_initial": e0})
    row["load"] = os.getloadavg()[0]
    db = load(path)
    db[kk] = row
    write_atomic(path, lambda tmp: Path(tmp).write_text(json.dumps(db, indent=1)), name="bending_rise results")
    print(f"{kk}: v_peak={row['v_peak']:.5g} N={row['N']} rhs={row['n_rhs']} cpu={cpu:.1f}s "
          f"load={row['load']:.1f}", flush=True)
    return row


def _nan(d, k):
    return d.get(k, float("nan"))


def table(path):
    db = load(path)
    print(f"machine: {platform.node()} {platform.machine()} {os.cpu_count()} cpus; CPU seconds by time.process_time "
          f"(the machine shared; the first run's includes loading the compiled kernels)")
    cells = sorted({tuple(x.split()[:3]) for x in db}, key=lambda c: (float(c[0]), float(c[1]), int(c[2])))
    for c in cells:
        chi, beta, k = float(c[0]), float(c[1]), int(c[2])
        got = [x.split()[3] for x in db if tuple(x.split()[:3]) == c]
        order = [v for v in VARIANTS if v in got] + sorted(v for v in got if v not in VARIANTS)
        rows = {v: db[key(chi, beta, k, v)] for v in order}
        ide = rows.get("ideal")
        n = next(iter(rows.values()))["N"]
        print(f"\nchi={chi:g} beta={beta:g} level k={k} (frac {level(k)['frac']:g}), N={n} links (every variant on "
              f"these links); ratio: v_peak over the ideal's")
        print(f"  {'variant':10} {'v_peak':>7} {'ratio':>6} {'t*':>10} {'closure':>7} {'E chk':>7} {'diss@pk':>7} "
              f"{'Eb max':>7} {'Eb@pk':>7} {'p(-2,-3)':>8} {'p(-3,-4)':>8} {'k(1e-3)':>7} {'k(1e-4)':>7} {'delta':>8} "
              f"{'v_delta':>7} {'R/l_B':>5} {'t_final':>9} {'rhs':>6} {'cpu s':>5}")
        for v, r in rows.items():
            fo = r["fold"]
            ratio = r["v_peak"] / ide["v_peak"] if ide else float("nan")
            rlb = fo["fold_radius"] / fo["l_B_at_delta"] if "l_B_at_delta" in fo else float("nan")
            print(f"  {v:10} {r['v_peak']:7.4g} {ratio:6.3f} {r['t_snap_v']:10.7f} {r['closure']:7.0e} "
                  f"{r['energy_check']:7.0e} {r['dissipated_at_peak']:7.1e} {r.get('Eb_max', 0.0):7.1e} "
                  f"{r.get('Eb_at_peak', 0.0):7.1e} {fo['kappa_exponent'][0]:8.3f} {fo['kappa_exponent'][1]:8.3f} "
                  f"{fo['kappa_at']['0.001']:7.0f} {fo['kappa_at']['0.0001']:7.0f} {_nan(fo, 'delta'):8.2e} "
                  f"{_nan(fo, 'v_delta'):7.4g} {rlb:5.1f} {r['t_final']:9.6f} {r['n_rhs']:6d} {r['cpu']:5.1f}")
        if not ide:
            continue
        pi = ide["peak"]
        print("  speed budget at the peak, v_peak^2 = (2 K_half / m_half) / shape over the piece out to r_half (speed "
              "> v_peak / 2); factors of v_peak over the ideal's: energy sqrt(K_half / K_half_ideal), length "
              "sqrt(m_half_ideal / m_half), shape sqrt(shape_ideal / shape); kinetic energy within r of the free end "
              f"(fraction of all); the tip over t* - t <= {TIP_WINDOW:g}: ve/vm min of v_end / v_max, dip the largest "
              f"fall of v_end below its running maximum (/ v_peak), inside the time fraction with the fastest point "
              f"not at the free end, turn the largest total turning (rad) within {TIP_R:g} of the free end")
        print(f"  {'variant':10} {'r_half':>8} {'links':>5} {'K_half':>7} {'shape':>6} {'energy':>6} {'length':>6} "
              f"{'shape':>6} {'product':>7} " + " ".join(f"{'K<' + format(x, 'g'):>7}" for x in RADII)
              + f" {'kappa@pk':>8} {'at r':>8} {'ve/vm':>6} {'dip':>6} {'inside':>6} {'turn':>6}")
        for v, r in rows.items():
            pk = r["peak"]
            fe, fl = math.sqrt(pk["K_half"] / pi["K_half"]), math.sqrt(pi["m_half"] / pk["m_half"])
            fs = math.sqrt(pi["shape"] / pk["shape"])
            print(f"  {v:10} {pk['r_half']:8.2e} {pk['n_half']:5d} {pk['K_half']:7.4f} {pk['shape']:6.3f} {fe:6.3f} "
                  f"{fl:6.3f} {fs:6.3f} {fe * fl * fs:7.3f} "
                  + " ".join(f"{pk['K_within'][format(x, 'g')] / pk['K']:7.3f}" for x in RADII)
                  + f" {pk['kappa']:8.0f} {pk['r_kappa']:8.1e} {r['tip']['v_end_over_v_max_min']:6.3f} "
                  f"{r['tip']['v_end_dip']:6.3f} {r['tip']['inside_fraction']:6.3f} {r['tip']['tip_turning_max']:6.2f}")
        b = rows.get("bent")
        if b:
            pb = b["peak"]
            print(f"  bent / ideal: v_peak x{b['v_peak'] / ide['v_peak']:.3f}; the paper's estimate from the fold, "
                  f"sqrt(delta_ideal / delta_bent), x{_nan(b['fold'], 'v_delta') / _nan(ide['fold'], 'v_delta'):.3f} "
                  f"(delta {_nan(b['fold'], 'delta'):.2e} against {_nan(ide['fold'], 'delta'):.2e}); t* earlier by "
                  f"{ide['t_snap_v'] - b['t_snap_v']:.2e}; the fast piece's kinetic energy {pb['K_half']:.4f} against "
                  f"the ideal's {pi['K_half']:.4f}: excess {pb['K_half'] - pi['K_half']:+.4f}, the bent line's "
                  f"largest bending energy {b['Eb_max']:.2e}; kinetic energy at the peak {pb['K']:.4f} against "
                  f"{pi['K']:.4f} (released P {b['energy_initial']:.5f}, {ide['energy_initial']:.5f}; dissipated "
                  f"by the grid damping by the peak {b['dissipated_at_peak']:.1e})")


SHAPES = os.path.join(HERE, "results", "bending_rise_shapes.json")
#: t* - t of the tip shapes drawn (besides the peak)
SHAPE_TIMES = (1e-3, 2.5e-4, 1.2e-4, 6e-5, 3e-5, 1.5e-5, 5e-6)


def tip_shapes(chi, beta, k, path, out=SHAPES, reach=1e-3):
    """The line within ``reach`` of the free end at t* - SHAPE_TIMES and at the peak, ideal and bent (each run
    again with these snapshots, its t* from ``path``), for the figure; kept in ``out``."""
    from snapping.simulate import run

    db, shp = load(path), load(out)
    for v in ("ideal", "bent"):
        kk = key(chi, beta, k, v)
        if kk in shp or kk not in db:
            continue
        prob, method, tol = problems(chi, beta, k, v)
        ts = db[kk]["t_snap_v"]
        ds = run(prob, method=method, tol=tol, snapshot_times=[ts - x for x in SHAPE_TIMES], progress=False).dataset
        if abs(float(ds.attrs["t_snap_v"]) - ts) > 1e-12:
            raise RuntimeError(f"{kk}: the rerun's t* {ds.attrs['t_snap_v']!r} is not the stored {ts!r}")
        r = np.concatenate([[0.0], np.cumsum(ds.link_length.values)])
        sel = r <= reach
        kinds = [str(x) for x in ds.snapshot_kind.values]
        rows = []
        for j, kind in enumerate(kinds):
            if kind not in ("requested", "peak"):
                continue
            sn = ds.isel(snapshot=j)
            x, y = sn.x.values[sel] - float(sn.x.values[0]), sn.y.values[sel] - float(sn.y.values[0])
            rows.append({"tstar_minus_t": ts - float(sn.t_snapshot), "kind": kind,
                         "v_end": float(np.hypot(sn.vx.values[0], sn.vy.values[0])),
                         "x": [float(f"{q:.4g}") for q in x], "y": [float(f"{q:.4g}") for q in y]})
        shp = load(out)
        shp[kk] = rows
        json.dump(shp, open(out, "w"))
        print(f"tip shapes: {kk}", flush=True)
    return load(out)


def figure(path, out, cells, shape_cell):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    db = load(path)
    shp = tip_shapes(*shape_cell, path)
    fig = plt.figure(figsize=(13, 7))
    gs = fig.add_gridspec(2, 8, height_ratios=[1.6, 1])
    ax = [fig.add_subplot(gs[0, 0:4]), fig.add_subplot(gs[0, 4:8])]
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for ci, (chi, beta, k) in enumerate(cells):
        for v, ls in (("ideal", "-"), ("bent", "--")):
            r = db.get(key(chi, beta, k, v))
            if r is None:
                continue
            h = r["history"]
            c = colors[ci % len(colors)]
            lab = f"chi={chi:g}, {r['N']} links, " + ("ideal" if v == "ideal" else f"beta={beta:g}")
            ax[0].loglog(h["tstar_minus_t"], h["kappa_max"], ls, color=c, label=lab)
            ax[1].loglog(h["tstar_minus_t"], h["v_end"], ls, color=c, label=lab)
    ax[0].set_ylabel("kappa_max (the fold's curvature)")
    ax[1].set_ylabel("v_end (the free end's speed)")
    for a in ax:
        a.set_xlabel("t* - t (each run's own t*)")
        a.set_xlim(0.3, 1e-6)
        a.grid(True, which="both", alpha=0.3)
    ax[0].legend(fontsize=7)
    ax[0].set_title("bent (dashed) against ideal (solid), same links", fontsize=9)
    ax[1].set_title("the bent line's free end slows, then cracks", fontsize=9)
    ki, kb = key(*shape_cell, "ideal"), key(*shape_cell, "bent")
    if ki in shp and kb in shp:
        n = min(len(shp[ki]), len(shp[kb]), 8)
        w = 4e-4
        for j in range(n):
            a = fig.add_subplot(gs[1, j])
            for v, kk, lw, c in (("ideal", ki, 1.0, "0.5"), ("bent", kb, 1.6, colors[3])):
                sn = shp[kk][j]
                a.plot(sn["x"], sn["y"], "-", lw=lw, color=c)
            a.plot(0, 0, "ko", ms=3)
            a.set_xlim(-w, w)
            a.set_ylim(w, -w)
            a.set_aspect("equal")
            a.set_xticks([])
            a.set_yticks([])
            a.set_title(("peak" if shp[kb][j]["kind"] == "peak" else f"t*-t={shp[kb][j]['tstar_minus_t']:.2g}")
                        + f"\nv_end {shp[ki][j]['v_end']:.3g} / {shp[kb][j]['v_end']:.3g}", fontsize=7)
        fig.text(0.5, 0.005, f"the line near its free end (black dot; boxes {2 * w:g} wide), chi={shape_cell[0]:g}, "
                 f"beta={shape_cell[1]:g}, level {shape_cell[2]}: grey ideal, red bent (v_end ideal / bent)", ha="center",
                 fontsize=8)
    fig.tight_layout(rect=(0, 0.02, 1, 1))
    fig.savefig(out, dpi=100)
    print(f"figure: {out}")


FOLDS = os.path.join(HERE, "results", "bending_rise_folds.json")


def fold_profiles(chi, beta, k, path, out=FOLDS, variants=("ideal", "bent-cat", "bent"), n=12):
    """The fold through the fall, from snapshots at t = 0 and t_ideal* - t log-spaced from t* to 1e-4 (each variant
    run again with them): the curvature maximum and where, the fold's turning Theta (the line's turning
    from the free end out to three times the fold's distance), its width W (the arclength over which the
    turning goes from 10% to 90% of Theta), the tension there, the bending length sqrt(beta / T) and
    l_B kappa_max. Kept in ``out``; printed."""
    from snapping.simulate import run

    db, res = load(path), load(out)
    ts = db[key(chi, beta, k, "ideal")]["t_snap_v"] if key(chi, beta, k, "ideal") in db else 1.1935
    times = ts - np.logspace(math.log10(ts), -4, n + 1)[1:]
    for v in variants:
        kk = key(chi, beta, k, v)
        if kk in res:
            continue
        prob, method, tol = problems(chi, beta, k, v)
        cpu = time.process_time()
        ds = run(prob, method=method, tol=tol, snapshot_times=times, progress=False).dataset
        cpu = time.process_time() - cpu
        h = ds.link_length.values
        r = np.concatenate([[0.0], np.cumsum(h)])
        rl = 0.5 * (r[:-1] + r[1:])  # link midpoints' distance from the free end
        rows = []
        for j, kind in enumerate(str(x) for x in ds.snapshot_kind.values):
            if kind not in ("initial", "requested"):
                continue
            sn = ds.isel(snapshot=j)
            th = np.unwrap(np.arctan2(np.diff(sn.y.values), np.diff(sn.x.values)))
            kap = np.abs(sn.curvature.values)
            i = int(np.nanargmax(kap))
            turn = np.abs(th - th[0])
            theta = float(turn[min(int(np.searchsorted(rl, min(3 * r[i], 0.9))), turn.size - 1)])
            w = float(rl[np.argmax(turn >= 0.9 * theta)] - rl[np.argmax(turn >= 0.1 * theta)])
            T = float(sn.tension.values[min(i, h.size - 1)])
            lb = math.sqrt(beta / T) if T > 0 else float("nan")
            rows.append({"t": float(sn.t_snapshot), "kappa": float(kap[i]), "r_kappa": float(r[i]), "theta": theta,
                         "width": w, "T": T, "l_B": lb})
        res = load(out)
        res[kk] = {"rows": rows, "cpu": cpu, "n_rhs": int(ds.attrs["n_rhs"]), "N": int(ds.attrs["N"])}
        json.dump(res, open(out, "w"), indent=1)
    print(f"\nthe fold through the fall, chi={chi:g} beta={beta:g} level k={k}: kappa_max, its distance r from the free "
          f"end, the fold's turning Theta and width W (10-90% of Theta), the tension T there, l_B = sqrt(beta/T)")
    for v in variants:
        e = res.get(key(chi, beta, k, v))
        if e is None:
            continue
        print(f"  {v} ({e['N']} links, {e['n_rhs']} evaluations, {e['cpu']:.1f} s CPU)")
        print(f"    {'t':>7} {'t*-t':>8} {'kappa':>8} {'r':>9} {'Theta':>6} {'W':>9} {'T':>7} {'l_B':>8} {'l_B kappa':>9}")
        for q in e["rows"]:
            print(f"    {q['t']:7.4f} {ts - q['t']:8.2e} {q['kappa']:8.1f} {q['r_kappa']:9.3e} {q['theta']:6.3f} "
                  f"{q['width']:9.3e} {q['T']:7.3g} {q['l_B']:8.2e} {q['l_B'] * q['kappa']:9.3f}")


#: the default set: the rise's cell at two levels (the second resolves the bending length at the fold),
#: every variant on the coarser, bending confined in space (tipX, outX) and in time (ib@T, bi@T); the
#: other betas and the controls chi = 0.3 and 0.5
LOCAL = ("tip0.01", "tip0.1", "out0.01", "out0.1", "out0.3", "bi@0.5", "ib@0.5", "bi@1.1", "ib@1.1")
DEFAULT = ([(0.1, 7.2e-8, 0, VARIANTS + LOCAL),
            (0.1, 7.2e-8, 2, ("ideal", "bent", "bent-cat", "damp-only", "tip0.1", "out0.3", "bi@0.5")),
            (0.1, 1e-8, 0, ("ideal", "bent")), (0.1, 5.18e-7, 0, ("ideal", "bent")),
            (0.1, 3.73e-6, 0, ("ideal", "bent")),
            (0.3, 5.18e-7, 0, ("ideal", "bent")), (0.5, 5.18e-7, 0, ("ideal", "bent"))])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--chi", type=float, nargs="*", default=[])
    ap.add_argument("--beta", type=float, nargs="*", default=[])
    ap.add_argument("--k", type=int, nargs="*", default=[], help="fold levels: frac = 0.04 * 2**-k (the study's)")
    ap.add_argument("--variants", nargs="*", default=["ideal", "bent"],
                    help=f"of {', '.join(VARIANTS)}; tipX / outX for any X")
    ap.add_argument("--out", default=OUT)
    ap.add_argument("--table", action="store_true", help="only print what is done")
    ap.add_argument("--figure", default=None, help="draw the fold's curvature and v_end against t* - t, and the tip")
    ap.add_argument("--fold-profile", action="store_true",
                    help="the fold through the fall (ideal, bent-cat, bent) at chi=0.1 beta=7.2e-8 level 2, or at the "
                         "one --chi, --beta, --k given")
    a = ap.parse_args(argv)
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    if a.fold_profile:
        cell = (a.chi[0], a.beta[0], a.k[0]) if a.chi else (0.1, 7.2e-8, 2)
        fold_profiles(*cell, a.out)
        return
    todo = [(c, b, k, tuple(a.variants)) for k in a.k for c in a.chi for b in a.beta] if a.chi else \
        ([] if a.table else DEFAULT)
    for chi, beta, k, vs in todo:
        for v in vs:
            run_one(chi, beta, k, v, a.out)
    table(a.out)
    if a.figure:
        figure(a.out, a.figure, [(0.1, 7.2e-8, 0), (0.1, 7.2e-8, 2), (0.3, 5.18e-7, 0)], (0.1, 7.2e-8, 2))


if __name__ == "__main__":
    main()
