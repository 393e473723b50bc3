"""Command-line options of a line's body (bending stiffness, damping, drag, wind, a clamped
held end) for ``snapping simulate``: :class:`snapping.simulate.Body`, nondimensional (SI
options later). The option dests are the Body's parameter names, so that its messages name
the options as typed (``bending=-1`` -> ``--bending=-1``)."""

from __future__ import annotations

BODY_DESTS = ("bending", "damping", "drag_normal", "drag_tangential", "drag_linear", "wind", "tip_drag", "clamp")


def add_body_options(p) -> None:
    g = p.add_argument_group("the line's body (nondimensional; any of them makes a general problem, method fast)")
    g.add_argument("--bending", type=float, default=0.0, metavar="B",
                   help="bending stiffness EI in units of lambda g L^3 (default 0: a chain)")
    g.add_argument("--bending-damping", dest="damping", type=float, default=0.0, metavar="ETA",
                   help="Kelvin-Voigt bending damping (moment per curvature rate; default 0)")
    g.add_argument("--drag-normal", type=float, default=0.0, metavar="CN",
                   help="quadratic normal air drag per length, units of lambda/L (terminal speed 1/sqrt(CN))")
    g.add_argument("--drag-tangential", type=float, default=0.0, metavar="CT",
                   help="quadratic tangential (skin friction) drag per length, units of lambda/L")
    g.add_argument("--drag-linear", default=None, metavar="KN[,KT]",
                   help="linear (Stokes) drag per length, normal [and tangential], units of lambda sqrt(g/L)")
    g.add_argument("--wind", default=None, metavar="WX,WY",
                   help="uniform wind velocity (y downward), units of sqrt(gL)")
    g.add_argument("--tip-drag", type=float, default=0.0, metavar="CD",
                   help="body drag of the free end's tip body, force CD |u| u, units of M/L")
    g.add_argument("--clamped", dest="clamp", nargs="?", const="start", default=None, metavar="ANGLE",
                   help="clamp the held end at ANGLE (radians, the direction the line leaves it, from +x towards "
                        "+y downward; no ANGLE: the start's direction); needs --bending")


def body_from_args(args):
    """The :class:`Body` of the options, or None when none was given."""
    from .._validate import SnappingInputError
    from ..simulate import Body
    from ._common import _numbers

    if all(getattr(args, k, None) in (None, 0.0) for k in BODY_DESTS):
        return None
    kw = {}
    for k in ("bending", "damping", "drag_normal", "drag_tangential", "tip_drag"):
        kw[k] = getattr(args, k)
    if args.drag_linear is not None:
        v = _numbers("--drag-linear", args.drag_linear, 1, 2)
        kw["drag_linear_normal"] = v[0]
        kw["drag_linear_tangential"] = v[1] if len(v) > 1 else 0.0
        try:
            Body(drag_linear_normal=kw["drag_linear_normal"], drag_linear_tangential=kw["drag_linear_tangential"])
        except SnappingInputError as exc:
            raise SnappingInputError(f"--drag-linear={args.drag_linear!r}: {exc}") from None
    if args.wind is not None:
        try:
            w = [float(x) for x in args.wind.split(",")]
        except ValueError:
            raise SnappingInputError(f"--wind={args.wind!r} must be two comma-separated numbers WX,WY") from None
        kw["wind"] = w
    clamp = args.clamp
    if clamp is not None and clamp != "start":
        try:
            clamp = float(clamp)
        except ValueError:
            raise SnappingInputError(f"--clamped={args.clamp!r} must be an angle in radians (or no value: the "
                                     f"start's direction)") from None
    kw["clamp"] = clamp
    return Body(**kw)


def attach_body(problem, body, args):
    """The problem (None: the paper's, from --chi and --N) with the body of :func:`body_from_args`."""
    from ..simulate import Problem

    if problem is None:
        problem = Problem.catenary(args.chi, args.N, chords=args.chords)
    return problem.with_body(body)
