"""The cost of a design answer for a real line (issue 24's target: at most 10 s of CPU for
100-1000 links, the peaks to 1%), and what the graded links and the stiff runs' rule change.

For every catalogue line and each N: :func:`snapping.caps.cap` (chi 0.25, the N/2 check, each
mechanism alone) twice:

* **before** (``--before uniform``, the default): ``graded=False`` -- every run on N uniform links,
  the answers as they were made before the graded links (:func:`snapping.caps_runs.grading_rule`);
  ``--before undamped``: also ``damping=0``, every run by the fast method (DOP853, tol 1e-6),
  undamped: the answers as they were before the stiff runs' rule (DOP853 at 1e-6 is within 1e-6 of
  DOP853 at 1e-8 in these peaks);
* **after**: the default -- graded links where the rule takes them (the nylon line), the runs whose
  bending waves would hold DOP853 to more than ``STIFF_RATIO`` times its accuracy-limited steps by
  RODAS4 at ``STIFF_TOL`` with those waves grid-damped, the others as before (bit for bit).

It prints, per line and N: CPU seconds and right-hand-side evaluations of each answer, the real
answer's tension of each and the largest relative difference of its peaks, the largest
difference over every run of the answer (ideal, full, each alone), the capping mechanism of
each, the graded levels (links) and the answer's error estimate where graded, and which runs
RODAS4 took; for the nylon line the full run's tension against its converged value
(``NYLON_T``: levels of 535, 1054 and 2091 graded links by DOP853, tol 1e-6, undamped, order 2.0).
``--after-only`` skips the before answers. ``--order LINE`` instead runs LINE's full model on
graded levels 0, 1, 2 (:meth:`snapping.caps_runs.Runs.graded`) and prints the observed order of
each peak and the extrapolations from levels 0-1 and 1-2 (``--levels a b c``: other levels).
``--escalation LINE ...`` runs the answer of each LINE at ``--chi`` on ``--N[0]`` links and, where
graded, prints every level :func:`snapping.caps_runs.graded_levels` ran, the pair it extrapolated,
why it stopped, the graded runs' CPU, and beside it the levels-0-1 answer (before the escalation).
``--profile LINE`` (``design10``) runs LINE's full model on the graded ``--levels`` at each ``--tols``
(RODAS4's tolerance; default :data:`snapping.caps_runs.GRADED_TOL`) and prints, per run, its links,
CPU, steps, rejected steps, evaluations and CPU per step attempt per link, its peaks and their change
from the first tolerance; then the first run's steps by time, the fold's smallest radius along its
path on the first run (from the per-step curvature peak and where it is) beside the grading's links
there, and the cost of one step's parts on the last level (the right side, the Jacobian, the banded
LU, a stage's solve).

Usage::

    python benchmarks/bench_caps.py                      # N = 100 200 400 1000, every line
    python benchmarks/bench_caps.py --N 1000 --lines bullwhip nylon-monofilament
    python benchmarks/bench_caps.py --escalation nylon-monofilament fly-line --chi 0.1 --N 200
    python benchmarks/bench_caps.py --answers ball-chain fly-line --chis 0.1 0.25 --N 200
    python benchmarks/bench_caps.py --answers climbing-rope bungee-cord --chis 0.1 0.25 --default-N   # caps.cap's N=None
    python benchmarks/bench_caps.py --order nylon-monofilament --chi 0.1 --levels 1 2 3
    python benchmarks/bench_caps.py --profile nylon-monofilament --chi 0.1 --levels 0 1 2 --tols 1e-3 3e-3 1e-2
"""

from __future__ import annotations

import argparse
import os

from snapping import caps, lines

#: the nylon line's converged peak tension at chi 0.25 (N), its error bar, and speed (m/s)
NYLON_T, NYLON_T_ERR, NYLON_V = 0.009656, 0.000016, 21.568


def _peaks(r: dict) -> dict:
    """Every run's peaks of an answer: (what, quantity) -> SI value."""
    out = {("real", q): v for q, v in r["real"].items()}
    for m, pk in r["alone"].items():
        out.update({(m, q): v for q, v in pk.items()})
    return out


def _graded(r: dict) -> str:
    g = r["graded"]
    if not g.get("used"):
        return "-"
    pair = "/".join(str(g["levels"][k]) for k in g["pair"])
    return (f"{'/'.join(map(str, g['levels']))}: {pair} (T +- {g['relative_error']['sigma_peak']:.2%}, "
            f"stopped: {g['stopped']})")


def _order(name: str, chi: float, levels=(0, 1, 2)) -> int:
    """Three graded levels of the full model (``levels``, default 0, 1, 2): observed order,
    extrapolations of the first two and of the last two."""
    from snapping import caps_runs

    sp = caps.spec(name)
    runs = caps_runs.Runs(sp, chi, 1e-6, caps_runs.STIFF_TOL, caps_runs.GRID_DAMPING)
    on = tuple(m for m in caps.MECHANISMS[:-1] if sp.has(m))
    lv = [runs.graded(on, k) for k in levels]
    si = [caps._si(sp, x) for x in lv]
    print(f"{name}, chi = {chi:g}: graded levels {[x['links'] for x in lv]} links, evaluations "
          f"{[x['n_rhs'] for x in lv]}, CPU s {[round(x['cpu'], 2) for x in lv]}; load {os.getloadavg()[0]:.1f}")
    for q in caps.QUANTITIES:
        v = [x[q] for x in si]
        p_obs = caps_runs.observed_order(*v)
        e01, e12 = caps_runs.richardson(v[0], v[1]), caps_runs.richardson(v[1], v[2])
        a, b, c = levels
        print(f"  {q}: levels {v[0]:.6g}, {v[1]:.6g}, {v[2]:.6g}; observed order {p_obs:.2f}; extrapolated "
              f"{a}-{b} {e01[0]:.6g} +- {e01[1]:.2g}, {b}-{c} {e12[0]:.6g} +- {e12[1]:.2g}")
    if name == "nylon-monofilament":
        print(f"  converged (DOP853, undamped, 535/1054/2091 links): T {NYLON_T} +- {NYLON_T_ERR} N, v {NYLON_V} m/s")
    return 0


def _profile(name: str, chi: float, levels, tols) -> int:
    """Where a graded answer's time goes: each level at each tolerance (steps, rejections, CPU per
    step attempt per link, peaks), the fold's radius along its path, and one step's parts."""
    import time

    import numpy as np

    from snapping import caps_runs
    from snapping.simulate import run

    sp = caps.spec(name)
    on = tuple(m for m in caps.MECHANISMS[:-1] if sp.has(m))
    lb = caps_runs.bending_length(sp)
    caps.cap("nylon-monofilament", chi, N=8, check=False, alone=False, graded=False)  # compile
    print(f"{name}, chi = {chi:g}, bending length {lb:.4g} L; load {os.getloadavg()[0]:.1f}")
    print("| level | links | tol | CPU s | steps | rejected | evaluations | CPU us per attempt per link | T (N) | "
          "v (m/s) | a (m/s^2) | T, v, a from the first tol |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    first, last = None, None
    for k in levels:
        h = caps_runs.graded_h(chi, lb, k)
        p = caps_runs.problem(sp, chi, h.size, on, damping=caps_runs.GRADED_DAMPING, omega_min=0.0, h=h)
        base = None
        for tol in tols:
            c0 = time.process_time()
            ds = run(p, method="rodas4", tol=tol, progress=False).dataset
            cpu = time.process_time() - c0
            at = ds.attrs
            si = caps._si(sp, {q: float(at[q]) for q in caps.QUANTITIES})
            base = base or si
            d = ", ".join(f"{si[q] / base[q] - 1.0:+.2%}" for q in ("sigma_peak", "v_peak", "a_peak"))
            tries = int(at["n_steps"]) + int(at["n_rejected"])
            print(f"| {k} | {h.size} | {tol:g} | {cpu:.2f} | {at['n_steps']} | {at['n_rejected']} | {at['n_rhs']} | "
                  f"{cpu / tries / h.size * 1e6:.2f} | {si['sigma_peak']:.6g} | {si['v_peak']:.5g} | "
                  f"{si['a_peak']:.5g} | {d} |", flush=True)
            first = first or (h, ds)
        last = p
    h, ds = first
    t = ds["t"].values
    edges = [0.0, 0.3, 0.6, 0.9, 1.2, 1.3, float(t[-1])]
    print(f"\nsteps of level {levels[0]}, tol {tols[0]:g}, by time: " + ", ".join(
        f"{a:g}-{b:.3g}: {int(((t > a) & (t <= b)).sum())}" for a, b in zip(edges[:-1], edges[1:])))
    s_k, k_max = ds["s_kappa_max"].values, ds["kappa_max"].values
    xs = np.cumsum(h) - 0.5 * h
    print(f"\nthe fold along its path (level {levels[0]}, tol {tols[0]:g}): x from the free end, its smallest radius, "
          f"the link there, in bending lengths")
    for x in (0.5, 0.4, 0.3, 0.2, 0.15, 0.1, 0.05, 0.02, 0.01):
        m = np.abs((1.0 - s_k) - x) < 0.1 * x
        if m.any():
            print(f"  x {x:g}: radius {1.0 / k_max[m].max() / lb:.2f} l_b, link {np.interp(x, xs, h) / lb:.2f} l_b")
    print(f"\none step's parts on {last.N} links (us): " + _step_parts(last) + f"; load {os.getloadavg()[0]:.1f}")
    return 0


def _step_parts(p, n: int = 200) -> str:
    """The cost of one RODAS4 step's parts on problem ``p`` (at its start): the right side (a step makes
    six: five stages and the new f; before ``dragexact``, with drag, ~12: a difference along each stage
    for the dissipation row), the drag power's gradient (once per attempt, with drag), the Jacobian, the
    banded LU, a stage's solve (six per step)."""
    import time

    import numpy as np

    from snapping.simulate import forced as FR, models as MD, rosenbrock as RB
    from snapping.simulate.banded import KL, KU
    from snapping.simulate.methods import rodas4 as M4

    y0 = p.initial_angles()
    e = M4.Engine(y0, 0.0, mdl=p.model(), tol=1e-3, dt0=None, t_end=2.0, stop_fraction=0.0, thin=0.0,
                  max_link_error=0.5, snapshot_times=())
    N, w, f = e.N, e.w, np.empty_like(y0)
    b, U = np.linspace(0.0, 1.0, y0.size), np.zeros_like(y0)
    parts = {"rhs": lambda: MD.model_rhs(N, 0.1, y0, f, w.c, w.s, w.S, w.cp, w.dp, w.sig, e.mdl),
             "drag gradient": lambda: FR.drag_power_gradient(N, 0.1, y0, w.c, w.s, e.mdl[0], e.mdl[1], e.mdl[5],
                                                             np.empty(2 * N)),
             "jacobian": lambda: RB.jacobian_at(N, 0.1, y0, f, w.sig, e.Dj, e.mdl, e.barr, e.rp),
             "LU": lambda: (RB.assemble(N, e.Dj, 2.5e-4, e.ab), RB.band_lu(e.ab, 2 * N, KL, KU, e.piv)),
             "stage solve": lambda: RB._stage_solve(N, e.Dj, 2.5e-4, e.ab, e.piv, b.copy(), U, e.rhs, e.tmp)}
    out = []
    for name, fn in parts.items():
        fn()  # (compiled, warm)
        c0 = time.process_time()
        for _ in range(n):
            fn()
        out.append(f"{name} {(time.process_time() - c0) / n * 1e6:.0f}")
    return ", ".join(out)


def _escalation(names, chi: float, N: int) -> int:
    """The escalated graded answers (:func:`snapping.caps_runs.graded_levels`) against levels 0-1 alone."""
    from snapping import caps_runs

    caps.cap("nylon-monofilament", chi, N=8, check=False, alone=False, graded=False)  # compile
    for name in names:
        r = caps.cap(name, chi, N=N, check=False)
        g = r["graded"]
        if not g.get("used"):
            print(f"{name}, chi = {chi:g}, N = {N}: not graded ({g.get('why')}); T {r['real']['sigma_peak']:.5g} N")
            continue
        lp = g["levels_peaks"]
        cpu = [x["cpu"] for x in r["runs"] if "graded" in x["run"]]
        print(f"{name}, chi = {chi:g}, N = {N}: levels {g['levels']} links, graded CPU s "
              f"{[round(c, 1) for c in cpu]}; answer CPU {r['cpu']:.1f} s, wall {r['wall']:.1f} s; "
              f"load {os.getloadavg()[0]:.1f}")
        for q in caps.QUANTITIES:
            b = caps_runs.richardson(lp[0][q], lp[1][q])
            obs = g["observed_order"][q] if g["observed_order"] else float("nan")
            print(f"  {q}: levels {', '.join(f'{x[q]:.6g}' for x in lp)}; before (0-1) {b[0]:.6g} +- "
                  f"{b[1] / abs(b[0]):.2%}; after {g['pair']} {r['full'][q]:.6g} +- {g['relative_error'][q]:.2%}"
                  f"; observed order {obs:.2f}")
        print(f"  stopped: {g['stopped']} ({g['stop_why']}); real T {r['real']['sigma_peak']:.6g} N, cap {r['cap']}")
    return 0


def _answers(names, chis, N) -> int:
    """Each line's design answer (``caps.cap(name, chi, N=N)``, the defaults) at each chi: a markdown table of
    its wall and CPU seconds (the machine's load beside them), the links of each graded level (or the uniform
    N), each peak's error bar (graded: the escalation's estimate; uniform: the change N/2 -> N), the capping
    mechanism and the peak tension in newtons, ideal and real."""
    caps.cap("bungee-cord", 0.25, N=12)  # compile the kernels (both methods)
    caps.cap("nylon-monofilament", 0.1, N=8, check=False, alone=False, graded=False)
    print("| line | chi | wall s | CPU s | load | links | error bar v, a, T | within 1% | cap | T ideal (N) | "
          "T real (N) | factor | evaluations | ideal: its error (T), on uniform links (N) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for chi in chis:
        for name in names:
            load = os.getloadavg()[0]
            r = caps.cap(name, chi, N=N)
            g = r["graded"]
            if g.get("used"):
                links = "/".join(map(str, g["levels"])) + f" (graded; {g['stopped']})"
                err = [g["relative_error"][q] for q in caps.QUANTITIES]
            else:
                links = f"{r['N']} uniform" + (f" (auto: {'/'.join(map(str, r['auto_N']))})" if r.get("auto_N") else "")
                err = [abs(r["resolution"][q]) for q in caps.QUANTITIES] if r["resolution"] else [float("nan")] * 3
            own = (r.get("own_links") or {}).get("used")
            if own:
                links = f"{r['N']} own (a chain of discrete links)"
            st = r["stretching"]
            if st.get("run") and not all(st["resolved"].values()):
                links += "; stretching factor not resolved: " + ", ".join(q for q, ok in st["resolved"].items()
                                                                          if not ok)
            print(f"| {name} | {chi:g} | {r['wall']:.1f} | {r['cpu']:.1f} | {load:.1f}-{os.getloadavg()[0]:.1f} | "
                  f"{links} | {', '.join(f'{e:.2%}' for e in err)} | {'own links' if own else 'yes' if max(err) <= 0.01 else 'NO'} | "
                  f"{r['cap']} | {r['ideal']['sigma_peak']:.4g} | {r['real']['sigma_peak']:.4g} | "
                  f"{r['factor']['sigma_peak']:.3f} | {r['n_rhs']} | " + _ideal_on(r) + " |", flush=True)
    return 0


def _ideal_on(r: dict) -> str:
    """Where the ideal beside an answer ran: on its graded links (its own error on T, its run on the answer's
    uniform links beside) or on the answer's links."""
    io = r.get("ideal_on")
    if not io:
        return "on the answer's links"
    return (f"{io['what']} {'/'.join(map(str, io['links']))}: +-{io['relative_error']['sigma_peak']:.2%}; "
            f"{io['uniform']['sigma_peak']:.4g} on {io['N']}")


def _graded_tol() -> float:
    from snapping import caps_runs

    return caps_runs.GRADED_TOL


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--N", nargs="+", type=int, default=[100, 200, 400, 1000])
    p.add_argument("--lines", nargs="+", default=lines.names(), choices=lines.names())
    p.add_argument("--chi", type=float, default=0.25)
    p.add_argument("--after-only", action="store_true")
    p.add_argument("--before", choices=("uniform", "undamped"), default="uniform")
    p.add_argument("--order", choices=lines.names(), help="verify the graded levels' order on this line")
    p.add_argument("--levels", nargs="+", type=int, default=[0, 1, 2],
                   help="the graded levels of --order (three) or --profile")
    p.add_argument("--profile", choices=lines.names(),
                   help="where this line's graded runs' time goes (--levels, --tols)")
    p.add_argument("--tols", nargs="+", type=float, default=None, help="RODAS4's tolerances of --profile")
    p.add_argument("--drag-jacobian", choices=("banded", "correct"), default=None,
                   help="the graded runs' stage solves on lines with drag (caps_runs.GRADED_DRAG_JACOBIAN)")
    p.add_argument("--escalation", nargs="+", choices=lines.names(),
                   help="the escalated graded answer of these lines at --chi on --N[0] links: each level, the "
                        "pair extrapolated, why it stopped, CPU; beside it the levels-0-1 answer (before)")
    p.add_argument("--answers", nargs="+", choices=lines.names(),
                   help="the design answer of each of these lines (caps.cap defaults) at each --chis on --N[0] links: "
                        "wall and CPU s, links, each peak's error bar, the capping mechanism, T ideal and real")
    p.add_argument("--chis", nargs="+", type=float, default=[0.1], help="the separations of --answers")
    p.add_argument("--auto", action="store_true", help="--answers with N='auto' (links doubled from 100 until the "
                                                        "tension moves by <= 1%%), not --N")
    p.add_argument("--default-N", action="store_true", help="--answers with caps.cap's default links (N=None), not --N")
    a = p.parse_args(argv)
    if a.answers:
        return _answers(a.answers, a.chis, "auto" if a.auto else None if a.default_N else a.N[0])
    if a.profile:
        return _profile(a.profile, a.chi, a.levels, a.tols or [_graded_tol()])
    if a.order:
        if len(a.levels) != 3:
            p.error("--order takes three --levels")
        return _order(a.order, a.chi, tuple(a.levels))
    if a.drag_jacobian:
        from snapping import caps_runs

        caps_runs.GRADED_DRAG_JACOBIAN = a.drag_jacobian
    if a.escalation:
        return _escalation(a.escalation, a.chi, a.N[0])
    before_kw = {"graded": False} if a.before == "uniform" else {"graded": False, "damping": 0.0}
    caps.cap("bungee-cord", a.chi, N=12)  # compile the kernels (both methods)
    caps.cap("bungee-cord", a.chi, N=12, damping=0.0)
    caps.cap("nylon-monofilament", a.chi, N=8, check=False, alone=False, graded=False)
    print(f"chi = {a.chi:g}; before = {before_kw}; load {os.getloadavg()[0]:.1f}\n")
    print("| line | N | CPU s before | CPU s after | evaluations before | evaluations after | T before (N) | "
          "T after (N) | v, a, T: largest change | every run: largest change | cap before / after | graded levels | "
          "RODAS4 runs |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for N in a.N:
        for name in a.lines:
            after = caps.cap(name, a.chi, N=N)
            stiff = [f"{x['run']}@{x['N']}" for x in after["runs"] if x["method"] == "rodas4"]
            note = ""
            if name == "nylon-monofilament":
                f = after["full"]
                note = (f"  (nylon: full run T {f['sigma_peak']:.6g} N, {f['sigma_peak'] / NYLON_T - 1:+.2%} from the "
                        f"converged {NYLON_T:g} +- {NYLON_T_ERR:g}; v {f['v_peak']:.5g} m/s, "
                        f"{f['v_peak'] / NYLON_V - 1:+.2%} from {NYLON_V:g}; load {os.getloadavg()[0]:.1f})")
            if a.after_only:
                print(f"| {name} | {N} | - | {after['cpu']:.2f} | - | {after['n_rhs']} | - | "
                      f"{after['real']['sigma_peak']:.5g} | - | - | {after['cap']} | {_graded(after)} | "
                      f"{', '.join(stiff) or '-'} |", flush=True)
            else:
                before = caps.cap(name, a.chi, N=N, **before_kw)
                pb, pa = _peaks(before), _peaks(after)
                real = max(abs(pa[("real", q)] / pb[("real", q)] - 1.0) for q in caps.QUANTITIES)
                every = max(abs(pa[k] / pb[k] - 1.0) for k in pb)
                print(f"| {name} | {N} | {before['cpu']:.2f} | {after['cpu']:.2f} | {before['n_rhs']} | "
                      f"{after['n_rhs']} | {before['real']['sigma_peak']:.5g} | {after['real']['sigma_peak']:.5g} | "
                      f"{real:.2%} | {every:.2%} | {before['cap']} / {after['cap']} | {_graded(after)} | "
                      f"{', '.join(stiff) or '-'} |", flush=True)
            if note:
                print(note, flush=True)
    print(f"\nload {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
