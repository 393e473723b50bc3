"""Command-line options of the extensible, tension-only line (:mod:`snapping.simulate.elastic`)
for ``snapping simulate``: in SI with --length/--mass (--ea N, --damping N s, --strain-table
CSV of strain and tension in N) or nondimensional (--stretching C = c/sqrt(gL),
--axial-damping in M g sqrt(L/g)). Every check is made before any work; a bad value is one
line naming the option (exit 2)."""

from __future__ import annotations

import math

#: the dests of the elastic options (any of them given: the elastic model)
ELASTIC_DESTS = ("ea", "stretching", "axial_damping_si", "axial_damping", "grid_damping", "strain_table")
#: simulate options the elastic model does not take (dest: why)
NOT_ELASTIC = {"record_thin": "--record-thin (it thins the rigid-link record)",
               "dt0": "--dt0 (it sets the rigid-link methods' first step)",
               "max_link_error": "--max-link-error (it checks rigid links)", "chords": "--chords",
               "max_energy_drift": "--max-energy-drift", "dt_min": "--dt-min", "max_rejections": "--max-rejections",
               "start": "--start (the bending line's start; the extensible line's is --elastic-start)"}
#: the extensible line's starts (--elastic-start; snapping.simulate.elastic_model.STARTS)
ELASTIC_STARTS = ("stretched", "matched", "unstretched")


#: the elastic solver's method for each --method (fast: Radau, the elastic line's default)
ELASTIC_METHOD = {"dop853": "dop853", "rodas4": "rodas4", "stiff": "rodas4", "radau": "radau",
                  "rodas4-links": "rodas4-links"}


def add_elastic_options(p) -> None:
    g = p.add_argument_group(
        "the extensible line (tension-only links: snapping.simulate.elastic; any of these runs it, with scipy's "
        "Radau on the banded Jacobian, or --method rodas4 (compiled) or dop853; released from its stretched "
        "equilibrium, or --elastic-start matched)",
        "SI with --length METERS --mass KG [--g]; or nondimensional: EA in M g, c = sqrt(EA/lambda) in sqrt(g L)")
    g.add_argument("--ea", type=float, default=None, metavar="N", help="axial stiffness EA in N (SI)")
    g.add_argument("--stretching", type=float, default=None, metavar="C",
                   help="axial stiffness as the wave speed c/sqrt(g L) of the uniform line (EA = c^2 M g)")
    g.add_argument("--damping", dest="axial_damping_si", type=float, default=None, metavar="N_S",
                   help="Kelvin-Voigt axial damping, N s (tension + damping x strain rate while taut; SI)")
    g.add_argument("--axial-damping", dest="axial_damping", type=float, default=None, metavar="ETA",
                   help="Kelvin-Voigt axial damping in units of M g sqrt(L/g)")
    g.add_argument("--grid-damping", dest="grid_damping", type=float, default=None, metavar="ZETA",
                   help="damping ratio of the shortest longitudinal mode (added Kelvin-Voigt damping; ~1 damps "
                        "the release's grid-scale ringing, the long waves by about ZETA pi/(4N))")
    g.add_argument("--elastic-start", dest="elastic_start", default=None, choices=ELASTIC_STARTS,
                   help="the extensible line's start: stretched (default: the static equilibrium with both ends "
                        "held, then one let go: its unloading wave rings along the line), matched (the start's "
                        "shape stretched to the rigid chain's tensions after release: no release wave, the rigid "
                        "chain's release as EA -> infinity) or unstretched (every link at its rest length)")
    g.add_argument("--strain-table", default=None, metavar="CSV",
                   help="tension-strain curve: rows strain,tension (tension in N with --length/--mass, else in "
                        "M g), strains increasing from 0; replaces --ea")


def _given(args) -> list[str]:
    return [d for d in ELASTIC_DESTS if getattr(args, d, None) is not None]


def is_elastic(args) -> bool:
    return bool(_given(args))


def _finite_positive(opt: str, v: float, what: str) -> float:
    from .._validate import SnappingInputError

    if not (math.isfinite(v) and v > 0.0):
        raise SnappingInputError(f"{opt}={v!r} is out of range: {what} must be finite and > 0")
    return v


def _read_table(path: str):
    from .._validate import SnappingInputError

    try:
        with open(path, encoding="utf-8") as fh:
            text = fh.read()
    except OSError as exc:
        raise SnappingInputError(f"--strain-table={path!r} cannot be read: {exc.strerror or exc}") from None
    e, t = [], []
    for k, line in enumerate(text.splitlines(), 1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        parts = [q.strip() for q in s.split(",")]
        try:
            a, b = (float(q) for q in parts)
        except ValueError:
            if not e and k == 1 or not e and all(not _isnum(q) for q in parts):
                continue  # a header line
            raise SnappingInputError(f"--strain-table={path!r} line {k}: {s[:40]!r} is not two comma-separated "
                                     f"numbers (strain,tension)") from None
        e.append(a)
        t.append(b)
    if len(e) < 1:
        raise SnappingInputError(f"--strain-table={path!r} has no rows strain,tension (CSV)")
    return e, t


def _isnum(q: str) -> bool:
    try:
        float(q)
        return True
    except ValueError:
        return False


def elastic_from_args(args, scales):
    """The :class:`~snapping.simulate.elastic.Elastic` of the options (None when none is given),
    after checking every one (SnappingInputError naming the option)."""
    from .._validate import SnappingInputError
    from ..simulate.elastic import Elastic

    given = _given(args)
    if not given:
        if getattr(args, "elastic_start", None) is not None:
            raise SnappingInputError(f"--elastic-start {args.elastic_start} is the extensible line's start: give it "
                                     f"with --ea, --stretching or --strain-table")
        return None
    if getattr(args, "method", None) in ("euler-richardson", "euler-richardson-fixed"):
        opt = "--" + given[0].replace("axial_damping_si", "damping").replace("_", "-")
        raise SnappingInputError(f"{opt} (the extensible line) with --method {args.method}: the paper's method steps "
                                 f"rigid links only; use --method fast (Radau) or dop853")
    for dest, why in NOT_ELASTIC.items():
        if dest in getattr(args, "_explicit", ()) and getattr(args, dest, None) not in (None, False):
            raise SnappingInputError(f"{why} cannot be given with the extensible line (--ea/--stretching/...)")
    if getattr(args, "method", None) not in (None, "fast", "dop853", "radau", "rodas4", "stiff", "euler-richardson",
                                             "euler-richardson-fixed", "rodas4-links"):
        opt = "--" + given[0].replace("axial_damping_si", "damping").replace("_", "-")
        raise SnappingInputError(f"--method {args.method} with {opt} (the extensible line): its methods are fast "
                                 f"(Radau on the banded Jacobian), rodas4 (or stiff: the compiled RODAS4), "
                                 f"rodas4-links (RODAS4 in link coordinates) and dop853")
    from ..simulate.elastic_body import BODY_METHODS
    from ._body import body_from_args
    from .simulate3d import wants_3d

    if hasattr(args, "dims") and wants_3d(args):
        raise SnappingInputError("the extensible line (--ea/--stretching/...) is planar: not with --dims 3, "
                                 "--perturb or --whirl")
    if body_from_args(args) is not None and ELASTIC_METHOD.get(getattr(args, "method", None), "radau") not in BODY_METHODS:
        raise SnappingInputError(f"--method {getattr(args, 'method', None)} does not carry the line's body (bending, drag, wind) on "
                                 f"the extensible line: its methods with a body are fast (Radau), dop853 and rodas4 "
                                 f"(or stiff)")
    n_stiff = sum(getattr(args, d) is not None for d in ("ea", "stretching", "strain_table"))
    if n_stiff != 1:
        raise SnappingInputError("give exactly one of --ea, --stretching and --strain-table (the axial stiffness)")
    if args.axial_damping is not None and args.axial_damping_si is not None:
        raise SnappingInputError("give --damping (N s) or --axial-damping (nondimensional), not both")
    need_si = [o for d, o in (("ea", "--ea"), ("axial_damping_si", "--damping")) if getattr(args, d) is not None]
    if need_si and scales is None:
        raise SnappingInputError(f"{need_si[0]} is in SI: it needs --length METERS and --mass KG (or use "
                                 f"{'--stretching' if need_si[0] == '--ea' else '--axial-damping'})")
    force = 1.0 if scales is None else scales.mass * scales.g
    damping = 0.0
    if args.axial_damping_si is not None or args.axial_damping is not None:
        opt, v = (("--damping", args.axial_damping_si) if args.axial_damping_si is not None
                  else ("--axial-damping", args.axial_damping))
        if not (math.isfinite(v) and v >= 0.0):
            raise SnappingInputError(f"{opt}={v!r} is out of range: the damping must be finite and >= 0")
        damping = v / (force * scales.time) if opt == "--damping" else v
    zeta = 0.0 if args.grid_damping is None else args.grid_damping
    if not (math.isfinite(zeta) and zeta >= 0.0):
        raise SnappingInputError(f"--grid-damping={zeta!r} is out of range: the damping ratio must be finite and >= 0")
    from ..simulate.elastic_model import EA_MAX

    if args.ea is not None:  # (the bound in the option's own unit: EA <= EA_MAX M g)
        ea = _finite_positive("--ea", args.ea, "the axial stiffness EA (N)")
        if not ea / force <= EA_MAX:
            raise SnappingInputError(f"--ea={ea!r} is out of range: the axial stiffness EA must lie in "
                                     f"(0, {EA_MAX * force:.4g}] N ({EA_MAX:g} times the line's weight M g)")
        return Elastic(ea=ea / force, damping=damping, grid_damping=zeta)
    if args.stretching is not None:
        c = _finite_positive("--stretching", args.stretching, "the wave speed c/sqrt(g L)")
        if not c * c <= EA_MAX:
            raise SnappingInputError(f"--stretching={c!r} is out of range: the wave speed c/sqrt(g L) must lie in "
                                     f"(0, {math.sqrt(EA_MAX):g}] (EA = c^2 M g at most {EA_MAX:g} M g)")
        return Elastic.from_wave_speed(c, damping=damping, grid_damping=zeta)
    e, t = _read_table(args.strain_table)
    try:
        return Elastic(table=(e, [v / force for v in t]), damping=damping, grid_damping=zeta)
    except SnappingInputError as exc:
        raise SnappingInputError(f"--strain-table={args.strain_table!r}: {exc}") from None


def elastic_start(args) -> str:
    """The extensible line's start of the options (--elastic-start; default "stretched")."""
    return getattr(args, "elastic_start", None) or "stretched"


#: the options of the stored inputs of an extensible-line checkpoint (elastic_checkpoint.read's keys)
MISMATCH_OPTIONS = {"N": "--N", "method": "--method", "tol": "--tol", "t_end": "--t-end",
                    "stop_fraction": "--stop-fraction", "snapshot_times": "--snapshot-times",
                    "start": "--elastic-start", "initial": "the start (--chi/--supports/--shape, --elastic-start)",
                    "elastic": "--ea/--stretching/--strain-table/--damping/--axial-damping/--grid-damping",
                    "problem": "the problem (--chi/--supports/--shape, --tip-mass, --taper, --pin-motion, "
                               "--gravity, ...)", "chi": "--chi", "tip_mass": "--tip-mass", "gravity": "--gravity",
                    "pin_motion": "--pin-motion"}


def check_rigid_checkpoint(args) -> None:
    """--checkpoint, and --resume without its file, are the extensible line's: refused for the
    rigid chain (whose run is checkpointed to its -o file and resumed by --resume RUN.nc)."""
    from .._validate import SnappingInputError

    if getattr(args, "checkpoint", None) is not None:
        raise SnappingInputError(f"--checkpoint {args.checkpoint} is the extensible line's (--ea/--stretching/"
                                 f"--strain-table): the rigid chain's run is checkpointed to its -o RUN.nc file "
                                 f"(every --checkpoint-every seconds) and continued by --resume RUN.nc")
    if args.resume is True:
        raise SnappingInputError("--resume needs the run file to continue, --resume RUN.nc (without a file it "
                                 "continues the extensible line's --checkpoint FILE)")


def _checkpoint_paths(args, method: str):
    """(checkpoint, resume, checkpoint_every) of the options for :func:`solve`, checked: only
    rodas4 and rodas4-links keep checkpoints; --resume alone continues --checkpoint's file;
    --checkpoint-every needs a checkpoint; neither file is -o."""
    import os

    from .._files import netcdf_suffix
    from .._validate import SnappingInputError
    from ..simulate import elastic_checkpoint as ECK

    ck, res = getattr(args, "checkpoint", None), args.resume
    for o, v in (("--checkpoint", ck), ("--resume", res)):
        if isinstance(v, str):  # (a checkpoint is a netCDF4 run file: never under a name that says another format)
            netcdf_suffix(v, name=o)
    given = [(o, v) for o, v in (("--checkpoint", ck), ("--resume", res)) if v is not None]
    if given and method not in ECK.METHODS:
        o, v = given[0]
        shown = o if v is True else f"{o} {v}"
        raise SnappingInputError(f"{shown} with --method {args.method} (the extensible line's {method}): only "
                                 f"--method rodas4 (or stiff) and rodas4-links keep checkpoints")
    if res is True:
        if ck is None:
            raise SnappingInputError("--resume without a file continues the extensible line's --checkpoint FILE: "
                                     "give --checkpoint FILE (or --resume FILE)")
        res = ck
    if ck is None and res is None:
        if "checkpoint_every" in getattr(args, "_explicit", ()):
            raise SnappingInputError(f"--checkpoint-every {args.checkpoint_every} needs --checkpoint FILE (the "
                                     f"extensible line's checkpoint; its run file -o is written when it ends)")
        return None, None, None
    if args.output is not None:
        for o, v in (("--checkpoint", ck), ("--resume", res)):
            if v is not None and os.path.realpath(v) == os.path.realpath(args.output):
                raise SnappingInputError(f"{o} {v} and -o {args.output} name the same file: the checkpoint and the "
                                         f"finished run are kept apart; choose another -o or --checkpoint path")
    return ck, res, args.checkpoint_every


def resume_command(args, path) -> str:
    """The command that continues this interrupted run: the one given, its --checkpoint and
    --resume replaced by ``--checkpoint PATH --resume``.

    Built from the command line as argparse parsed it (parsed again from ``args._argv``, not from
    its words), so any spelling argparse accepts is dropped or kept alike: an abbreviation
    (``--res``, ``--resu FILE``), ``--checkpoint=FILE``, ``--resume=FILE``, an option given
    twice (the last counts). Every other option typed is kept (the resume checks the stored run
    against them, and -o, --overwrite, --checkpoint-every, --json, --no-progress act again), in
    the parser's order and its long spelling; a value that starts with '-' is written
    ``--option=VALUE``."""
    import argparse
    import shlex

    from . import _explicit_dests, build_parser

    argv = list(getattr(args, "_argv", None) or [])
    parser = build_parser()
    ns = parser.parse_args(argv)
    typed = _explicit_dests(argv)
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices[ns.command]
    out = [ns.command]
    for a in sub._actions:
        if a.dest in ("help", "checkpoint", "resume") or a.dest not in typed or not a.option_strings:
            continue
        opt = next((o for o in a.option_strings if o.startswith("--")), a.option_strings[0])
        v = getattr(ns, a.dest)
        if a.nargs == 0:  # (store_true: typed, so on)
            out.append(opt)
        elif a.nargs == "?" and v == a.const:
            out.append(opt)
        else:
            text = str(v)
            out.extend([f"{opt}={text}"] if text.startswith("-") or a.nargs == "?" else [opt, text])
    return "snapping " + shlex.join(out + ["--checkpoint", str(path), "--resume"])


def mismatch_words(exc, args) -> str:
    """A refused checkpoint's message in the command line's words: the options that differ."""
    opt = MISMATCH_OPTIONS.get(exc.key, exc.key)
    return (f"{opt} contradicts the checkpoint {exc.path!r}: its run has {exc.key}={exc.stored!r}, this command "
            f"{exc.key}={exc.given!r}; a resumed run continues the stored run: give the interrupted run's options, "
            f"or another --checkpoint path to start a new run")


def run_elastic(args, problem, elastic, times):
    """Solve (with --checkpoint: checkpointed, or continued with --resume), write -o, and return
    (summary, dataset). -o is checked before the run and locked while it lasts."""
    import contextlib

    from .. import _files
    from .._validate import SnappingInputError
    from ..simulate import elastic_checkpoint as ECK
    from ..simulate.elastic import solve

    method = ELASTIC_METHOD.get(args.method, "radau")
    ck, res, every = _checkpoint_paths(args, method)
    out = None
    if args.output is not None:
        out = _files.check_output(args.output, overwrite=args.overwrite)
    args._elastic_running = True  # (an interruption outside solve's loop: main says what was kept)
    with _files.locked(out) if out is not None else contextlib.nullcontext():
        if out is not None:
            _files.check_output(out, overwrite=args.overwrite)  # (again, under the lock)
        try:
            r = solve(problem, elastic, t_end=args.t_end, tol=1e-6 if args.tol is None else args.tol,
                      method=method, stop_fraction=args.stop_fraction, snapshot_times=times,
                      start=elastic_start(args), checkpoint=ck, resume=res, checkpoint_every=every,
                      progress=False if getattr(args, "no_progress", False) else None)
        except ECK.CheckpointMismatch as exc:
            raise SnappingInputError(mismatch_words(exc, args)) from None
        if out is not None:  # (SIGINT/SIGTERM held while the finished run is written, then raised: ECK.Signals)
            ds = r.dataset
            with ECK.Signals():
                _files.write_atomic(out, lambda tmp: ds.to_netcdf(tmp), overwrite=True, dataset=ds)
    return r.summary(), r.dataset
