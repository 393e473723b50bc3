"""The subcommands ``ideal``, ``estimate`` and ``design``: the folded string's exact results,
the peaks of a chain's snap (computed and estimated) and the inverse design."""

from __future__ import annotations

from ._caps import add_real_options, cmd_real_design, cmd_real_estimate, refuse_real_only, wants_real
from ._common import PLOT_BYTES, _floats, _add_g_option, _dimensionless, _formatter, _print_dimensionless, print_json


# --------------------------------------------------------------------------- ideal
def _add_ideal(sub) -> None:
    p = sub.add_parser(
        "ideal",
        help="the perfectly folded falling string: t*, exponents, prefactors",
        formatter_class=_formatter,
        description="Exact results for the perfectly folded falling string (chi = 0).",
        epilog="example:\n  snapping ideal --digits 30\n  snapping ideal --json",
    )
    p.add_argument("--digits", type=int, default=15, help="significant digits of t* (default 15)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=_cmd_ideal)


def _cmd_ideal(args) -> int:
    from .. import ideal

    summary = ideal.summary(digits=args.digits)
    if args.json:
        print_json(summary)
    else:
        ideal.print_summary(summary)
    return 0


# ------------------------------------------------------------------------ estimate
def _add_estimate(sub) -> None:
    p = sub.add_parser(
        "estimate",
        help="peak speed, acceleration and tension of the snap, computed and estimated, in SI",
        formatter_class=_formatter,
        description=(
            "How big will the spike be? With --links (the chain's number of links) the answer\n"
            "leads with the computed peaks: the fast exact method's, interpolated from the table of\n"
            "simulations shipped with snapping (milliseconds), with their error bound (where the\n"
            "bound is above 1% speed and tension or 3% acceleration and a run costs under 10 s, as\n"
            "for few-link chains and heavy tip masses, one run of the fast method instead); then the\n"
            "paper's design-rule estimators from the initial catenary alone, each with its error\n"
            "factor measured on the table. Give the end separation as a fraction --chi of the\n"
            "length, or in metres with --separation, or the initial maximum curvature in 1/m with\n"
            "--curvature. Outside the table, --simulate runs the fast method for that chain."
        ),
        epilog=(
            "examples:\n"
            "  snapping estimate --chi 0.25 --links 229                      # the paper's chain\n"
            "  snapping estimate --separation 0.3 --links 100 --length 2 --mass 0.05\n"
            "  snapping estimate --separation 0.3 --links 100 --length 2 --mass 0.05 --tip-mass 0.1\n"
            "  snapping estimate --chi 0.03 --links 229 --simulate           # outside the table: run it\n"
            "  snapping estimate --chi 0.3 --links 20 --table                # the table alone, never a run\n"
            "  snapping estimate --curvature 20 --length 1.022 --mass 0.0208 --json   # estimators only\n"
            "  snapping estimate --chi 0.25 --line bungee-cord --links 200   # a real line: what caps its snap\n"
            "  snapping estimate --chi 0.25 --length 2 --mass 0.1 --ei 1e-3 --diameter 5e-3 --end-mass 0.01"
        ),
    )
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--chi", type=float, help="end separation / length, in (0, 1)")
    g.add_argument("--separation", type=float, help="end separation in metres (needs --length)")
    g.add_argument("--curvature", type=float, help="initial maximum curvature in 1/m (needs --length)")
    p.add_argument("--length", type=float, default=None, metavar="METERS",
                   help="chain length in m (needed with --separation and --curvature; with --chi the default "
                        "is the paper's 1.022)")
    p.add_argument("--mass", type=float, default=None, metavar="KG",
                   help="chain mass in kg (default: the paper's 0.0208)")
    _add_g_option(p)
    p.add_argument("--links", type=int, default=None, metavar="N",
                   help="the chain's number of links: leads with the computed peaks (table: 10 to 10000); a real "
                        "line's runs: 2 to 20000, default: the links that resolve it (--resolve), a chain of discrete links "
                        "(--line ball-chain) its own")
    p.add_argument("--tip-mass", type=float, default=0.0, metavar="RATIO",
                   help="a point mass at the free end, as a ratio to the chain's mass (needs --links; table: 0 "
                        "to 1, for up to 1800 links)")
    how = p.add_mutually_exclusive_group()
    how.add_argument("--simulate", action="store_true",
                     help="compute the peaks with one run of the fast method instead of the table (any chi, "
                          "links, tip mass; seconds to minutes)")
    how.add_argument("--table", action="store_true",
                     help="the table's interpolated peaks only, whatever their error bound (default: where the "
                          "bound is above 1%% speed and tension or 3%% acceleration and a run costs under 10 s, "
                          "one run of the fast method replaces them)")
    p.add_argument("--N", type=int, default=None, help="number of links for the delta_N = 1/N estimator only "
                                                       "(no computed peaks; use --links)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_real_options(p)
    p.set_defaults(func=_cmd_estimate)


def _chain_of(args):
    """The estimates.Chain of --length/--mass/--g (the paper's chain by default), checked together."""
    from .. import estimates
    from .._validate import SnappingInputError

    for opt, v, unit in (("--separation", getattr(args, "separation", None), "m"),
                         ("--curvature", getattr(args, "curvature", None), "1/m")):
        if v is not None and args.length is None:
            raise SnappingInputError(f"{opt} {v:g} {unit} needs --length (the chain's length in m): chi follows "
                                     f"from both; give --length, or --chi for a fraction of the length")
    if (args.length is None) != (args.mass is None):
        given, missing = ("--length", "--mass") if args.mass is None else ("--mass", "--length")
        raise SnappingInputError(f"{given} {args.length if args.mass is None else args.mass:g} without {missing}: "
                                 f"the peaks in SI need both the chain's length and its mass (give both, or "
                                 f"neither for the paper's chain, 1.022 m and 0.0208 kg)")
    return estimates.Chain(
        **{k: v for k, v in (("length", args.length), ("mass", args.mass), ("g", args.g)) if v is not None}
    )


def _cmd_estimate(args) -> int:
    from .. import estimates, table
    from .._validate import SnappingInputError

    if wants_real(args):
        return cmd_real_estimate(args)
    refuse_real_only(args)
    chain = _chain_of(args)
    where = {k: getattr(args, k) for k in ("chi", "separation", "curvature") if getattr(args, k) is not None}
    if args.simulate and args.links is None:
        raise SnappingInputError("--simulate needs --links (the number of links of the chain to simulate)")
    if args.table and args.links is None:
        raise SnappingInputError("--table needs --links (the table's peaks are those of a chain of given links)")
    if args.tip_mass and args.links is None:
        raise SnappingInputError(f"--tip-mass {args.tip_mass:g} needs --links: the estimate with a tip mass is the "
                                 f"computed one")
    if args.links is not None and args.N is not None:
        raise SnappingInputError("--N and --links both give the number of links: give --links alone")
    if args.simulate:
        from ..design import simulate_estimate

        est = simulate_estimate(chain, **where, links=args.links, tip_mass=args.tip_mass)
    else:
        try:
            if args.links is not None and not args.table:
                from ..design import computed_estimate

                est = computed_estimate(chain, **where, links=args.links, tip_mass=args.tip_mass)
            else:
                est = estimates.design_estimate(chain, **where, N=args.N, links=args.links, tip_mass=args.tip_mass)
        except table.OutsideTable as exc:
            raise table.OutsideTable(f"{exc}; {'drop --table and ' if args.table else ''}add --simulate to "
                                     f"compute this chain with one run of the fast method instead") from None
    numbers = _numbers_of(chain, args, args.links if args.links is not None else args.N, args.tip_mass)
    if args.json:
        print_json({**est.to_dict(), "dimensionless_numbers": numbers})
    else:
        estimates.print_estimate(est)
        _print_dimensionless(numbers)
    return 0


def _numbers_of(chain, args, N, tip_mass) -> dict:
    """The dimensionless numbers (snapping.dimensionless) of the chain of --length/--mass/--g
    (the chain stands for the SI scales: its length, mass and g)."""
    return _dimensionless(chain, args, N=N, tip_mass=tip_mass)


# -------------------------------------------------------------------------- design
def _add_design(sub) -> None:
    p = sub.add_parser(
        "design",
        help="inverse design: the end separations that keep the peak tension, speed or acceleration under a limit",
        formatter_class=_formatter,
        description=(
            "Which end separations keep the snap's peak under a limit? For a chain of given\n"
            "length, mass and number of links, the peaks against the end separation come from\n"
            "the table of fast exact runs (interpolated, with their error bound); a separation is\n"
            "admissible when the peak plus its error bound stays under every limit given. Without\n"
            "--tip-mass every tip mass of the table is scanned (up to 1800 links)."
        ),
        epilog=(
            "examples:\n"
            "  snapping design --max-tension 20 --length 2 --mass 0.05 --links 100\n"
            "  snapping design --max-tension 20 --max-speed 30 --length 2 --mass 0.05 --links 100 --tip-mass 0\n"
            "  snapping design --max-acceleration 5e4 --length 1.022 --mass 0.0208 --links 229 --plot design.png\n"
            "  snapping design --max-tension 5 --line bungee-cord --links 100   # a real line: runs of the real model"
        ),
    )
    p.add_argument("--max-tension", type=float, default=None, metavar="NEWTONS", help="limit of the peak tension in N")
    p.add_argument("--max-speed", type=float, default=None, metavar="M_PER_S", help="limit of the peak speed in m/s")
    p.add_argument("--max-acceleration", type=float, default=None, metavar="M_PER_S2",
                   help="limit of the peak acceleration in m/s^2")
    p.add_argument("--length", type=float, default=None, metavar="METERS",
                   help="the chain's length in m (required, but for a --line)")
    p.add_argument("--mass", type=float, default=None, metavar="KG", help="the chain's mass in kg (required, but for a "
                                                                           "--line)")
    _add_g_option(p)
    p.add_argument("--links", type=int, default=None, metavar="N",
                   help="the chain's number of links (10 to 10000; required, but for a real line: 2 to 20000, "
                        "default: each chi on the links that resolve it, a chain of discrete links such as "
                        "--line ball-chain its own)")
    p.add_argument("--tip-mass", type=float, default=None, metavar="RATIO",
                   help="tip mass / chain mass (default: scan the table's tip masses, 0 to 1)")
    p.add_argument("--plot", default=None, metavar="PNG", help="save the peaks against the separation here")
    p.add_argument("--overwrite", action="store_true", help="replace an existing --plot file")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_real_options(p, resolve=False)
    p.add_argument("--chis", type=_floats, default=None, metavar="C1,C2,...",
                   help="a real line's end separations to run (default 0.05,0.1,0.15,0.2,0.25,0.3,0.4,0.5)")
    p.set_defaults(func=_cmd_design)


def _cmd_design(args) -> int:
    from .. import design
    from .._files import check_output as check_writable
    from .._files import figure_format
    from .._validate import SnappingInputError

    if wants_real(args):
        return cmd_real_design(args)
    refuse_real_only(args)
    for opt, v in (("--length", args.length), ("--mass", args.mass), ("--links", args.links)):
        if v is None:
            raise SnappingInputError(f"the following arguments are required: {opt} (or --line NAME: a real line)")
    chain = _chain_of(args)
    if args.plot is not None:  # (an empty name is refused, not ignored)
        figure_format(args.plot, name="--plot")
        check_writable(args.plot, name="--plot", overwrite=args.overwrite, need_bytes=PLOT_BYTES)
    res = design.design(chain, args.links, max_tension=args.max_tension, max_speed=args.max_speed,
                        max_acceleration=args.max_acceleration, tip_mass=args.tip_mass)
    if args.plot is not None:
        design.plot_design(res, args.plot, overwrite=args.overwrite)
    numbers = _numbers_of(chain, args, args.links, args.tip_mass)
    if args.json:
        print_json({**res.to_dict(), "plot": args.plot, "dimensionless_numbers": numbers})
    else:
        design.print_design(res)
        _print_dimensionless(numbers)
        if args.plot is not None:
            print(f"wrote {args.plot}")
    return 0
