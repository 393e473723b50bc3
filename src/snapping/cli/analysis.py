"""The subcommands ``fit``, ``reproduce`` and ``animate``: the scaling analysis of run files,
the reproduction of the paper and the animation of a run."""

from __future__ import annotations

import sys

from ._common import (PLOT_BYTES, _add_si_options, _formatter, _print_si, _si_scales, _with_si, print_json,
                      print_table)


# ----------------------------------------------------------------------------- fit
def _add_fit(sub) -> None:
    p = sub.add_parser(
        "fit",
        help="snapping times, exponent fits with uncertainties, delta_kappa_m, Fig. 3 and Fig. 4",
        formatter_class=_formatter,
        description=(
            "Scaling analysis of run files: t*_chi from the peaks of v_max, a_max, sigma_max;\n"
            "exponents of y ~ A (t* - t)^beta (with t* = t*_chi and with t* fitted) against the\n"
            "folded-string -1/3, -4/3, -2/3 and the paper's -5/6, -1/6 (a_max: one fit, judged\n"
            "against -4/3 and -5/6), each with its uncertainty, window and a verdict in plain words\n"
            "(\"agrees with -1/3\", \"differs from -1/3 (z = -3.0)\", \"inconclusive: ...\"; z is\n"
            "(beta - ref) / uncertainty, agreement means |z| <= 2), also against the exact folded\n"
            "string on the same window; the scale delta_kappa_m and the whirling-rod predictions of\n"
            "delta_kappa0, delta_kappa_m, delta_c. Units: nondimensional (time sqrt(L/g)).\n"
            "Several files (or a sweep file) print one row per run; --plot then shows the collapse.\n"
            "--plot out.png also writes out_slopes.png (local slopes) and out_delta.png (Fig. 4)."
        ),
        epilog=(
            "examples:\n"
            "  snapping simulate --chi 0.25 --N 1000 -o run.nc     # a run to fit (~1 s)\n"
            "  snapping fit run.nc\n"
            "  snapping fit run.nc --json\n"
            "  snapping fit run.nc --length 1.022 --mass 0.0208   # snapping time, peaks, scales in SI too\n"
            "  snapping fit run.nc --window v_max=1e-3,3e-2 --plot fig3.png   # v_max: agrees with -1/3\n"
            "  snapping fit run_chi0.1.nc run_chi0.25.nc run_chi0.5.nc --plot collapse.pdf\n"
            "\n"
            "the uncertainty of an exponent (in quadrature, four parts):\n"
            "  least squares  the standard error of the slope on log-log axes in the window\n"
            "  window choice  how far the slope moves when either window end moves by a quarter of\n"
            "                 a decade (x 10^(+-1/4))\n"
            "  t* choice      how far it moves when t* moves by its own uncertainty (t* = t*_chi), or\n"
            "                 its profile interval (t* fitted)\n"
            "  slope drift    half the change of the local slope across the window: the data are\n"
            "                 not a pure power law by that much\n"
            "--json gives each part (beta_err_stat, beta_err_window, beta_err_t_star, beta_err_drift)."
        ),
    )
    p.add_argument("files", nargs="+", metavar="RUN.nc", help="run files or a sweep file")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--plot", metavar="PATH", default=None, help="write the figures (.png, .pdf or .svg)")
    p.add_argument("--overwrite", action="store_true", help="replace existing --plot files (default: refuse them)")
    p.add_argument("--tol", type=float, default=1e-3, help="flatness tolerance of the local slope (default 1e-3)")
    p.add_argument("--min-width", type=float, default=1.0, help="smallest fit window in decades (default 1)")
    p.add_argument(
        "--window", action="append", default=[], metavar="ROW=LO,HI",
        help="fix the window of t* - t of a variable or row, e.g. v_max=1e-4,1e-2 (repeatable)",
    )
    p.add_argument("--no-joint", action="store_true", help="skip the fits with t* fitted jointly")
    _add_si_options(p)
    p.set_defaults(func=_cmd_fit)


def _cmd_fit(args) -> int:
    from pathlib import Path

    from .. import scaling, units
    from .._validate import SnappingInputError

    scales = _si_scales(args)
    windows = {}
    for w in args.window:
        try:
            key, rng = w.split("=", 1)
            lo, hi = (float(v) for v in rng.split(","))
        except ValueError:
            raise SnappingInputError(f"--window={w!r} must look like NAME=LO,HI (e.g. v_max=1e-4,1e-2)") from None
        windows[key.strip()] = (lo, hi)
    if args.plot is not None:  # before the (slow) fits
        from .._files import figure_format
        from ..simulate.dataset import check_writable

        if Path(args.plot).suffix.lower() not in (".png", ".pdf", ".svg"):
            raise SnappingInputError(f"--plot={args.plot!r}: the figure suffix must be .png, .pdf or .svg")
        out = Path(args.plot)
        for path in (out, out.with_name(f"{out.stem}_slopes{out.suffix}"), out.with_name(f"{out.stem}_delta{out.suffix}")):
            figure_format(path, name="--plot")
            check_writable(path, name="--plot", overwrite=args.overwrite, need_bytes=PLOT_BYTES)
    runs, names = [], []
    for f in args.files:
        ds = scaling.load_run(f)
        for k, r in enumerate(scaling.iter_runs(ds)):
            runs.append(r)
            names.append(f if k == 0 else f"{f}[{k}]")
    if not runs:
        raise SnappingInputError(f"files={args.files!r} hold no runs")
    results = []
    for name, r in zip(names, runs):
        try:
            results.append(
                scaling.fit_run(r, joint=not args.no_joint, windows=windows, tol=args.tol, min_width=args.min_width)
            )
        except SnappingInputError as exc:
            raise SnappingInputError(f"{name}: {exc}") from None
    def run_line(ds) -> str:
        a = ds.attrs
        return (f"method {a.get('method', '?')}, chords {a.get('chords', '?')}, tol {a.get('tol', '?')};\n"
                f"  units: nondimensional (length L, mass M, time sqrt(L/g), force M g)")

    if args.json:
        if len(results) == 1:
            d = results[0].to_dict()
            print_json(_with_si(d, scales, lambda: {"values": units.fit_to_si(d, scales)}))
        else:
            ds_ = [r.to_dict() for r in results]
            print_json(_with_si({"runs": ds_}, scales, lambda: {"runs": [units.fit_to_si(d, scales) for d in ds_]}))
    elif len(results) == 1:
        print(f"{names[0]}: {run_line(runs[0])}\n")
        res = results[0]
        s = res.snap
        print_table(
            [(f"t* from {k}", p.t, f"± {p.err:.2g}  peak {p.value:.6g}") for k, p in s.peaks.items()]
            + [("t*_chi (mean)", s.t_star, f"± {s.t_star_err:.2g} (spread {s.spread:.2g})")],
            title=f"{names[0]}: chi = {res.chi:g}, N = {res.N}",
        )
        print()
        _print_exponents(scaling.report_rows(res))
        if res.delta is not None:
            d = res.delta
            print()
            print_table(scaling.delta_rows(d), title=f"Scales and whirling-rod peaks (eq. estimates), P = {d.P:.6g}")
            if d.note:
                print(f"  delta_kappa_m: {d.note}")
        print(f"\n  curvature amplification max kappa_max / kappa_max(0) = {res.kappa_amplification:.4g}")
        _print_si(scales, units.fit_rows(res.to_dict(), scales) if scales else [])
    else:
        for line in dict.fromkeys(run_line(r) for r in runs):  # (each distinct one once)
            print(f"runs: {line}")
        print()
        _print_columns(scaling.summary_rows(results), title="Exponents per run (t* = t*_chi)")
        if scales is None:
            _print_si(None, [])
        for name, res in zip(names, results):
            if scales is not None:
                _print_si(scales, [r for r in units.fit_rows(res.to_dict(), scales)
                                   if r[0] in ("t_star", "peak_v_max", "peak_a_max", "peak_sigma_max")], name)
    if args.plot is not None:
        out = Path(args.plot)
        paths = [
            scaling.plot_maxima(runs, results, out),
            scaling.plot_local_slopes(runs, results, out.with_name(f"{out.stem}_slopes{out.suffix}")),
            scaling.plot_delta(runs, results, out.with_name(f"{out.stem}_delta{out.suffix}")),
        ]
        if not args.json:
            print("\nfigures: " + ", ".join(str(p) for p in paths))
    return 0


def _print_columns(rows: list[tuple], title: str, keep: int = 2, width: int = 100) -> None:
    """A table (first row: the headers) in blocks of columns that fit ``width``, each block
    repeating the first ``keep`` columns (chi, N of a run)."""
    print(title)
    print("-" * len(title))
    rows = [tuple(str(c).strip() for c in r) for r in rows]
    w = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    blocks, cur = [], []
    base = 2 + sum(w[:keep]) + 2 * keep
    for i in range(keep, len(w)):
        if cur and base + sum(w[j] + 2 for j in cur) + w[i] > width:
            blocks.append(cur)
            cur = []
        cur.append(i)
    blocks.append(cur)
    for n, block in enumerate(blocks):
        if n:
            print()
        for r in rows:
            cells = [r[i].ljust(w[i]) for i in range(keep)] + [r[i].rjust(w[i]) for i in block]
            print(("  " + "  ".join(cells)).rstrip())


#: short headers of the exponent table's numeric columns (the text fits 100 columns)
_EXPONENT_HEADERS = ("quantity", "beta, t*=t*_chi", "ref", "ideal", "window of t*-t", "beta, t* fitted",
                     "A/A_ideal")


def _print_exponents(rows: list[tuple], width: int = 100) -> None:
    """The exponent table of one run (:func:`snapping.scaling.report_rows`) in ``width``
    columns: the numbers on one line per quantity, its verdict and notes wrapped below it."""
    import textwrap

    title = "Exponents y ~ A (t* - t)^beta"
    print(title)
    print("-" * len(title))
    body = [tuple(c.strip().replace(" ± ", " ±") for c in r) for r in rows[1:]]
    table = [_EXPONENT_HEADERS] + [r[:7] for r in body]
    w = [max(len(r[i]) for r in table) for i in range(7)]
    for k, r in enumerate(table):
        cells = [r[0].ljust(w[0])] + [c.rjust(w[i + 1]) for i, c in enumerate(r[1:])]
        print(("  " + "  ".join(cells)).rstrip())
        if k:
            words = "; ".join(c for c in body[k - 1][7:] if c)
            for line in textwrap.wrap(words, width=width - 6):
                print(f"      {line}")
    print("  (ideal: the exact folded string's exponent on the same window; z = (beta - ref) / uncertainty)")


# ---------------------------------------------------------------------------- plot
def _add_plot(sub) -> None:
    p = sub.add_parser(
        "plot",
        help="one run at a glance: shapes, speed and tension along the chain, maxima against time",
        formatter_class=_formatter,
        description=(
            "Draw one run file: (a) the chain's shapes at its snapshots up to the snap (the held end\n"
            "marked: it may move), (b) speed and (c) tension along the chain at the same snapshots,\n"
            "(d) the maxima over the chain against time, with the snapping time. Nondimensional.\n"
            "The exponent fits are `snapping fit RUN.nc --plot`; an animation `snapping animate`."
        ),
        epilog=(
            "examples (run.nc from e.g. snapping simulate --chi 0.25 --N 200 -o run.nc):\n"
            "  snapping plot run.nc -o run.png\n"
            "  snapping plot run.nc -o run.pdf --snapshots 5 --overwrite"
        ),
    )
    p.add_argument("file", metavar="RUN.nc", help="run file (snapping simulate -o)")
    p.add_argument("-o", "--output", required=True, metavar="PATH", help="figure file: .png, .pdf or .svg")
    p.add_argument("--snapshots", type=int, default=7, metavar="N",
                   help="at most N snapshots drawn, from t = 0 to the snap (default 7)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing output (default: refuse it)")
    p.set_defaults(func=_cmd_plot)


def _cmd_plot(args) -> int:
    from .. import figures
    from .._files import check_output, figure_format, save_figure
    from .._validate import SnappingInputError
    from ..simulate import load_run

    figure_format(args.output, name="--output")
    check_output(args.output, name="--output", overwrite=args.overwrite, need_bytes=PLOT_BYTES)
    if not 2 <= args.snapshots <= 50:
        raise SnappingInputError(f"--snapshots {args.snapshots} is out of range: must lie in [2, 50]")
    ds = load_run(args.file)
    missing = [v for v in ("x", "y", "speed", "tension", "t_snapshot") if v not in ds]
    if missing:
        raise SnappingInputError(f"{args.file} has no profile snapshots (missing {missing}): nothing to plot; "
                                 f"`snapping fit {args.file}` reads the maxima alone")
    fig = figures.overview(ds, n=args.snapshots)
    try:
        save_figure(fig, args.output, dpi=120)
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)
    print(f"wrote {args.output}: {figures.run_label(ds).replace('$', '').replace(chr(92), '')}")
    from .. import figures_elastic

    if figures_elastic.is_elastic_run(ds):
        r = figures_elastic.energy_terms(ds)["residual"]
        print(f"energy balance: max |kinetic + gravity + elastic - pin work + dissipated - E0| / E0 = "
              f"{float(r.max()):.3g} (panel f); strain along the line against time: panel e")
    elif "dissipated" in ds and "bending_energy" in ds:
        r = figures.energy_terms(ds)["residual"]
        print(f"energy balance: max |kinetic + gravity + bending - pin work + dissipated - E0| / E0 = "
              f"{float(r.max()):.3g} (panel f)")
    return 0


#: the most snapshots ``animate --frames`` asks a rerun for (each is a full profile in memory)
MAX_RERUN_FRAMES = 2000


def _dense_rerun(ds, frames: int, path: str):
    """The run ``ds`` (from ``path``) run again with ``frames`` snapshots dense towards its snap."""
    import math

    from .. import animation
    from .._validate import SnappingInputError
    from ..simulate import rerun

    if not 2 <= frames <= MAX_RERUN_FRAMES:
        raise SnappingInputError(f"--frames {frames} is out of range: must lie in [2, {MAX_RERUN_FRAMES}]")
    t_snap = float(ds.attrs.get("t_snap_v", math.nan))
    if not (math.isfinite(t_snap) and t_snap > 0):
        raise SnappingInputError(f"--frames {frames}: {path} has no snapping time (t_snap_v), so there is no snap "
                                 f"to crowd the snapshots towards; use its own snapshots (leave out --frames)")
    times = animation.dense_snapshot_times(t_snap, frames)[1:]  # (t = 0 is always taken)
    print(f"snapping animate: rerunning {path} with {frames} snapshots dense towards the snap (t = {t_snap:.6g})",
          file=sys.stderr)
    if int(ds.attrs.get("dims", 2)) == 3:  # (a 3D run: snapping.spatial, the same steps again)
        from ..spatial.dataset3d import rerun3d

        return rerun3d(ds, snapshot_times=times)
    return rerun(ds, snapshot_times=times, output=None, progress=None).dataset


# ----------------------------------------------------------------------- reproduce
def _add_reproduce(sub) -> None:
    p = sub.add_parser(
        "reproduce",
        help="run, draw and report every quantitative claim and figure of the paper",
        formatter_class=_formatter,
        description=(
            "Reproduce the paper: the runs (in parallel, resumable), Fig. 1-4 as PNG and PDF,\n"
            "and REPORT.md with one row per quantitative claim (measured, paper, verdict).\n"
            "--quick uses small N (under 2 minutes on 2 cores, 40 MB); --full the paper's N = 2000 and 5000\n"
            "(about 30 minutes on 2 cores). The estimate is printed first; without a terminal, one line\n"
            "per finished run."
        ),
        epilog="examples:\n  snapping reproduce --quick -o paper_quick\n  snapping reproduce --full -o paper_full --workers 8",
    )
    g = p.add_mutually_exclusive_group()
    g.add_argument("--quick", dest="mode", action="store_const", const="quick", help="small N (default)")
    g.add_argument("--full", dest="mode", action="store_const", const="full", help="the paper's resolution")
    p.set_defaults(mode="quick")
    p.add_argument("-o", "--output", required=True, help="output directory")
    p.add_argument("--workers", type=int, default=None, help="local worker processes (default: all cores)")
    p.set_defaults(func=_cmd_reproduce)


def _cmd_reproduce(args) -> int:
    from ..reproduce import reproduce
    from ..sweep import SweepFailed

    try:
        report = reproduce(args.output, args.mode, workers=args.workers, progress=sys.stderr.isatty(),
                           log=lambda msg: print(msg, file=sys.stderr))
    except SweepFailed as exc:  # some runs failed: which and why, no traceback
        print(f"snapping reproduce: error: {len(exc.failures)} of the runs failed (the others are saved; rerun "
              f"the same command to retry only the failed ones):", file=sys.stderr)
        print(exc.table(), file=sys.stderr)
        return 1
    print(report.read_text().split("## Fit report")[0].rstrip())
    print(f"\nfull report: {report}")
    return 0


# ------------------------------------------------------------------------- animate
def _add_animate(sub) -> None:
    p = sub.add_parser(
        "animate",
        help="an animation of the snap from a run file's snapshots (GIF, or MP4 with ffmpeg)",
        formatter_class=_formatter,
        description=(
            "Draw the chain of every profile snapshot of RUN.nc as one frame, coloured by speed\n"
            "(log scale, colour bar), with the time and the time to the snap, nondimensional.\n"
            "GIF through Pillow (always available); MP4 needs ffmpeg on PATH. A run has few\n"
            "snapshots up to the snap unless asked for more: --frames K reruns it from its file\n"
            "(same inputs, nothing written) with K snapshots dense towards the snap (geometric in\n"
            "the time to the snap) and animates those."
        ),
        epilog=(
            "examples (run.nc from e.g. snapping simulate --chi 0.25 --N 200 -o run.nc):\n"
            "  snapping animate run.nc -o snap.gif\n"
            "  snapping animate run.nc -o smooth.gif --frames 60    # rerun with 60 dense snapshots\n"
            "  snapping animate run.nc -o snap.gif --max-frames 30 --fps 5\n"
            "  snapping animate run.nc -o snap.mp4 --fps 12 --overwrite"
        ),
    )
    p.add_argument("file", metavar="RUN.nc", help="run file (snapping simulate -o)")
    p.add_argument("-o", "--output", required=True, help="animation file: .gif or .mp4")
    p.add_argument("--fps", type=float, default=8.0, help="frames per second (default 8)")
    p.add_argument("--max-frames", type=int, default=None, help="at most this many frames (snapshots thinned evenly)")
    p.add_argument("--frames", type=int, default=None, metavar="K",
                   help=f"rerun the run with K snapshots dense towards the snap and animate them (2 to "
                        f"{MAX_RERUN_FRAMES}; costs one more run)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing output (default: refuse it)")
    p.set_defaults(func=_cmd_animate)


def _cmd_animate(args) -> int:
    from .. import animation
    from ..simulate import load_run

    animation.check_output(args.output, overwrite=args.overwrite)  # before reading the run
    ds = load_run(args.file)
    if args.frames is not None:
        ds = _dense_rerun(ds, args.frames, args.file)
    animation.frames_of(ds, args.max_frames)  # no snapshots: refused here
    out = animation.animate(ds, args.output, fps=args.fps, max_frames=args.max_frames, overwrite=args.overwrite)
    n = len(animation.frames_of(ds, args.max_frames))
    print(f"wrote {out}: {n} frames at {args.fps:g} fps")
    # (after the work: never a hint before an error)
    if args.frames is None and animation.denser_run_hint(ds, args.file):
        print(f"snapping animate: note: only {animation.snapshots_before_snap(ds)} snapshots up to the snap; for a "
              f"smoother animation add --frames 60 (reruns the run with that many snapshots dense towards the "
              f"snap)", file=sys.stderr)
    return 0
