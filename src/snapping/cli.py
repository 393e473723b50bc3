"""The ``snapping`` command line: thin wrappers over the library.

Each subcommand has an ``_add_<name>`` function that declares its arguments
(with a working example in its epilog) and a ``_cmd_<name>`` function that
calls the library and prints. No physics lives here.

Bad input (a :class:`ValueError` from the library, or an argparse error) prints
one line on stderr and exits with status 2, without a traceback.
"""

from __future__ import annotations

import argparse
import json
import math
import sys

EXIT_BAD_INPUT = 2
EXIT_FAILED = 1  # a numerical failure or an I/O fault (e.g. a full disk)
PLOT_BYTES = 2e6  # free space a figure file needs (checked before the work)


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit status 2."""

    def error(self, message: str):  # noqa: D401 - argparse API
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message}\n")


def _formatter(prog):
    return argparse.RawDescriptionHelpFormatter(prog, max_help_position=32)


def _json_default(obj):
    import numpy as np

    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    return str(obj)


def print_json(obj) -> None:
    """Print one JSON object (NaN/inf written as null)."""

    def clean(x):
        if isinstance(x, dict):
            return {k: clean(v) for k, v in x.items()}
        if isinstance(x, (list, tuple)):
            return [clean(v) for v in x]
        if isinstance(x, float) and not math.isfinite(x):
            return None
        return x

    print(json.dumps(clean(obj), default=_json_default, indent=2))


def _nonfinite(obj, path: str = "") -> list[str]:
    """``name=value`` of every NaN or infinite number in ``obj`` (nested dicts and lists);
    None (a value deliberately absent) is not one."""
    import numpy as np

    if isinstance(obj, dict):
        return [b for k, v in obj.items() for b in _nonfinite(v, f"{path}.{k}" if path else str(k))]
    if isinstance(obj, (list, tuple)):
        return [b for i, v in enumerate(obj) for b in _nonfinite(v, f"{path}[{i}]")]
    if isinstance(obj, (float, np.floating)) and not math.isfinite(float(obj)):
        return [f"{path}={float(obj)!r}"]
    return []


def _nonfinite_error(command: str, bad: list[str], where: str = "") -> int:
    """Print the one-line error of results that are not finite numbers; exit status 1."""
    more = f" and {len(bad) - 3} more" if len(bad) > 3 else ""
    print(f"snapping {command}: error: non-finite result {', '.join(bad[:3])}{more}: the computation overflowed "
          f"or is undefined at these inputs, so there is no result to print{where}", file=sys.stderr)
    return 1


def print_table(rows, title: str | None = None) -> None:
    """Print (name, value, unit/comment) rows as an aligned table."""
    if title:
        print(title)
        print("-" * len(title))
    rows = [tuple("" if c is None else c for c in r) for r in rows]
    fmt_rows = []
    for r in rows:
        name, value = r[0], r[1]
        if isinstance(value, float):
            value = f"{value:.6g}"
        fmt_rows.append((str(name), str(value), *(str(c) for c in r[2:])))
    w0 = max(len(r[0]) for r in fmt_rows)
    w1 = max(len(r[1]) for r in fmt_rows)
    for r in fmt_rows:
        rest = "  ".join(r[2:])
        print(f"  {r[0]:<{w0}}  {r[1]:>{w1}}  {rest}".rstrip())


# ----------------------------------------------------------------------- SI units
#: commands with --length/--mass/--g for SI output (their errors name these options themselves)
_SI_COMMANDS = ("simulate", "fit", "sweep", "converge")
_SI_DESTS = ("length", "mass", "g")


def _add_g_option(p) -> None:
    """--g: gravity in m/s^2, the same on every command that has it."""
    p.add_argument("--g", type=float, default=9.81, metavar="M_PER_S2", help="gravity in m/s^2 (default 9.81)")


def _add_si_options(p) -> None:
    """--length, --mass and --g: the chain in SI, to print the results in SI too (snapping.units)."""
    g = p.add_argument_group("SI units", "with --length and --mass the results are printed in SI too (text: a "
                                         "table beside the nondimensional one; --json: an \"si\" object)")
    g.add_argument("--length", type=float, default=None, metavar="METERS", help="the chain's length in m")
    g.add_argument("--mass", type=float, default=None, metavar="KG", help="the chain's mass in kg")
    _add_g_option(g)


def _si_scales(args):
    """The :class:`snapping.units.Scales` of --length/--mass/--g, or None when neither
    --length nor --mass is given; SnappingInputError naming the option when one is bad."""
    from ._validate import SnappingInputError
    from .units import Scales

    if args.length is None and args.mass is None:
        if "g" in getattr(args, "_explicit", ()):
            raise SnappingInputError(f"--g {args.g!r} needs --length METERS and --mass KG (it only scales SI output)")
        return None
    if args.length is None or args.mass is None:
        given, missing = ("--length", "--mass") if args.mass is None else ("--mass", "--length")
        raise SnappingInputError(f"{given} needs {missing} too: give both (the chain's length in m and mass in kg) "
                                 f"for SI output, or neither")
    try:
        return Scales(args.length, args.mass, args.g)
    except SnappingInputError as exc:
        raise SnappingInputError(f"--{exc}") from None  # (its message starts with length=, mass= or g=)


def _with_si(obj: dict, scales, si) -> dict:
    """``obj`` (a --json answer) with its ``"si"`` part (``si()`` computes it), or, without
    --length/--mass, a ``"units_note"`` line saying the numbers are nondimensional and how to
    get SI (a run's own ``"units"`` field, its unit system, is kept)."""
    from . import units

    if scales is None:
        return {**obj, "units_note": units.NONDIMENSIONAL_NOTE}
    return {**obj, "si": {"system": "SI", "scales": units._scale_inputs(scales), **si()}}


def _print_si(scales, rows, title: str = "") -> None:
    """The SI part of a text answer: ``rows`` (name, nondimensional, SI, units; from
    :func:`snapping.units.si_rows`) as a table, or, without --length/--mass, the line saying
    the numbers are nondimensional and how to get SI."""
    from . import units

    if scales is None:
        print(f"  {units.NONDIMENSIONAL_NOTE}")
        return

    def fmt(v):
        if v is None:
            return "absent"
        if isinstance(v, list):
            return "[" + ", ".join(fmt(x) for x in v) + "]"
        return f"{v:.6g}" if isinstance(v, float) else str(v)

    head = (f"In SI{f' ({title})' if title else ''}: chain length {scales.length:g} m, mass {scales.mass:g} kg, "
            f"g = {scales.g:g} m/s^2 (time unit {scales.time:.6g} s)")
    print()
    print(head)
    print("-" * len(head))
    table = [("", "nondimensional", "SI", "units")] + [(str(k), fmt(v), fmt(si), u) for k, v, si, u in rows]
    w = [max(len(r[i]) for r in table) for i in range(3)]
    for r in table:
        print(f"  {r[0]:<{w[0]}}  {r[1]:>{w[1]}}  {r[2]:>{w[2]}}  {r[3]}".rstrip())


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
    from . import ideal

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
            "simulations shipped with snapping (milliseconds), with their error bound; then the\n"
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
            "  snapping estimate --curvature 20 --length 1.022 --mass 0.0208 --json   # estimators only"
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
                   help="the chain's number of links: leads with the computed peaks (table: 10 to 10000)")
    p.add_argument("--tip-mass", type=float, default=0.0, metavar="RATIO",
                   help="a point mass at the free end, as a ratio to the chain's mass (needs --links; table: 0 "
                        "to 1, for up to 1800 links)")
    p.add_argument("--simulate", action="store_true",
                   help="compute the peaks with one run of the fast method instead of the table (any chi, links, "
                        "tip mass; seconds to minutes)")
    p.add_argument("--N", type=int, default=None, help="number of links for the delta_N = 1/N estimator only "
                                                       "(no computed peaks; use --links)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=_cmd_estimate)


def _chain_of(args):
    """The estimates.Chain of --length/--mass/--g (the paper's chain by default), checked together."""
    from . import estimates
    from ._validate import SnappingInputError

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
    from . import estimates, table
    from ._validate import SnappingInputError

    chain = _chain_of(args)
    where = {k: getattr(args, k) for k in ("chi", "separation", "curvature") if getattr(args, k) is not None}
    if args.simulate and args.links is None:
        raise SnappingInputError("--simulate needs --links (the number of links of the chain to simulate)")
    if args.tip_mass and args.links is None:
        raise SnappingInputError(f"--tip-mass {args.tip_mass:g} needs --links: the estimate with a tip mass is the "
                                 f"computed one")
    if args.links is not None and args.N is not None:
        raise SnappingInputError("--N and --links both give the number of links: give --links alone")
    if args.simulate:
        from .design import simulate_estimate

        est = simulate_estimate(chain, **where, links=args.links, tip_mass=args.tip_mass)
    else:
        try:
            est = estimates.design_estimate(chain, **where, N=args.N, links=args.links, tip_mass=args.tip_mass)
        except table.OutsideTable as exc:
            raise table.OutsideTable(f"{exc}; add --simulate to compute this chain with one run of the fast "
                                     f"method instead") from None
    if args.json:
        print_json(est.to_dict())
    else:
        estimates.print_estimate(est)
    return 0


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
            "  snapping design --max-acceleration 5e4 --length 1.022 --mass 0.0208 --links 229 --plot design.png"
        ),
    )
    p.add_argument("--max-tension", type=float, default=None, metavar="NEWTONS", help="limit of the peak tension in N")
    p.add_argument("--max-speed", type=float, default=None, metavar="M_PER_S", help="limit of the peak speed in m/s")
    p.add_argument("--max-acceleration", type=float, default=None, metavar="M_PER_S2",
                   help="limit of the peak acceleration in m/s^2")
    p.add_argument("--length", type=float, required=True, metavar="METERS", help="the chain's length in m")
    p.add_argument("--mass", type=float, required=True, metavar="KG", help="the chain's mass in kg")
    _add_g_option(p)
    p.add_argument("--links", type=int, required=True, metavar="N", help="the chain's number of links (10 to 10000)")
    p.add_argument("--tip-mass", type=float, default=None, metavar="RATIO",
                   help="tip mass / chain mass (default: scan the table's tip masses, 0 to 1)")
    p.add_argument("--plot", default=None, metavar="PNG", help="save the peaks against the separation here")
    p.add_argument("--overwrite", action="store_true", help="replace an existing --plot file")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=_cmd_design)


def _cmd_design(args) -> int:
    from . import design
    from ._files import check_output as check_writable

    chain = _chain_of(args)
    if args.plot:
        check_writable(args.plot, name="--plot", overwrite=args.overwrite, need_bytes=PLOT_BYTES)
    res = design.design(chain, args.links, max_tension=args.max_tension, max_speed=args.max_speed,
                        max_acceleration=args.max_acceleration, tip_mass=args.tip_mass)
    if args.plot:
        design.plot_design(res, args.plot, overwrite=args.overwrite)
    if args.json:
        print_json(res.to_dict())
    else:
        design.print_design(res)
        if args.plot:
            print(f"wrote {args.plot}")
    return 0


# ------------------------------------------------------------------------ simulate
def _problem_title(summary) -> str:
    parts = [f"{k}={summary[k]}" for k in ("start", "tip_mass", "pin_motion", "gravity") if k in summary]
    return ", ".join(parts) or "general problem"


def _add_simulate(sub) -> None:
    p = sub.add_parser(
        "simulate",
        help="simulate the falling chain from the catenary to the snap (netCDF4 run file)",
        formatter_class=_formatter,
        description=(
            "Simulate the N-link chain released from the catenary of end separation --chi, to shortly\n"
            "after the snap (or to --t-end), and print peaks, snapping times, invariant drifts and cost.\n"
            "Default: the fast exact method (--method fast, links exact to round-off) from the catenary\n"
            "with exact chords 1/N (--chords exact); the paper's computation is --method\n"
            "euler-richardson --chords arclength (what snapping reproduce runs). Units: nondimensional\n"
            "(length L, mass M, time sqrt(L/g), force M g). -o writes the run as netCDF4."
        ),
        epilog=(
            "methods (--method):\n"
            "  euler-richardson        the paper's adaptive 2nd-order scheme, position form (reference)\n"
            "  euler-richardson-fixed  the same step at the fixed dt = --dt0 (order studies)\n"
            "  dop853                  link-angle form (links exact to round-off), compiled 8th-order\n"
            "                          Dormand-Prince with dense output: 20-40x fewer evaluations\n"
            "  fast                    always the project's best exact method (now dop853; the default)\n"
            "\n"
            "examples:\n"
            "  snapping simulate --chi 0.25 --N 500 -o run.nc\n"
            "  snapping simulate --chi 0.1 --N 5000 --tol 1e-8\n"
            "  snapping simulate --chi 0.25 --N 2000 --method euler-richardson --chords arclength --json  # the paper's\n"
            "  snapping simulate --chi 0.5 --N 100 --t-end 0.5 --snapshot-times 0.1,0.2 -o run.nc\n"
            "  snapping simulate --resume run.nc      # continue an interrupted or checkpointed run\n"
            "  snapping simulate --chi 0.25 --N 229 --length 1.022 --mass 0.0208   # results in SI too\n"
            "\n"
            "other chains, starts and held ends (method fast; every option is nondimensional:\n"
            "lengths in chain lengths, masses in chain masses, time in sqrt(length/g)):\n"
            "  snapping simulate --chi 0.3 --N 500 --method fast --tip-mass 0.2       # a payload at the end\n"
            "  snapping simulate --chi 0.3 --N 500 --method fast --taper 0.1          # a whip, linear taper\n"
            "  snapping simulate --chi 0.3 --N 500 --method fast --taper 0.1:2        # power-law taper\n"
            "  snapping simulate --supports 0.4,0.2 --N 300 --method fast             # 2nd support 0.2 lower\n"
            "  snapping simulate --shape start.csv --N 300 --method fast              # x,y from the held end\n"
            "  snapping simulate --chi 0.5 --N 300 --method fast --pin-motion flick:3,0,0.25  # flick the end\n"
            "  snapping simulate --chi 0.5 --N 300 --method fast --pin-motion pull:0,-2,0.3   # yank it up\n"
            "  snapping simulate --chi 0.3 --N 300 --method fast --gravity 0 --pin-motion pull:1,0\n"
            "\n"
            "With -o the run is checkpointed to its file every --checkpoint-every seconds; Ctrl-C\n"
            "(SIGINT) or SIGTERM stops it at a step boundary, saves it and prints the command that\n"
            "resumes it (exit status 130 or 143). A resumed run gives the same file, bit for bit.\n"
            "\n"
            "Output files: -o must be a new path or, with --overwrite, an existing regular file (a\n"
            "device, FIFO or directory is never replaced; a symbolic link is written through, to its\n"
            "target); its directory and free space are checked before the run, and the file is locked\n"
            "while the run writes it (a second writer is refused, naming the PID). --resume checks\n"
            "the checkpoint's integrity digest, and refuses options that contradict the stored run.\n"
            "Exit status: 0 done, 1 numerical failure or I/O fault (e.g. a full disk), 2 bad input."
        ),
    )
    p.add_argument("--chi", type=float, default=None, help="end separation / length, in (0, 1)")
    p.add_argument("--N", type=int, default=None, help="number of links (>= 1)")
    p.add_argument("--tol", type=float, default=None,
                   help="stepper tolerance (default: the method's, fast 1e-6 and euler-richardson the paper's 1e-8)")
    p.add_argument("--method", default="fast",
                   choices=["fast", "dop853", "euler-richardson", "euler-richardson-fixed"],
                   help="time stepper (default: fast; every method is listed below)")
    p.add_argument("--dt0", type=float, default=None, help="initial (fixed method: constant) time step")
    p.add_argument("--t-end", type=float, default=None, help="end time (default: stop shortly after the snap)")
    p.add_argument("--stop-fraction", type=float, default=0.5,
                   help="automatic stop once v_max < this fraction of its peak (default 0.5)")
    p.add_argument("--snapshot-times", default="", help="comma-separated extra snapshot times")
    p.add_argument("--record-thin", type=float, default=0.0,
                   help="record a step only if a maximum changed by more than this fraction (default 0: all)")
    p.add_argument("--chords", default="exact", choices=["exact", "arclength"],
                   help="initial nodes with exact chords 1/N (default) or at equal arclength (the paper's)")
    p.add_argument("--tip-mass", type=float, default=0.0, metavar="RATIO",
                   help="point mass at the free end, as a ratio to the chain's mass (default 0)")
    p.add_argument("--taper", default=None, metavar="RATIO[:POWER]",
                   help="mass per length falling as (1 - c s)^POWER to RATIO of its value at the held end")
    p.add_argument("--lumping", default=None, choices=["shared", "paper"],
                   help="node masses: each node's share of its two links (default with --taper) or the "
                        "paper's whole link per node (default otherwise)")
    p.add_argument("--supports", default=None, metavar="DX,DY",
                   help="start: the catenary between the held end and a support at (DX, DY), y downward")
    p.add_argument("--shape", default=None, metavar="FILE",
                   help="start: a curve x,y (CSV or netCDF) listed from the held end; nodes at exact chords")
    p.add_argument("--pin-motion", default=None, metavar="SPEC",
                   help="held end: fixed (default), pull:AX,AY[,DURATION[,T0]] or flick:AX,AY,PERIOD[,T0]")
    p.add_argument("--gravity", type=float, default=1.0, help="gravity along +y in units of g (default 1; 0: none)")
    p.add_argument("-o", "--output", default=None, help="write the run to this netCDF4 file (a new path, or --overwrite)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing -o file (default: refuse it)")
    p.add_argument("--resume", metavar="RUN.nc", default=None,
                   help="continue the interrupted or checkpointed run in this file (written back to it, or to -o)")
    p.add_argument("--checkpoint-every", type=float, default=300.0, metavar="SECONDS",
                   help="with -o: save the run's full state every this many seconds (default 300; 0: very often)")
    p.add_argument("--max-link-error", type=float, default=1e-2,
                   help="fail when a link length is off 1/N by more than this fraction (default 1e-2)")
    p.add_argument("--max-energy-drift", type=float, default=None,
                   help="fail when |E(t) - E(0)| exceeds this (default: no bound)")
    p.add_argument("--dt-min", type=float, default=1e-14, help="fail when the adaptive step falls below this (default 1e-14)")
    p.add_argument("--max-rejections", type=int, default=100,
                   help="fail after more than this many consecutive rejected steps (default 100)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar (it is off anyway when not a tty)")
    p.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    _add_si_options(p)
    p.set_defaults(func=_cmd_simulate)


def _cmd_simulate(args) -> int:
    from . import simulate, units
    from ._validate import SnappingInputError

    scales = _si_scales(args)
    try:
        times = [float(v) for v in args.snapshot_times.split(",") if v.strip()]
    except ValueError:
        raise SnappingInputError(f"--snapshot-times={args.snapshot_times!r} is not a comma-separated list of times")
    if times and args.output is None and args.resume is None:  # snapshots are profiles: only a run file holds them
        from .simulate.options import _times

        _times(times)  # a bad time is named first
        raise SnappingInputError(f"--snapshot-times={args.snapshot_times!r} without -o RUN.nc: the snapshots are "
                                 f"profiles kept only in the run file; add -o RUN.nc (or leave out --snapshot-times)")
    progress = False if args.no_progress else None
    start_given = args.chi is not None or args.supports is not None or args.shape is not None
    if args.resume is None and (not start_given or args.N is None):
        raise SnappingInputError("the arguments --chi (or --supports/--shape) and --N are required (or --resume RUN.nc)")
    problem = None
    if args.resume is None:
        from .simulate.problem import from_options

        taper = None if args.taper is None else _numbers("--taper", args.taper.replace(":", ","), 1, 2)
        supports = None if args.supports is None else _numbers("--supports", args.supports, 2, 2)
        problem = from_options(chi=args.chi, N=args.N, chords=args.chords, supports=supports, shape=args.shape,
                               tip_mass=args.tip_mass, taper=taper, lumping=args.lumping,
                               pin_motion=args.pin_motion, gravity=args.gravity)
    try:
        if args.resume is not None:
            expect = _resume_expect(args, times)
            try:
                result = simulate.resume(args.resume, output=args.output, progress=progress,
                                         checkpoint_every=args.checkpoint_every, overwrite=args.overwrite,
                                         expect=expect)
            except simulate.driver.ResumeMismatch as exc:
                opt = "--" + exc.key.replace("_", "-")
                raise simulate.driver.ResumeMismatch(exc.key, _given_text(args, exc.key), exc.stored, exc.path,
                                                     option=opt) from None
            args.output = result.path
            args.chi, args.N = float(result.dataset.attrs["chi"]), int(result.dataset.attrs["N"])
            if str(result.dataset.attrs.get("initial")) == "problem":
                problem = True
        else:
            result = simulate.run(
                problem if problem is not None else args.chi, None if problem is not None else args.N, tol=args.tol, method=args.method, dt0=args.dt0, t_end=args.t_end,
                stop_fraction=args.stop_fraction, snapshot_times=times, record_thin=args.record_thin,
                chords=args.chords if problem is None else None, output=args.output, progress=progress, max_link_error=args.max_link_error,
                max_energy_drift=args.max_energy_drift, dt_min=args.dt_min, max_rejections=args.max_rejections,
                checkpoint_every=args.checkpoint_every, overwrite=args.overwrite,
            )
        summary, failed = result.summary(), None
    except simulate.RunInterrupted as exc:
        how = (f"resume with: {simulate.driver._resume_command(exc.path)}" if exc.path
               else "nothing was saved (no -o RUN.nc)")
        print(f"snapping simulate: {exc.args[0].split(';')[0]}; {how}", file=sys.stderr)
        return exc.exit_status
    except simulate.SimulationError as exc:
        summary, failed = simulate.summary(exc.dataset), exc
    if args.output:
        summary["output"] = args.output
    bad = _nonfinite(summary)
    if bad and failed is None:  # a completed run whose results are not numbers: not a result
        where = f" (the run file is {args.output})" if args.output else ""
        return _nonfinite_error("simulate", bad, where)
    reached = summary.get("snap_reached", True)
    if args.json:
        print_json(_with_si(summary, scales, lambda: {"values": units.values_to_si(summary, scales)}))
    else:
        note_units = {"wall_time": "s"}
        precise = ("t_snap_v", "t_snap_a", "t_snap_sigma", "v_peak", "a_peak", "sigma_peak", "kappa_peak")
        rows = []
        for k, v in summary.items():
            if k in ("snap_note", "peaks"):
                continue
            note = note_units.get(k)
            if v is None and k in precise:
                v, note = "absent", ("no snap reached" if not reached else "its peak is at the run's last step")
            elif k in ("v_peak", "a_peak", "sigma_peak", "kappa_peak") and not reached:
                note = "maximum over the run, not a snap peak"
            rows.append((k, f"{v:.10g}" if k in precise and isinstance(v, float) else v, note))
        print_table(
            rows,
            title=f"snapping simulate: chi={args.chi:g}, N={args.N}" if problem is None else
            f"snapping simulate: N={args.N}, {_problem_title(summary)}",
        )
        if not reached and summary.get("snap_note"):
            print(f"  note: {summary['snap_note']}")
        _print_si(scales, units.si_rows(summary, scales) if scales else [])
    if failed is not None:
        print(f"snapping simulate: error: {failed}", file=sys.stderr)
        return 1
    return 0


# ----------------------------------------------------------------------------- fit
#: simulate options that define the run (with --resume: checked against the checkpoint)
_RUN_OPTIONS = ("chi", "N", "tol", "method", "dt0", "t_end", "stop_fraction", "snapshot_times", "record_thin",
                "chords", "max_link_error", "max_energy_drift", "dt_min", "max_rejections")
#: simulate options that define the problem: never with --resume (the checkpoint holds its problem)
_PROBLEM_OPTIONS = ("tip_mass", "taper", "lumping", "supports", "shape", "pin_motion", "gravity")


def _given_text(args, key: str) -> str:
    return str(getattr(args, key))


def _resume_expect(args, times) -> dict:
    """The run inputs given on the command line with --resume (explicitly typed), to be
    checked against the checkpoint; a problem option is refused outright."""
    from ._validate import SnappingInputError

    given = getattr(args, "_explicit", set())
    for key in _PROBLEM_OPTIONS:
        if key in given:
            opt = "--" + key.replace("_", "-")
            raise SnappingInputError(f"{opt} {getattr(args, key)} cannot be given with --resume: the checkpoint "
                                     f"{args.resume!r} holds its problem (a resumed run continues the stored run)")
    expect = {k: getattr(args, k) for k in _RUN_OPTIONS if k in given}
    if "snapshot_times" in expect:
        expect["snapshot_times"] = times
    return expect


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

    from . import scaling, units
    from ._validate import SnappingInputError

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
        from .simulate.dataset import check_writable

        if Path(args.plot).suffix.lower() not in (".png", ".pdf", ".svg"):
            raise SnappingInputError(f"--plot={args.plot!r}: the figure suffix must be .png, .pdf or .svg")
        out = Path(args.plot)
        for path in (out, out.with_name(f"{out.stem}_slopes{out.suffix}"), out.with_name(f"{out.stem}_delta{out.suffix}")):
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
        return (f"method {a.get('method', '?')}, chords {a.get('chords', '?')}, tol {a.get('tol', '?')}; "
                f"units: nondimensional (length L, mass M, time sqrt(L/g), force M g)")

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
        print_table(scaling.report_rows(res), title="Exponents y ~ A (t* - t)^beta")
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
        print_table(scaling.summary_rows(results), title="Exponents per run (t* = t*_chi)")
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


# --------------------------------------------------------------------------- sweep
def _numbers(option: str, text: str, lo: int, hi: int) -> list[float]:
    """Comma-separated numbers of an option (lo to hi of them), or SnappingInputError naming it."""
    from ._validate import SnappingInputError

    try:
        vals = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        vals = []
    if not lo <= len(vals) <= hi:
        raise SnappingInputError(f"{option}={text!r} must be {lo}{'' if lo == hi else f' to {hi}'} comma-separated "
                                 f"numbers")
    return vals


def _floats(text: str) -> list[float]:
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a comma-separated list of numbers") from None


def _ints(text: str) -> list[int]:
    try:
        return [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a comma-separated list of integers") from None


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
            "  snapping sweep --chi 0.1,0.25 --N 200,500 --scheduler tcp://scheduler.example.org:8786 -o sweep_cluster"
        ),
    )
    p.add_argument("--chi", type=_floats, required=True, help="comma-separated end separations in (0, 1)")
    p.add_argument("--N", type=_ints, required=True, help="comma-separated numbers of links")
    p.add_argument("--tol", type=float, default=None,
                   help="stepper tolerance (default: the method's, fast 1e-6 and euler-richardson 1e-8)")
    p.add_argument("--method", default=None,
                   help="time-stepping method: fast (default), dop853, euler-richardson, euler-richardson-fixed")
    p.add_argument("--chords", default=None, choices=["exact", "arclength"],
                   help="initial nodes with exact chords 1/N (default) or at equal arclength (the paper's)")
    p.add_argument("--workers", type=int, default=None, help="local worker processes (default: all cores)")
    p.add_argument("--scheduler", default=None, help="address of a running Dask scheduler")
    p.add_argument("--ensemble", type=int, default=None, metavar="K",
                   help="run up to K chi of one N together in one ensemble kernel (needs --method fast or dop853)")
    p.add_argument("-o", "--output", required=True, help="output directory")
    p.add_argument("--overwrite", action="store_true",
                   help="replace DIR/sweep.nc even if it holds another grid's runs (default: refuse)")
    p.add_argument("--json", action="store_true", help="print the per-run results as one JSON object")
    _add_si_options(p)
    p.set_defaults(func=_cmd_sweep)


def _cmd_sweep(args) -> int:
    from pathlib import Path

    from . import sweep, units

    scales = _si_scales(args)
    options = {k: v for k, v in (("tol", args.tol), ("method", args.method), ("chords", args.chords))
               if v is not None}
    grid = sweep.Grid(chi=args.chi, N=args.N, options=options)
    target = sweep.check_combined(Path(args.output) / "sweep.nc", grid, overwrite=args.overwrite)
    failed = None
    try:
        paths = sweep.run_sweep(grid, args.output, workers=args.workers, scheduler=args.scheduler,
                                progress=sys.stderr.isatty(), ensemble=args.ensemble)
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
                row.update({k: float(sel[k]) for k in ("v_peak", "a_peak", "sigma_peak", "t_snap_v") if k in sel})
                reached = float(sel["snap_reached"]) if "snap_reached" in sel else 1.0
                row["snap_reached"] = bool(reached == 1.0)
                if not row["snap_reached"]:
                    row["t_snap_v"] = None  # absent: the run ended before the snap
                rows.append(row)
    bad = _nonfinite({"runs": rows})
    if args.json:
        obj = {"sweep": None if out is None else str(out), "runs": rows}
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
            "  snapping converge --chi 0.25 --lumping paper      # the paper's lumping: first order\n"
            "  snapping converge --chi 0.25 --length 1.022 --mass 0.0208   # the limits in SI too\n"
            "\n"
            "With -o DIR every level's run file is kept there and a rerun reuses the finished levels."
        ),
    )
    p.add_argument("--chi", type=float, required=True, help="end separation / length, in (0, 1)")
    p.add_argument("--levels", type=int, default=4, help="refinement levels (default 4; >= 4 for an error bar)")
    p.add_argument("--ratio", type=float, default=0.5, help="length scales' factor per level (default 0.5)")
    p.add_argument("--first", type=int, default=0,
                   help="index of the coarsest level (default 0: fold links 4%% of its radius; -1: 8%%)")
    p.add_argument("--lumping", default="shared", choices=["shared", "paper"], help="node masses (default shared)")
    p.add_argument("--free-end", default=None, choices=["half", "whole"],
                   help="mass of the free-end node: its share of the last link (shared's) or all of it")
    p.add_argument("--tol", type=float, default=1e-7, help="tolerance of the fast method (default 1e-7)")
    p.add_argument("--workers", type=int, default=1, help="levels run in parallel (default 1)")
    p.add_argument("-o", "--output", default=None, metavar="DIR", help="keep the levels' run files here")
    p.add_argument("--plot", default=None, metavar="PATH", help="draw the convergence figure (.png, .pdf, .svg)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing --plot file (default: refuse it)")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    _add_si_options(p)
    p.set_defaults(func=_cmd_converge)


def _cmd_converge(args) -> int:
    from . import continuum, units

    scales = _si_scales(args)
    if args.plot is not None:
        from ._validate import SnappingInputError
        from .simulate.dataset import check_writable

        try:
            check_writable(args.plot, name="plot", overwrite=args.overwrite, need_bytes=PLOT_BYTES)
        except SnappingInputError as exc:
            raise SnappingInputError(f"--plot {args.plot!r}: {exc}") from None
    res = continuum.converge(args.chi, levels=args.levels, ratio=args.ratio, first=args.first, lumping=args.lumping,
                             free_end=args.free_end, tol=args.tol, output=args.output, workers=args.workers,
                             progress=None if not args.json else False)
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
    return 0


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
    from .reproduce import reproduce
    from .sweep import SweepFailed

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
            "GIF through Pillow (always available); MP4 needs ffmpeg on PATH. A run with few\n"
            "snapshots up to the snap gets a note with the command for a denser run\n"
            "(--snapshot-times geometric in the time to the snap)."
        ),
        epilog=(
            "examples (run.nc from e.g. snapping simulate --chi 0.25 --N 200 -o run.nc):\n"
            "  snapping animate run.nc -o snap.gif\n"
            "  snapping animate run.nc -o snap.gif --max-frames 30 --fps 5\n"
            "  snapping animate run.nc -o snap.mp4 --fps 12 --overwrite"
        ),
    )
    p.add_argument("file", metavar="RUN.nc", help="run file (snapping simulate -o)")
    p.add_argument("-o", "--output", required=True, help="animation file: .gif or .mp4")
    p.add_argument("--fps", type=float, default=8.0, help="frames per second (default 8)")
    p.add_argument("--max-frames", type=int, default=None, help="at most this many frames (snapshots thinned evenly)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing output (default: refuse it)")
    p.set_defaults(func=_cmd_animate)


def _cmd_animate(args) -> int:
    from . import animation
    from .simulate import load_run

    animation.check_output(args.output, overwrite=args.overwrite)  # before reading the run
    ds = load_run(args.file)
    animation.frames_of(ds, args.max_frames)  # no snapshots: refused here
    hint = animation.denser_run_hint(ds, args.file)
    if hint:
        print(f"snapping animate: note: {hint}", file=sys.stderr)
    out = animation.animate(ds, args.output, fps=args.fps, max_frames=args.max_frames, overwrite=args.overwrite)
    n = len(animation.frames_of(ds, args.max_frames))
    print(f"wrote {out}: {n} frames at {args.fps:g} fps")
    return 0


# ---------------------------------------------------------------------------- main
def build_parser() -> argparse.ArgumentParser:
    """The ``snapping`` command's parser, with one subparser per subcommand.

    >>> build_parser().parse_args(["estimate", "--chi", "0.25"]).chi
    0.25
    """
    from . import __version__

    parser = _Parser(
        prog="snapping",
        formatter_class=_formatter,
        description=(
            "snapping: the physics of snapping in flexible bodies (falling chains, whips).\n"
            "Exact folded-string results, design-rule estimates, a compiled chain simulator\n"
            "and scaling analysis."
        ),
        epilog=(
            "examples:\n"
            "  snapping ideal --digits 30          # t* = 2E(pi/4|2) and the exponents\n"
            "  snapping estimate --chi 0.25 --links 229   # how big will the spike be?\n"
            "  snapping design --max-tension 20 --length 2 --mass 0.05 --links 100\n"
            "  snapping simulate --chi 0.25 --N 500 -o run.nc\n"
            "  snapping fit run.nc --plot fit.png  # exponents near the snap\n"
            "  snapping reproduce --quick -o out   # every claim and figure of the paper\n"
            "  snapping <command> --help           # each command's options and examples"
        ),
    )
    parser.add_argument("--version", action="version", version=f"snapping {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="<command>", parser_class=_Parser)
    for add in (_add_ideal, _add_estimate, _add_design, _add_simulate, _add_sweep, _add_fit, _add_converge, _add_reproduce,
                _add_animate):
        add(sub)
    return parser


#: library parameters that come from inside an option's value (named after the option)
_PART_OF = {"simulate": {"ratio": "--taper", "power": "--taper", "accel": "--pin-motion", "period": "--pin-motion",
                         "duration": "--pin-motion", "t0": "--pin-motion", "dx": "--supports", "dy": "--supports"}}


def _as_typed(parser, command: str, msg: str) -> str:
    """The library's message with its parameter names as the user typed them (``t_end=`` ->
    ``--t-end=``; ``ratio=`` of --taper -> ``--taper ratio=``)."""
    import re

    try:
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices[command]
    except (StopIteration, KeyError):
        return msg
    names = {}
    for a in sub._actions:
        longs = [o for o in a.option_strings if o.startswith("--")]
        si_own = command in _SI_COMMANDS and a.dest in _SI_DESTS  # (their messages name the options)
        if longs and a.dest not in ("help", "json", "overwrite") and not si_own:  # (overwrite: named both ways)
            names[a.dest] = longs[0]
    after = r"(?=[=\[]| contains| grid)"
    for dest, opt in sorted(names.items(), key=lambda kv: -len(kv[0])):
        msg = re.sub(rf"(?<![\w.\-]){re.escape(dest)}{after}", opt, msg)
    for name, opt in _PART_OF.get(command, {}).items():
        if opt not in msg:
            msg = re.sub(rf"(?<![\w.\-]){re.escape(name)}{after}", f"{opt} {name}", msg, count=1)
    return msg


def main(argv: list[str] | None = None) -> int:
    """Run the ``snapping`` command on ``argv`` (default: ``sys.argv[1:]``); returns the exit status
    (0 done, 1 numerical failure or I/O fault, 2 bad input, 130 or 143 interrupted by SIGINT or SIGTERM)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return EXIT_BAD_INPUT
    args._explicit = _explicit_dests(argv)
    try:
        return int(args.func(args) or 0)
    except ValueError as exc:  # SnappingInputError and friends: one line, exit 2
        print(f"snapping {args.command}: error: {_as_typed(parser, args.command, str(exc))}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print(f"snapping {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader of stdout went away (`snapping ... | head`): stop quietly
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # (no second error at exit)
        return 141
    except OSError as exc:  # an I/O fault while working (a full disk, a vanished path): one line, exit 1
        what = "" if type(exc).__name__ == "OutputWriteError" else "I/O error: "
        print(f"snapping {args.command}: error: {what}{exc}", file=sys.stderr)
        return EXIT_FAILED


def _explicit_dests(argv) -> set[str]:
    """The options typed on the command line ``argv`` (not defaulted), as argparse dests."""
    parser = build_parser()

    def suppress(p):
        for action in p._actions:
            if isinstance(action, argparse._SubParsersAction):
                for sp in action.choices.values():
                    suppress(sp)
            elif action.dest != "help":
                action.default = argparse.SUPPRESS

    suppress(parser)
    return set(vars(parser.parse_args(argv)))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
