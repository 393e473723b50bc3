"""The subcommands ``sweep`` and ``converge``: grids of runs (over chi and N, or refined chains
extrapolated to the continuum limit)."""

from __future__ import annotations

import math
import sys

from ._common import (PLOT_BYTES, _add_si_options, _dimensionless, _floats, _formatter, _ints, _nonfinite,
                      _nonfinite_error, _print_dimensionless, _print_si, _si_scales, _with_si, print_json)


# --------------------------------------------------------------------------- sweep
def _add_sweep(sub) -> None:
    p = sub.add_parser(
        "sweep",
        help="a grid of runs over chi and N, in parallel, resumable",
        formatter_class=_formatter,
        description=(
            "Run every (chi, N) of the grid, each saved atomically to DIR as it finishes;\n"
            "a rerun skips finished runs. Runs go to local processes, or to a Dask cluster\n"
            "with --scheduler. Finally the runs are combined into DIR/sweep.nc.\n"
            "Default: the fast exact method (--method fast) from the catenary with exact chords\n"
            "(--chords exact); the paper's is --method euler-richardson --chords arclength.\n"
            "Units: nondimensional (length L, mass M, time sqrt(L/g), force M g)."
        ),
        epilog=(
            "examples:\n"
            "  snapping sweep --chi 0.25,0.5 --N 50,100 --tol 1e-7 -o sweep_small\n"
            "  snapping sweep --chi 0.25,0.5 --N 50 -o sweep_si --length 1.022 --mass 0.0208   # SI too\n"
            "  snapping sweep --chi 0.2,0.3,0.4,0.5 --N 1000 --ensemble 4 -o sweep_ensemble\n"
            "  snapping sweep --chi 0.25,0.5 --N 200 --method euler-richardson --chords arclength -o sweep_paper\n"
            "  snapping sweep --chi 0.1,0.25 --N 200,500 --scheduler tcp://scheduler.example.org:8786 -o sweep_cluster\n"
            "  snapping sweep --chi 0.2,0.3 --N 100 --bending 1e-3 --drag-normal 0.5 -o sweep_body   # a line's body\n"
            "  snapping sweep --chi 0.25 --N 30,60 --stretching 300 --grid-damping 1 -o sweep_elastic  # extensible"
        ),
    )
    p.add_argument("--chi", type=_floats, required=True, help="comma-separated end separations in (0, 1)")
    p.add_argument("--N", type=_ints, required=True, help="comma-separated numbers of links")
    p.add_argument("--tol", type=float, default=None,
                   help="stepper tolerance (default: the method's, fast 1e-6 and euler-richardson 1e-8)")
    p.add_argument("--method", default=None,
                   help="time-stepping method: fast (default), dop853, rodas4 (stiff), euler-richardson, "
                        "euler-richardson-fixed")
    p.add_argument("--chords", default=None, choices=["exact", "arclength"],
                   help="initial nodes with exact chords 1/N (default) or at equal arclength (the paper's)")
    p.add_argument("--workers", type=int, default=None, help="local worker processes (default: all cores)")
    p.add_argument("--scheduler", default=None, help="address of a running Dask scheduler")
    p.add_argument("--ensemble", type=int, default=None, metavar="K",
                   help="run up to K chi of one N together in one ensemble kernel (needs --method fast or dop853)")
    p.add_argument("-o", "--output", required=True, help="output directory")
    p.add_argument("--overwrite", action="store_true",
                   help="replace DIR/sweep.nc even if it holds another grid's runs, and files named like its runs "
                        "that snapping did not write (default: refuse)")
    p.add_argument("--json", action="store_true", help="print the per-run results as one JSON object")
    from ._body import add_body_options

    add_body_options(p)  # a line's body, the same at every (chi, N)
    from ._elastic import add_elastic_options

    add_elastic_options(p)  # the extensible line, the same links at every (chi, N)
    _add_si_options(p)
    p.set_defaults(func=_cmd_sweep)


def _cmd_sweep(args) -> int:
    from pathlib import Path

    from .. import sweep, units

    scales = _si_scales(args)
    options = {k: v for k, v in (("tol", args.tol), ("method", args.method), ("chords", args.chords))
               if v is not None}
    from ._body import body_from_args, refuse_line_masses

    refuse_line_masses(args, "sweep")
    from ._elastic import elastic_from_args

    elastic = elastic_from_args(args, scales)  # (None: the rigid-link chain)
    body = body_from_args(args)
    if body is not None and body.active:
        options["body"] = body
    if elastic is not None:
        options["elastic"] = elastic
        if args.elastic_start is not None:
            options["start"] = args.elastic_start
    grid = sweep.Grid(chi=args.chi, N=args.N, options=options)
    target = sweep.check_combined(Path(args.output) / "sweep.nc", grid, overwrite=args.overwrite)
    failed = None
    try:
        paths = sweep.run_sweep(grid, args.output, workers=args.workers, scheduler=args.scheduler,
                                progress=sys.stderr.isatty(), ensemble=args.ensemble, overwrite=args.overwrite)
    except KeyboardInterrupt:
        print(f"snapping sweep: interrupted; finished and checkpointed runs are kept in {args.output}: "
              "run the same command again to resume only the missing runs", file=sys.stderr)
        return 130
    except sweep.SweepFailed as exc:
        failed, paths = exc, exc.paths
    rows, out = [], None
    if paths:
        combined = sweep.combine(paths)
        combined.attrs["sweep_grid"] = sweep.grid_key(grid)
        out = sweep.atomic_to_netcdf(combined, target)
        for chi in combined["chi"].values:
            for N in combined["N"].values:
                sel = combined.sel(chi=chi, N=N)
                if "n_steps" in sel and not math.isfinite(float(sel["n_steps"])):
                    continue  # (chi, N) is no finished run (it failed): a hole of the grid
                row = {"chi": float(chi), "N": int(N)}
                row.update({k: float(sel[k]) for k in ("v_peak", "a_peak", "sigma_peak", "t_snap_v", "strain_peak")
                            if k in sel})
                reached = float(sel["snap_reached"]) if "snap_reached" in sel else 1.0
                row["snap_reached"] = bool(reached == 1.0)
                if not row["snap_reached"]:
                    row["t_snap_v"] = None  # absent: the run ended before the snap
                rows.append(row)
    bad = _nonfinite({"runs": rows})
    if args.json:
        obj = {"sweep": None if out is None else str(out), "runs": rows}
        if "body" in grid.options:
            from ..simulate.body import summarize

            obj["body"] = summarize(grid.options["body"])
        if failed is not None:
            obj["failed"] = [f.to_dict() for f in failed.failures]
        if bad:
            return _nonfinite_error("sweep", bad)
        print_json(_with_si(obj, scales, lambda: {"runs": [{"chi": r["chi"], "N": r["N"],
                                                            **units.values_to_si(r, scales)} for r in rows]}))
    else:
        if bad:
            return _nonfinite_error("sweep", bad)
        n_done = len(paths)
        if out is not None:
            print(f"{n_done} runs in {args.output}; combined: {out}")
            ca = combined.attrs
            print(f"  method {ca.get('method', '?')}, chords {ca.get('chords', '?')}, tol {ca.get('tol', '?')}; "
                  f"units: nondimensional (length L, mass M, time sqrt(L/g), force M g)")
            if "body" in grid.options:
                from ..simulate.body import summarize

                print(f"  body (every run): {summarize(grid.options['body'])}")
            if "elastic" in grid.options:
                print(f"  extensible line (every run): {grid.options['elastic']}; strain_peak: "
                      + ", ".join(f"{r['strain_peak']:.4g}" for r in rows if "strain_peak" in r))
            print(f"  {'chi':>6} {'N':>7} {'v_peak':>10} {'a_peak':>11} {'sigma_peak':>11} {'t_snap_v':>10}")
            for r in rows:
                t_snap = "no snap" if r["t_snap_v"] is None else f"{r['t_snap_v']:.6g}"
                print(f"  {r['chi']:>6g} {r['N']:>7d} {r.get('v_peak', float('nan')):>10.5g} "
                      f"{r.get('a_peak', float('nan')):>11.5g} {r.get('sigma_peak', float('nan')):>11.5g} "
                      f"{t_snap:>10}")
            if any(not r["snap_reached"] for r in rows):
                print("  no snap: the run ended before the snap (see its snap_note); its peaks are maxima over the run")
            _print_si(scales, [(f"chi={r['chi']:g} N={r['N']} {k}", *rest) for r in rows if scales
                               for k, *rest in units.si_rows(r, scales)])
            _print_dimensionless(_dimensionless(scales, args, N=[int(n) for n in args.N], tip_mass=0.0))
        else:
            print(f"no run of the sweep completed; nothing combined in {args.output}")
    if failed is not None:
        print(f"snapping sweep: error: {len(failed.failures)} of {failed.n_runs} runs failed (the other runs are "
              f"saved; rerun the same command to retry only the failed ones):", file=sys.stderr)
        print(failed.table(), file=sys.stderr)
        return 1
    return 0


# ----------------------------------------------------------------------- converge
def _add_converge(sub) -> None:
    p = sub.add_parser(
        "converge",
        help="the continuum limit of the snap: graded chains refined, peaks extrapolated with error bars",
        formatter_class=_formatter,
        description=(
            "Refine chains whose links follow the fold (snapping.simulate.grading.fold_following) level\n"
            "by level, every length scale times --ratio per level, run each to the snap (method fast),\n"
            "and extrapolate the peaks of speed, acceleration, tension, curvature and the snapping\n"
            "time to the string (Richardson, with the observed order and an error bar from the\n"
            "spread of successive extrapolations). Nondimensional units (length, mass and g of the\n"
            "chain)."
        ),
        epilog=(
            "examples:\n"
            "  snapping converge --chi 0.25                      # 4 levels, ~10 s\n"
            "  snapping converge --chi 0.1 --levels 5 --workers 2 -o conv01 --plot conv01.png\n"
            "  snapping converge --chi 0.25 --levels 3 --first -1 --json\n"
            "  snapping converge --chi 0.05 --ratio 0.7071067811865476 --first 3   # 3 digits, ~4 min\n"
            "  snapping converge --chi 0.25 --lumping paper      # the paper's lumping: first order\n"
            "  snapping converge --chi 0.25 --length 1.022 --mass 0.0208   # the limits in SI too\n"
            "  snapping converge --chi 0.25 --bending 1e-2 --n0 25         # the rod's limit: uniform chains\n"
            "  snapping converge --chi 0.25 --stretching 300 --grid-damping 1 --n0 8 --levels 3  # extensible line\n"
            "\n"
            "With -o DIR every level's run file is kept there and a rerun reuses the finished levels."
        ),
    )
    p.add_argument("--chi", type=float, required=True, help="end separation / length, in (0, 1)")
    p.add_argument("--levels", type=int, default=4, help="refinement levels (default 4; >= 4 for an error bar)")
    p.add_argument("--ratio", type=float, default=0.5,
                   help="length scales' factor per level (default 0.5; closer to 1 with a larger --first: four "
                        "cheaper levels, all asymptotic, for the error bar)")
    p.add_argument("--first", type=int, default=0,
                   help="index of the coarsest level (default 0: fold links 4%% of its radius; -1: 8%%)")
    p.add_argument("--lumping", default="shared", choices=["shared", "paper"], help="node masses (default shared)")
    p.add_argument("--free-end", default=None, choices=["half", "whole"],
                   help="mass of the free-end node: its share of the last link (shared's) or all of it")
    p.add_argument("--tol", type=float, default=1e-7, help="tolerance of the fast method (default 1e-7)")
    p.add_argument("--workers", type=int, default=1, help="levels run in parallel (default 1)")
    p.add_argument("-o", "--output", default=None, metavar="DIR", help="keep the levels' run files here")
    p.add_argument("--plot", default=None, metavar="PATH", help="draw the convergence figure (.png, .pdf, .svg)")
    p.add_argument("--overwrite", action="store_true",
                   help="replace an existing --plot file, and files in -o named like a level that snapping did not "
                        "write (default: refuse them)")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    p.add_argument("--n0", type=int, default=50, metavar="N",
                   help="with a body or the extensible line: links of level 0 (uniform chains of N/ratio^k links; "
                        "default 50)")
    from ._body import add_body_options

    add_body_options(p)
    from ._elastic import add_elastic_options

    add_elastic_options(p)
    _add_si_options(p)
    p.set_defaults(func=_cmd_converge)


def _level_numbers(res, scales, args):
    """The dimensionless numbers of a convergence study's line; its link scale: each level's
    smallest link h_min/L (graded chains)."""
    numbers = _dimensionless(scales, args)
    if numbers is not None and "h_min" in res.dataset.variables:
        numbers["link_scale"] = tuple(float(h) for h in res.dataset["h_min"].values)
    return numbers


def _cmd_converge(args) -> int:
    from .. import continuum, units

    from .._validate import SnappingInputError

    scales = _si_scales(args)
    if args.plot is not None:
        from .._files import figure_format
        from ..simulate.dataset import check_writable

        try:
            figure_format(args.plot, name="plot")
            check_writable(args.plot, name="plot", overwrite=args.overwrite, need_bytes=PLOT_BYTES)
        except SnappingInputError as exc:
            raise SnappingInputError(f"--plot {args.plot!r}: {exc}") from None
    from ._body import body_from_args, refuse_line_masses

    refuse_line_masses(args, "converge")
    from ._elastic import elastic_from_args

    elastic = elastic_from_args(args, scales)
    body = body_from_args(args)
    if "n0" in getattr(args, "_explicit", ()) and body is None and elastic is None:
        raise SnappingInputError(f"--n0 {args.n0} needs a body (--bending, --drag-normal, ...) or the extensible line "
                                 f"(--stretching, --ea): without them the levels are fold-following chains (--first, "
                                 f"--ratio)")
    extra = {} if body is None or not body.active else {"body": body, "n0": args.n0}
    if elastic is not None:
        extra = {**extra, "elastic": elastic, "n0": args.n0}  # (with the body, if any: it rides on the line)
        if args.elastic_start is not None:
            extra["elastic_start"] = args.elastic_start
    res = continuum.converge(args.chi, levels=args.levels, ratio=args.ratio, first=args.first, lumping=args.lumping,
                             free_end=args.free_end, tol=args.tol, output=args.output, workers=args.workers,
                             progress=None if not args.json else False, overwrite=args.overwrite, **extra)
    if args.plot is not None:
        res.plot(args.plot)
    if args.json:
        ds = res.dataset
        levels = {k: ds[k].values.tolist() for k in ds.data_vars}
        print_json(_with_si({**res.summary(), "levels": levels}, scales,
                            lambda: {"values": units.values_to_si(res.summary(), scales),
                                     "levels": units.values_to_si(levels, scales)}))
    else:
        print(res.table())
        _print_si(scales, units.si_rows(res.summary(), scales) if scales else [])
        _print_dimensionless(_level_numbers(res, scales, args))
    return 0
