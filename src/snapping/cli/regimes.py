"""The subcommand ``regimes``: a mechanism's number against chi, continuum-extrapolated peaks,
power laws, crossovers and the regime map (:mod:`snapping.regimes`, :mod:`snapping.regimes_analysis`)."""

from __future__ import annotations

from ._common import PLOT_BYTES, _floats, _formatter, print_json


def _add_regimes(sub) -> None:
    from ..regimes_spec import ACCURACY, MECHANISMS

    p = sub.add_parser(
        "regimes",
        help="what caps the snap: a mechanism's number x chi, converged peaks against the ideal's, regime map",
        formatter_class=_formatter,
        description=(
            "For every chi and number, refine the chain level by level (links graded along the\n"
            "fold's path) and extrapolate the peaks to the continuum, beside the ideal chain's\n"
            "limit (number 0). Prints each peak's ratio to the ideal, the power law of the peak\n"
            "against the number where its local slope is constant, and the crossover number where\n"
            "the peak falls 10% below the ideal's. The study file (-o) is rewritten after every\n"
            "run and reused by a rerun of the same study (another study's file is refused).\n"
            "Numbers: bending beta = B/(lambda g L^3); drag 0.5 rho C d L/lambda; end-mass\n"
            "M_end/(lambda L); stretching sqrt(g L)/c, the inverse of c/sqrt(g L)\n"
            "(snapping.dimensionless). Nondimensional units. The shipped 4 x 8 studies:\n"
            "snapping.regimes.bundled_study(mechanism)."
        ),
        epilog=(
            "examples:\n"
            "  snapping regimes --mechanism end-mass --chi 0.25 --numbers 1e-3,1e-2 -o em.nc   # ~1 min\n"
            "  snapping regimes --mechanism bending --chi 0.1,0.25 --numbers 1e-6,1e-4,1e-2 -o bend.nc --workers 2\n"
            "  snapping regimes --mechanism drag --chi 0.1,0.25 --numbers 0.01,0.1,1,10 -o drag.nc --plot drag.png\n"
            "  snapping regimes --load drag.nc --plot drag.png           # the map of a finished study"
        ),
    )
    p.add_argument("--mechanism", choices=sorted(MECHANISMS), default=None, help="the mechanism scanned")
    p.add_argument("--chi", type=_floats, default=None, help="comma-separated end separations in (0, 1)")
    p.add_argument("--numbers", type=_floats, default=None,
                   help="comma-separated values of the mechanism's number (nondimensional: Numbers above), each "
                        "in (0, 1e4]")
    p.add_argument("--accuracy", choices=sorted(ACCURACY), default="coarse",
                   help="levels preset (default coarse: 3 levels; medium: 4 levels, ~1e-3 in the ideal's peaks)")
    p.add_argument("--levels", type=int, default=None, help="override the preset's refinement levels")
    p.add_argument("--first", type=int, default=None, help="override the preset's first fold-graded level")
    p.add_argument("--n0", type=int, default=None,
                   help="override the preset's links of the first uniform level (a mechanism with uniform levels "
                        "only; every mechanism's levels are fold-graded at present: use --first)")
    p.add_argument("--damping", type=float, default=None,
                   help="grid damping ratio of the shortest waves (vanishes with the links): bending (default 1), "
                        "stretching (the longitudinal waves; default 4)")
    p.add_argument("--start", default=None, choices=["matched", "stretched", "unstretched"],
                   help="stretching: the elastic line's start (default matched: no release wave)")
    p.add_argument("--elastic-method", default=None, choices=["rodas4", "rodas4-links"],
                   help="stretching: the elastic line's method (default rodas4-links, link coordinates, steps not "
                        "capped by the wave speed, the shipped study's; rodas4: node coordinates)")
    p.add_argument("--workers", type=int, default=1, help="local worker processes (default 1)")
    p.add_argument("--scheduler", default=None, help="address of a running Dask scheduler")
    p.add_argument("-o", "--output", default=None, metavar="FILE",
                   help="the study file (netCDF: .nc, .nc4 or .netcdf), resumable")
    p.add_argument("--load", default=None, metavar="FILE", help="report (and --plot) a study file, running nothing")
    p.add_argument("--plot", default=None, metavar="PATH", help="draw the regime map (.png, .pdf, .svg)")
    p.add_argument("--quantity", default="v_peak", choices=["v_peak", "a_peak", "sigma_peak", "kappa_peak"],
                   help="the peak of the map (default v_peak)")
    p.add_argument("--overwrite", action="store_true",
                   help="replace an existing --plot file (the study file -o is resumed, never replaced)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--json", action="store_true", help="print the analysis as one JSON object")
    p.set_defaults(func=_cmd_regimes)


def _cmd_regimes(args) -> int:
    from .. import regimes as R
    from .. import regimes_analysis as A
    from .._files import check_output, figure_format
    from .._validate import SnappingInputError

    _refuse_unused(args)
    if args.output is not None:  # (the study is netCDF: never under a name that says another format)
        from .._files import netcdf_suffix

        netcdf_suffix(args.output, name="--output")
    if args.plot is not None:
        figure_format(args.plot, name="--plot")
        check_output(args.plot, name="--plot", overwrite=args.overwrite, need_bytes=PLOT_BYTES)
    if args.load is not None:
        if args.mechanism or args.chi or args.numbers:
            raise SnappingInputError("--load reads a finished study: give no --mechanism, --chi or --numbers")
        ds = R.load_study(args.load)
    else:
        missing = [o for o, v in (("--mechanism", args.mechanism), ("--chi", args.chi), ("--numbers", args.numbers))
                   if v is None]
        if missing:
            raise SnappingInputError(f"regimes needs {', '.join(missing)} (or --load FILE)")
        ds = R.regimes(args.mechanism, args.chi, args.numbers, accuracy=args.accuracy, levels=args.levels,
                       first=args.first, n0=args.n0, damping=args.damping,
                       **({} if args.start is None else {"start": args.start}),
                       method=args.elastic_method, workers=args.workers, scheduler=args.scheduler,
                       out=args.output, progress=not args.no_progress)
    if args.json:
        out = {q: A.analyze(ds, q) for q in ("v_peak", "a_peak", "sigma_peak")}
        print_json({"study": {k: (v.item() if hasattr(v, "item") else v) for k, v in ds.attrs.items()},
                    "analysis": out})
    else:
        print("\n".join(A.report(ds)))
    if args.plot is not None:
        import matplotlib.pyplot as plt

        plt.close(A.regime_map(ds, args.plot, quantity=args.quantity))
        print(f"regime map: {args.plot}")
    return 0


#: options that only a run of a study takes (not --load)
_RUN_OPTIONS = (("accuracy", "--accuracy"), ("levels", "--levels"), ("first", "--first"), ("n0", "--n0"),
                ("damping", "--damping"), ("start", "--start"), ("elastic_method", "--elastic-method"),
                ("workers", "--workers"), ("scheduler", "--scheduler"), ("output", "--output"))


def _refuse_unused(args) -> None:
    """Refuse an option that the study asked for would ignore (SnappingInputError naming it and why):
    a run's options with --load, a mechanism's options with another mechanism, --n0 with fold-graded
    levels, --quantity and --overwrite without --plot."""
    from .._validate import SnappingInputError
    from ..regimes_spec import MECHANISMS

    explicit = getattr(args, "_explicit", None)

    def typed(dest):
        value = getattr(args, dest, None)
        if explicit is not None:
            return dest in explicit and value not in (None, False)
        return value not in (None, False)

    if args.load is not None:
        for dest, opt in _RUN_OPTIONS:
            if typed(dest):
                raise SnappingInputError(f"{opt} is an option of a study's runs: --load reads a finished study and "
                                         f"runs nothing (give {opt} without --load)")
    mech = args.mechanism
    if mech is not None:
        if typed("damping") and mech not in ("bending", "stretching"):
            raise SnappingInputError(f"--damping={args.damping!r} is the grid damping of the bending and stretching "
                                     f"studies: the {mech} study has none (drop --damping)")
        if typed("start") and mech != "stretching":
            raise SnappingInputError(f"--start {args.start} is the elastic line's start (--mechanism stretching): "
                                     f"the {mech} study starts from the catenary at rest (drop --start)")
        if typed("n0") and MECHANISMS[mech][1] != "uniform":
            raise SnappingInputError(f"--n0={args.n0!r} sets the links of uniform levels: the {mech} study's levels "
                                     f"are graded along the fold (set them with --first and --levels)")
    if args.plot is None:
        for dest, opt in (("overwrite", "--overwrite"),):
            if typed(dest):
                raise SnappingInputError(f"{opt} replaces an existing --plot file: give it with --plot (the study "
                                         f"file -o is resumed, never replaced: give another -o path to start afresh)")
        if explicit is not None and "quantity" in explicit:
            raise SnappingInputError(f"--quantity {args.quantity} is the peak of the regime map: give it with --plot "
                                     f"(the report prints every peak)")
