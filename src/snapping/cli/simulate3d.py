"""``snapping simulate --dims 3`` (or an option only 3D has: ``--perturb``, ``--whirl``): one run
of the chain in space (:mod:`snapping.spatial`), thin over :func:`snapping.spatial.dataset3d.run3d_dataset`."""

from __future__ import annotations

import math

from ._common import print_json, print_table

#: the 3D results printed after the planar ones
_KEYS = ("N", "chi", "method", "tol", "status", "stop_reason", "snap_reached", "t_snap_v", "t_snap_a", "t_snap_sigma",
         "v_peak", "a_peak", "sigma_peak", "z_amp_snap", "vz_amp_snap", "z_amp_max", "energy_drift",
         "angular_momentum_drift", "link_error_max", "t_final", "n_steps", "n_rejected", "n_rhs", "wall_time")


def add_3d_options(p) -> None:
    """The options of a 3D run (``simulate``'s parser)."""
    p.add_argument("--dims", type=int, default=None, choices=[2, 3],
                   help="space dimensions: 3 runs the chain in space (snapping.spatial; implied by --perturb, --whirl)")
    p.add_argument("--perturb", type=float, default=None, metavar="EPS",
                   help="3D: add the out-of-plane start velocity EPS phi(s) (mode --perturb-mode)")
    p.add_argument("--perturb-mode", default="sin", choices=["sin", "random", "modes"],
                   help="3D: phi = sin(K pi s/L) (default), random node values, or 8 sine modes with random "
                        "coefficients (--seed), max 1")
    p.add_argument("--perturb-k", type=int, default=1, metavar="K", help="3D: the mode number K of --perturb-mode sin")
    p.add_argument("--perturb-kind", default="velocity", choices=["velocity", "shape"],
                   help="3D: perturb the start velocity (default) or the shape (displaced by EPS L phi(s), exact chords)")
    p.add_argument("--seed", type=int, default=None, help="3D: seed of --perturb-mode random or modes")
    p.add_argument("--whirl", type=float, default=None, metavar="OMEGA",
                   help="3D: start whirling at the rate OMEGA about the vertical through the held end (steady shape)")
    p.add_argument("--spin-up", default=None, metavar="RAMP[,RADIUS]",
                   help="3D, with --whirl: instead of the steady shape, start hanging at rest and drive the held end "
                        "around a horizontal circle (radius RADIUS, default 0.05) at the rate ramped to OMEGA over RAMP")
    p.add_argument("--g-dir", default=None, metavar="X,Y,Z",
                   help="3D: gravity's unit direction (default 0,1,0: y downward, as the planar runs)")
    p.add_argument("--pin-axis", default=None, metavar="X,Y,Z",
                   help="3D: the unit axis of --pin-motion circle:R,OMEGA[,RAMP[,T0]] (default 0,1,0: a horizontal "
                        "circle); 3D --pin-motion also takes pull3d:AX,AY,AZ[,DURATION[,T0]], "
                        "flick3d:AX,AY,AZ,PERIOD[,T0] and table:FILE.csv (columns t, x, y, z)")


#: options only a 3D run has (any of them makes the run 3D)
_ONLY_3D = ("perturb", "whirl", "spin_up", "g_dir", "pin_axis")


def wants_3d(args) -> bool:
    spec = str(getattr(args, "pin_motion", None) or "")
    if args.dims == 3 or any(getattr(args, k, None) is not None for k in _ONLY_3D):
        return True
    if spec.split(":")[0].strip() in ("pull3d", "flick3d", "circle", "table"):
        return True
    if getattr(args, "shape", None) is not None and args.dims != 2:  # (a curve in space: x, y, z columns)
        from ..spatial.shape3d import is_3d_shape

        return is_3d_shape(args.shape)
    return False


#: planar-only options, refused with a 3D run (name, value that means 'not given')
_PLANAR_ONLY = (("resume", None), ("record_thin", 0.0), ("dt0", None), ("max_energy_drift", None))


def _problem3d(args):
    """The :class:`snapping.spatial.Problem3D` of the options (every input checked before any run)."""
    from .._validate import SnappingInputError
    from ..spatial import Problem3D
    from ..spatial.held3d import parse_pin3d
    from ..spatial.starts3d import planar_body
    from ._body import body_from_args, line_links
    from ._common import _numbers
    from ..simulate.links import Links
    from ..simulate.problem import from_options

    if args.dims == 2:
        raise SnappingInputError("--dims 2 with an option only 3D has (--perturb, --whirl, --spin-up, --g-dir, "
                                 "--pin-axis, a 3D --pin-motion): use --dims 3 (or leave --dims out)")
    g_dir = (0.0, 1.0, 0.0) if args.g_dir is None else tuple(_numbers("--g-dir", args.g_dir, 3, 3))
    axis = None if args.pin_axis is None else tuple(_numbers("--pin-axis", args.pin_axis, 3, 3))
    pin = parse_pin3d(args.pin_motion, axis)
    body = body_from_args(args)  # (bending, damping, drag, a 3D wind: snapping.spatial.forces3d)
    kw = {"g_dir": g_dir} if body is None else {"g_dir": g_dir, "body": body}
    if args.spin_up is not None and args.whirl is None:
        raise SnappingInputError(f"--spin-up {args.spin_up} needs --whirl OMEGA (the rate it spins up to)")

    def chain_links():  # (the chain's options without a start: tip mass, taper, lumping, --line)
        given = from_options(chi=0.5, N=args.N, tip_mass=args.tip_mass, lumping=args.lumping,
                             taper=None if args.taper is None else _taper(args), links=line_links(args))
        return Links.uniform(args.N) if given is None else given.links

    if args.whirl is not None:
        if args.chi is not None or args.supports is not None or args.shape is not None:
            raise SnappingInputError("--whirl starts from the whirling shape (or, with --spin-up, hanging): give no "
                                     "--chi/--supports/--shape")
        if g_dir != (0.0, 1.0, 0.0) or args.pin_motion not in (None, "", "fixed"):
            raise SnappingInputError("--whirl is about the vertical through a held end it drives itself: give no "
                                     "--g-dir or --pin-motion")
        if args.spin_up is not None:
            ramp, *rad = _numbers("--spin-up", args.spin_up, 1, 2)
            return Problem3D.spun_up(args.whirl, args.N, ramp=ramp, radius=rad[0] if rad else 0.05,
                                     links=chain_links(), gravity=args.gravity, **kw)
        return Problem3D.whirling(args.whirl, args.N, links=chain_links(), gravity=args.gravity, **kw)
    if args.chi is None and args.supports is None and args.shape is None:
        raise SnappingInputError("the arguments --chi (or --supports/--shape, or --whirl) and --N are required")
    if args.shape is not None:
        from ..spatial.shape3d import read_shape3d

        if args.chi is not None or args.supports is not None:
            raise SnappingInputError("--shape is the start: give no --chi/--supports with it")
        problem = Problem3D.curve(read_shape3d(args.shape), links=chain_links(), name=str(args.shape),
                                  gravity=args.gravity, **kw)
        return problem.with_pin(pin)
    from ._body import attach_body

    supports = None if args.supports is None else _numbers("--supports", args.supports, 2, 2)
    planar = from_options(chi=args.chi, N=args.N, chords=args.chords, supports=supports, shape=None,
                          tip_mass=args.tip_mass, taper=None if args.taper is None else _taper(args),
                          lumping=args.lumping, pin_motion=None, gravity=args.gravity, links=line_links(args))
    if planar is None:  # the paper's problem
        from ..simulate.problem import Problem

        planar = Problem.catenary(args.chi, args.N, chords=args.chords)
    if body is not None:  # (the planar problem places the start; the body in space keeps its 3D wind)
        planar = attach_body(planar, planar_body(body), args)
        kw["body"] = body if body.clamp is None else planar.body
    return Problem3D.from_planar(planar, **kw).with_pin(pin)


def cmd_simulate3d(args, times, scales=None) -> int:
    from .._validate import SnappingInputError
    from ..spatial.dataset3d import run3d_dataset

    for key, off in _PLANAR_ONLY:
        if getattr(args, key) != off:
            raise SnappingInputError(f"--{key.replace('_', '-')} {getattr(args, key)} has no 3D form yet "
                                     f"(a 3D run: --dims 3, --perturb, --whirl)")
    if args.method not in ("fast", "dop853"):
        raise SnappingInputError(f"--method {args.method}: a 3D run is stepped by DOP853 (fast or dop853)")
    if args.N is None:
        raise SnappingInputError("the argument --N is required")
    problem = _problem3d(args)
    if args.perturb is not None:
        problem = problem.perturbed(args.perturb, args.perturb_mode, seed=args.seed, k=args.perturb_k,
                                    kind=args.perturb_kind)
    tol = 1e-8 if args.tol is None else args.tol
    ds = run3d_dataset(problem, tol=tol, t_end=args.t_end, stop_fraction=args.stop_fraction, snapshot_times=times,
                       output=args.output, overwrite=args.overwrite, max_link_error=min(args.max_link_error, 1e-6))
    summary = {k: ds.attrs[k] for k in _KEYS}
    summary = {k: (v.item() if hasattr(v, "item") else v) for k, v in summary.items()}
    summary["dims"] = 3
    if problem.body_active:
        from ..simulate.body import summarize

        summary["body"] = summarize(ds.attrs["body"])
        summary["dissipated"] = float(ds["dissipated"].values[-1])
    if args.output:
        summary["output"] = args.output
    from .. import units
    from ._common import _print_si, _with_si

    if args.json:
        print_json(_with_si(summary, scales, lambda: {"values": units.values_to_si(summary, scales)}))
    else:
        rows = [(k, f"{v:.10g}" if isinstance(v, float) and math.isfinite(v) else v, "s" if k == "wall_time" else None)
                for k, v in summary.items()]
        print_table(rows, title=f"snapping simulate --dims 3: N={args.N}, start={problem.start.get('kind')}")
        _print_si(scales, units.si_rows(summary, scales) if scales else [])
    if summary["status"] != "completed":
        import sys

        print(f"snapping simulate: error: the 3D run failed: {summary['stop_reason']}", file=sys.stderr)
        return 1
    return 0


def _taper(args):
    from ._common import _numbers

    return _numbers("--taper", args.taper.replace(":", ","), 1, 2)
