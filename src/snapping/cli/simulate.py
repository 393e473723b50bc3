"""The subcommand ``simulate``: one run of the chain, from its start to the snap (or resumed
from a checkpoint)."""

from __future__ import annotations

import sys

from ._common import (_add_si_options, _dimensionless, _formatter, _nonfinite, _nonfinite_error, _numbers,
                      _print_dimensionless, _print_si, _si_scales, _with_si, print_json, print_table)


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
            "  rodas4, stiff           linearly implicit, L-stable RODAS4 with banded O(N) solves: lines with\n"
            "                          bending stiffness (a body), whose bending waves limit dop853's steps\n"
            "  fast                    always the project's best exact method (the default): dop853, or\n"
            "                          rodas4 for a body whose damped bending waves make dop853 stiff\n"
            "  rodas4-links            the extensible line only (--ea/--stretching/...): RODAS4 in link\n"
            "                          coordinates, steps not capped by the wave speed\n"
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
            "  snapping simulate --chi 0.25 --N 300 --bending 1e-4 --drag-normal 2 --drag-tangential 0.04\n"
            "  snapping simulate --chi 0.3 --N 200 --bending 1e-3 --clamped 0 --wind 0.5,0 --t-end 1  # held out\n"
            "  snapping simulate --chi 0.3 --N 40 --bending 1e-3 --drag-normal 2 --method rodas4 --drag-jacobian correct\n"
            "  snapping simulate --chi 0.25 --N 200 --length 2 --mass 0.02 --ei 1e-3 --diameter 1e-3  # SI body\n"
            "  snapping simulate --chi 0.25 --N 200 --line fly-line   # a real line (snapping.lines)\n"
            "\n"
            "the extensible, tension-only line (links go slack; Radau on the banded Jacobian):\n"
            "  snapping simulate --chi 0.25 --N 60 --stretching 30 --grid-damping 1  # c = 30 sqrt(gL)\n"
            "  snapping simulate --chi 0.25 --N 60 --length 2 --mass 0.5 --ea 900 --damping 2  # SI: N, N s\n"
            "  snapping simulate --chi 0.25 --N 60 --length 2 --mass 0.5 --strain-table rope.csv -o run.nc\n"
            "  snapping simulate --chi 0.25 --N 60 --stretching 30 --method rodas4 --checkpoint ck.nc -o run.nc\n"
            "  snapping simulate --chi 0.25 --N 60 --stretching 30 --method rodas4 --checkpoint ck.nc -o run.nc --resume\n"
            "\n"
            "in space (snapping.spatial; --dims 3, implied by --perturb and --whirl):\n"
            "  snapping simulate --dims 3 --chi 0.25 --N 200 -o run3d.nc   # a planar start, run in 3D\n"
            "  snapping simulate --chi 0.25 --N 200 --perturb 1e-4          # out-of-plane kick sin(pi s/L)\n"
            "  snapping simulate --chi 0.25 --N 200 --perturb 1e-4 --perturb-mode random --seed 1\n"
            "  snapping simulate --whirl 2.5 --N 30 --t-end 7.5             # a steadily whirling chain\n"
            "\n"
            "With -o the run is checkpointed to its file every --checkpoint-every seconds; Ctrl-C\n"
            "(SIGINT) or SIGTERM stops it at a step boundary, saves it and prints the command that\n"
            "resumes it (exit status 130 or 143). A resumed run gives the same file, bit for bit.\n"
            "The extensible line's run (--ea/--stretching/--strain-table) writes -o when it ends;\n"
            "with --method rodas4 or rodas4-links and --checkpoint FILE.nc it keeps a checkpoint there\n"
            "(every --checkpoint-every seconds, and on Ctrl-C or SIGTERM, exit status 130 or 143), which\n"
            "the same command with --resume added continues, bit for bit; without --checkpoint an\n"
            "interrupted one writes nothing. A checkpoint is never replaced by another run, and one of\n"
            "other options is refused, naming the option that differs.\n"
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
                   choices=["fast", "dop853", "rodas4", "stiff", "euler-richardson", "euler-richardson-fixed",
                            "rodas4-links"],
                   help="time stepper (default: fast; every method is listed below)")
    p.add_argument("--drag-jacobian", default=None, choices=["banded", "correct"],
                   help="--method rodas4 (stiff) on a line with drag: its stage solves on the banded Jacobian, "
                        "which leaves the drag out (banded, the default), or corrected once per stage for it "
                        "(correct: one evaluation and one banded solve more per stage, far fewer steps when drag "
                        "dominates); recorded in the run file and kept by --resume")
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
    p.add_argument("--start", default=None, choices=("catenary", "equilibrium"),
                   help="the shape the line hangs in, held at both ends at rest, before its free end is released "
                        "(--chi or --supports): the catenary, or the static equilibrium of the chain and its body "
                        "(with bending the heavy elastica); default: the equilibrium when the line bends, else "
                        "the catenary")
    from ._body import add_body_options

    add_body_options(p)
    from ._elastic import add_elastic_options

    add_elastic_options(p)
    p.add_argument("-o", "--output", default=None,
                   help="write the run to this netCDF4 file: .nc, .nc4 or .netcdf (a new path, or --overwrite)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing -o file (default: refuse it)")
    p.add_argument("--resume", metavar="RUN.nc", default=None, nargs="?", const=True,
                   help="continue the interrupted or checkpointed run in this file (written back to it, or to -o); "
                        "the extensible line: its --checkpoint file (the same command, with --resume added)")
    p.add_argument("--checkpoint-every", type=float, default=300.0, metavar="SECONDS",
                   help="with -o (the extensible line: with --checkpoint): save the run's full state every this "
                        "many seconds (default 300; 0: very often)")
    p.add_argument("--checkpoint", metavar="FILE.nc", default=None,
                   help="the extensible line (--method rodas4 or rodas4-links): keep its checkpoint in this new file "
                        "(saved on Ctrl-C/SIGTERM and every --checkpoint-every seconds; -o gets the finished run)")
    p.add_argument("--max-link-error", type=float, default=1e-2,
                   help="fail when a link length is off 1/N by more than this fraction (default 1e-2)")
    p.add_argument("--max-energy-drift", type=float, default=None,
                   help="fail when |E(t) - E(0)| exceeds this (default: no bound)")
    p.add_argument("--dt-min", type=float, default=1e-14, help="fail when the adaptive step falls below this (default 1e-14)")
    p.add_argument("--max-rejections", type=int, default=100,
                   help="fail after more than this many consecutive rejected steps (default 100)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar (it is off anyway when not a tty)")
    p.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    from .simulate3d import add_3d_options

    add_3d_options(p)
    _add_si_options(p)
    p.set_defaults(func=_cmd_simulate)


def _cmd_simulate(args) -> int:
    from .. import simulate, units
    from .._validate import SnappingInputError

    scales = _si_scales(args)
    if args.output is not None:  # (a run file is netCDF4: never under a name that says another format)
        from .._files import netcdf_suffix

        netcdf_suffix(args.output, name="--output")
    try:
        times = [float(v) for v in args.snapshot_times.split(",") if v.strip()]
    except ValueError:
        raise SnappingInputError(f"--snapshot-times={args.snapshot_times!r} is not a comma-separated list of times")
    from ._elastic import is_elastic

    rigid_resume = args.resume is not None and not is_elastic(args)  # (its run file holds the snapshots)
    if times and args.output is None and not rigid_resume:  # snapshots are profiles: only a run file holds them
        from ..simulate.options import _times

        _times(times)  # a bad time is named first
        raise SnappingInputError(f"--snapshot-times={args.snapshot_times!r} without -o RUN.nc: the snapshots are "
                                 f"profiles kept only in the run file; add -o RUN.nc (or leave out --snapshot-times)")
    from ._elastic import check_rigid_checkpoint, elastic_from_args

    elastic = elastic_from_args(args, scales)  # (None: the rigid-link chain)
    if elastic is None:
        check_rigid_checkpoint(args)
    _check_drag_jacobian(args, elastic)
    if elastic is None and args.method == "rodas4-links":
        raise SnappingInputError("--method rodas4-links steps the extensible line only: give --ea, --stretching or "
                                 "--strain-table (the rigid chain's methods: fast, dop853, rodas4, stiff, "
                                 "euler-richardson)")
    from .simulate3d import cmd_simulate3d, wants_3d

    if wants_3d(args):  # the chain in space (snapping.spatial)
        return cmd_simulate3d(args, times, scales)
    progress = False if args.no_progress else None
    start_given = args.chi is not None or args.supports is not None or args.shape is not None
    if elastic is not None and (not start_given or args.N is None):  # (a resumed one: checked against them)
        raise SnappingInputError("the arguments --chi (or --supports/--shape) and --N are required by the extensible "
                                 "line's run, also with --resume (its checkpoint is checked against them)")
    if args.resume is None and (not start_given or args.N is None):
        raise SnappingInputError("the arguments --chi (or --supports/--shape) and --N are required (or --resume RUN.nc)")
    problem = None
    if args.resume is None or elastic is not None:
        from ..simulate.problem import from_options

        taper = None if args.taper is None else _numbers("--taper", args.taper.replace(":", ","), 1, 2)
        supports = None if args.supports is None else _numbers("--supports", args.supports, 2, 2)
        from ._body import attach_body, body_from_args, line_links

        problem = from_options(chi=args.chi, N=args.N, chords=args.chords, supports=supports, shape=args.shape,
                               tip_mass=args.tip_mass, taper=taper,
                               lumping=args.lumping or ("shared" if elastic is not None else None),
                               pin_motion=args.pin_motion, gravity=args.gravity, links=line_links(args))

        body = body_from_args(args)
        if elastic is not None:  # (the line's body, if any, rides on the extensible line: simulate.elastic_body)
            return _simulate_elastic(args, problem if body is None else problem.with_body(body), elastic, times, scales)
        if body is not None or args.start is not None:  # bending, drag, a clamp: a general problem (simulate.body)
            problem = attach_body(problem, body, args)
    try:
        if args.resume is not None:
            expect = _resume_expect(args, times)
            try:
                result = simulate.resume(args.resume, output=args.output, progress=progress,
                                         checkpoint_every=args.checkpoint_every, overwrite=args.overwrite,
                                         expect=expect)
            except simulate.resuming.ResumeMismatch as exc:
                opt = "--" + exc.key.replace("_", "-")
                raise simulate.resuming.ResumeMismatch(exc.key, _given_text(args, exc.key), exc.stored, exc.path,
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
                drag_jacobian=args.drag_jacobian or "banded",
            )
        summary, failed = result.summary(), None
    except simulate.RunInterrupted as exc:
        how = (f"resume with: {simulate.driver._resume_command(exc.path)}" if exc.path
               else "nothing was saved (no -o RUN.nc)")
        print(f"snapping simulate: {exc.args[0].split(';')[0]}; {how}", file=sys.stderr)
        return exc.exit_status
    except simulate.SimulationError as exc:
        summary, failed = simulate.summary(exc.dataset), exc
        if args.resume is not None:  # the stored run's chi and N (not given with --resume), for the title
            args.chi, args.N = summary.get("chi"), summary.get("N")
            if args.chi is None or str(exc.dataset.attrs.get("initial")) == "problem":
                problem = True
    if args.output:
        summary["output"] = args.output
    from ._body import body_si_inputs, si_summary

    body_si = si_summary(body_si_inputs(args)) if args.resume is None else None
    if body_si:
        summary["body_si"] = body_si  # the SI inputs the body's numbers ("body") were made from
    if getattr(args, "line_obj", None) is not None and args.resume is None:
        summary["line"] = args.line_obj.name  # (snapping.lines: the catalogue's line, as overridden)
    bad = _nonfinite(summary)
    if bad and failed is None:  # a completed run whose results are not numbers: not a result
        where = f" (the run file is {args.output})" if args.output else ""
        return _nonfinite_error("simulate", bad, where)
    reached = summary.get("snap_reached", True)
    numbers = _dimensionless(scales, args, N=args.N, tip_mass=args.tip_mass) if args.resume is None else None
    if args.json:
        print_json(_with_si(summary, scales, lambda: {"values": units.values_to_si(summary, scales),
                                                      **({"dimensionless_numbers": numbers} if numbers else {})}))
    else:
        note_units = {"wall_time": "s"}
        precise = ("t_snap_v", "t_snap_a", "t_snap_sigma", "v_peak", "a_peak", "sigma_peak", "kappa_peak")
        rows = []
        for k, v in summary.items():
            if k in ("snap_note", "peaks", "body", "body_si", "compression_note"):
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
        if summary.get("compression_note"):
            print(f"  note: {summary['compression_note']}")
        _print_body(summary)
        _print_si(scales, units.si_rows(summary, scales) if scales else [])
        _print_dimensionless(numbers)
    if failed is not None:
        print(f"snapping simulate: error: {failed}", file=sys.stderr)
        return 1
    return 0


def _check_drag_jacobian(args, elastic) -> None:
    """--drag-jacobian correct where it cannot apply, refused naming the option, its value and where
    it does: the stage solves of --method rodas4 (stiff) on the rigid chain (or of --method fast where
    it takes rodas4: the library's check). ``banded``, the default, is what every other run does."""
    from .._validate import SnappingInputError
    from .simulate3d import wants_3d

    if getattr(args, "drag_jacobian", None) in (None, "banded"):
        return
    why = None
    if elastic is not None:
        why = "the extensible line (--ea/--stretching/--strain-table) has no drag (no body options are built for it)"
    elif wants_3d(args):
        why = "a 3D run (--dims 3, --perturb, --whirl) is stepped by DOP853, which has no stage solves"
    elif args.resume is None and args.method in ("dop853", "euler-richardson", "euler-richardson-fixed"):
        why = f"--method {args.method} is explicit and has no stage solves"
    if why is not None:
        raise SnappingInputError(f"--drag-jacobian {args.drag_jacobian}: {why}; the choices are banded (the "
                                 f"default, every method) and correct (--method rodas4 or stiff on the rigid chain "
                                 f"with a body, where drag enters its stage solves): leave out --drag-jacobian")


def _simulate_elastic(args, problem, elastic, times, scales) -> int:
    """The extensible line's run (snapping.simulate.elastic): its summary, -o its Dataset."""
    from .. import units
    from ._elastic import run_elastic

    from ..simulate.errors import RunInterrupted

    try:
        summary, ds = run_elastic(args, problem, elastic, times)
    except RunInterrupted as exc:  # (saved in its --checkpoint file: the same words as the rigid chain's)
        from ._elastic import resume_command

        print(f"snapping simulate: {exc.args[0].split(';')[0]}; resume with: {resume_command(args, exc.path)}",
              file=sys.stderr)
        return exc.exit_status
    if args.output:
        summary["output"] = args.output
    if problem.body is not None:  # (the line's body on the extensible line: its numbers, and the SI they came from)
        import json

        from ..simulate.body import summarize
        from ._body import body_si_inputs, si_summary

        summary["body"] = summarize(json.dumps(problem.body.describe(problem.links.h), sort_keys=True))
        body_si = si_summary(body_si_inputs(args))
        if body_si:
            summary["body_si"] = body_si
    numbers = _dimensionless(scales, args, N=args.N, tip_mass=args.tip_mass)
    if numbers is not None and "stretching" not in numbers:  # (--stretching or --strain-table: the run's c)
        from .. import dimensionless

        numbers = {k: (summary["wave_speed"] if k == "stretching" else numbers.get(k)) for k in dimensionless.NUMBERS
                   if k in numbers or k == "stretching"}
    if args.json:
        print_json(_with_si(summary, scales, lambda: {"values": units.values_to_si(summary, scales),
                                                      **({"dimensionless_numbers": numbers} if numbers else {})}))
    else:
        rows = [(k, f"{v:.10g}" if isinstance(v, float) else v, None) for k, v in summary.items()
                if k not in ("problem", "elastic", "body", "body_si")]
        rows.append(("elastic", summary["elastic"], "EA and damping in M g, M g sqrt(L/g)"))
        print_table(rows, title=f"snapping simulate (extensible line): N={args.N}, {_problem_title(summary)}")
        _print_body(summary)
        _print_si(scales, units.si_rows(summary, scales) if scales else [])
        _print_dimensionless(numbers)
    if summary["status"] != "completed":
        print(f"snapping simulate: error: {elastic_failure_words(summary, args.output)}", file=sys.stderr)
        return 1
    return 0


def elastic_failure_words(summary: dict, output) -> str:
    """What a failed extensible-line run says: why (its stop reason, or, when it reached the snap,
    the peak guard's rules broken: its peaks are not resolved) and where the run was kept."""
    note, why = summary.get("peak_note") or "", summary.get("stop_reason") or "unknown"
    if why == "snap" and note:
        head = f"the extensible line's run reached the snap, but its peaks are not resolved (peak guard: {note})"
    else:
        head = f"the extensible line's run failed: {why}" + (f" (peak guard: {note})" if note else "")
    kept = (f"; the run is written to {output} with status 'failed'" if output
            else "; the summary above is the failed run's")
    return head + kept


def _print_body(summary) -> None:
    """The body's nondimensional numbers (and the SI inputs they were made from) under the table."""
    body = summary.get("body")
    if not body:
        return
    from ._body import BODY_NOTES

    rows = [(f"body: {k}", v if not isinstance(v, list) else ", ".join(f"{x:.6g}" for x in v), BODY_NOTES.get(k))
            for k, v in body.items()]
    for k, q in (summary.get("body_si") or {}).items():
        rows.append((f"  from SI: {k}", q["value"] if not isinstance(q["value"], list) else
                     ", ".join(f"{x:.6g}" for x in q["value"]), q["units"]))
    print_table(rows)


# ------------------------------------------------------------------ --resume
#: simulate options that define the run (with --resume: checked against the checkpoint)
_RUN_OPTIONS = ("chi", "N", "tol", "method", "dt0", "t_end", "stop_fraction", "snapshot_times", "record_thin",
                "chords", "max_link_error", "max_energy_drift", "dt_min", "max_rejections", "drag_jacobian")
#: simulate options that define the problem: never with --resume (the checkpoint holds its problem)
_PROBLEM_OPTIONS = ("tip_mass", "taper", "lumping", "supports", "shape", "pin_motion", "gravity", "bending", "damping",
                    "drag_normal", "drag_tangential", "drag_linear", "wind", "tip_drag", "clamp", "ei", "diameter",
                    "air_density", "cd_normal", "cd_tangential", "tip_drag_area", "wind_si", "line")


def _given_text(args, key: str) -> str:
    return str(getattr(args, key))


def _resume_expect(args, times) -> dict:
    """The run inputs given on the command line with --resume (explicitly typed), to be
    checked against the checkpoint; a problem option is refused outright."""
    from .._validate import SnappingInputError

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
