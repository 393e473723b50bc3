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


def wants_3d(args) -> bool:
    return args.dims == 3 or args.perturb is not None or args.whirl is not None


#: planar-only options, refused with a 3D run (name, value that means 'not given')
_PLANAR_ONLY = (("resume", None), ("record_thin", 0.0), ("dt0", None), ("max_energy_drift", None))


def cmd_simulate3d(args, times) -> int:
    from .._validate import SnappingInputError
    from ..spatial import Problem3D
    from ..spatial.dataset3d import run3d_dataset
    from ..spatial.starts3d import planar_body

    if args.dims == 2:
        raise SnappingInputError("--dims 2 with --perturb or --whirl: an out-of-plane perturbation or a whirl is 3D; "
                                 "use --dims 3 (or leave --dims out)")
    for key, off in _PLANAR_ONLY:
        if getattr(args, key) != off:
            raise SnappingInputError(f"--{key.replace('_', '-')} {getattr(args, key)} has no 3D form yet "
                                     f"(a 3D run: --dims 3, --perturb, --whirl)")
    if getattr(args, "length", None) is not None or getattr(args, "mass", None) is not None:
        raise SnappingInputError("--length/--mass (results in SI) have no 3D form yet: a 3D run reports "
                                 "nondimensional numbers")
    if args.method not in ("fast", "dop853"):
        raise SnappingInputError(f"--method {args.method}: a 3D run is stepped by DOP853 (fast or dop853)")
    if args.N is None:
        raise SnappingInputError("the argument --N is required")
    from ._body import body_from_args

    body = body_from_args(args)  # (bending, damping, drag, a 3D wind: snapping.spatial.forces3d)
    if args.whirl is not None:
        if args.chi is not None or args.supports is not None or args.shape is not None:
            raise SnappingInputError("--whirl starts from the steady whirling shape: give no --chi/--supports/--shape")
        from ._body import line_links
        from ..simulate.problem import from_options

        from ..simulate.links import Links

        given = from_options(chi=0.5, N=args.N, tip_mass=args.tip_mass, lumping=args.lumping,
                             taper=None if args.taper is None else _taper(args), links=line_links(args))
        links = Links.uniform(args.N) if given is None else given.links
        problem = Problem3D.whirling(args.whirl, args.N, links=links, gravity=args.gravity, body=body)
    else:
        if args.chi is None and args.supports is None and args.shape is None:
            raise SnappingInputError("the arguments --chi (or --supports/--shape, or --whirl) and --N are required")
        from ._body import attach_body, line_links
        from ._common import _numbers
        from ..simulate.problem import from_options

        supports = None if args.supports is None else _numbers("--supports", args.supports, 2, 2)
        planar = from_options(chi=args.chi, N=args.N, chords=args.chords, supports=supports, shape=args.shape,
                              tip_mass=args.tip_mass, taper=None if args.taper is None else _taper(args),
                              lumping=args.lumping, pin_motion=args.pin_motion, gravity=args.gravity,
                              links=line_links(args))
        if planar is None:  # the paper's problem
            from ..simulate.problem import Problem

            planar = Problem.catenary(args.chi, args.N, chords=args.chords)
        if body is not None:  # (the planar problem places the start; the body in space keeps its 3D wind)
            planar = attach_body(planar, planar_body(body), args)
        problem = Problem3D.from_planar(planar, body=body if body is None or body.clamp is None else planar.body)
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
    if args.json:
        print_json(summary)
    else:
        rows = [(k, f"{v:.10g}" if isinstance(v, float) and math.isfinite(v) else v, "s" if k == "wall_time" else None)
                for k, v in summary.items()]
        print_table(rows, title=f"snapping simulate --dims 3: N={args.N}, start={problem.start.get('kind')}")
    if summary["status"] != "completed":
        import sys

        print(f"snapping simulate: error: the 3D run failed: {summary['stop_reason']}", file=sys.stderr)
        return 1
    return 0


def _taper(args):
    from ._common import _numbers

    return _numbers("--taper", args.taper.replace(":", ","), 1, 2)
