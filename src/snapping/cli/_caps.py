"""The real line's options of ``snapping estimate`` and ``snapping design``: answers from runs
of the real model (:mod:`snapping.caps`) when --line or any physical parameter is given."""

from __future__ import annotations

from ._common import _print_dimensionless, print_json

#: option dest -> the keyword of snapping.caps.spec
REAL_KEYS = ("line", "ei", "ea", "diameter", "cd_normal", "cd_tangential", "air_density", "end_mass", "tip_drag_area")


#: the links of a real line's runs (snapping.caps.cap's N)
LINKS_RANGE = (2, 20000)


def add_real_options(p, resolve: bool = True) -> None:
    g = p.add_argument_group(
        "a real line (answers from runs of the real model: snapping.caps; any of these turns it on)",
        "the ideal chain's answer beside it, the factor, and the mechanism that capped the snap")
    g.add_argument("--line", default=None, metavar="NAME",
                   help="a real line of the catalogue (ball-chain, nylon-monofilament, fly-line, bullwhip, "
                        "climbing-rope, bungee-cord); every value overridable by the options below")
    g.add_argument("--ei", type=float, default=None, metavar="N_M2", help="bending stiffness EI in N m^2")
    g.add_argument("--ea", type=float, default=None, metavar="NEWTONS", help="axial stiffness EA in N (stretching)")
    g.add_argument("--diameter", type=float, default=None, metavar="METERS", help="diameter in m (air drag)")
    g.add_argument("--cd-normal", type=float, default=None, metavar="CN",
                   help="cross-flow drag coefficient, on d per length (default: the --line's, else 1.2)")
    g.add_argument("--cd-tangential", type=float, default=None, metavar="CT",
                   help="skin-friction coefficient, on pi d per length (default: the --line's, else 0.01)")
    g.add_argument("--air-density", type=float, default=None, metavar="KG_M3", help="air density in kg/m^3 (1.2)")
    g.add_argument("--end-mass", type=float, default=None, metavar="KG", help="a point mass at the free end, kg")
    g.add_argument("--tip-drag-area", type=float, default=None, metavar="M2",
                   help="drag area C_d A of the free end's tip body in m^2")
    g.add_argument("--combined", action="store_true",
                   help="where a line with bending or drag stretches and its stretching factor does not settle "
                        "on uniform links (the climbing rope), answer from the combined model on graded links "
                        "(snapping.caps_combined: minutes of CPU per chi; default: stretching left out, and said)")
    if resolve:
        g.add_argument("--resolve", action="store_true",
                       help="double the links from 100 (to 1600 at most) until the peak of --quantity moves by at "
                            "most 1%%, or graded links (instead of --links; the default without --links since "
                            "designres; a chain of discrete links, --line ball-chain: its own)")
    g.add_argument("--quantity", default="sigma_peak", choices=("sigma_peak", "v_peak", "a_peak"),
                   help="the peak that decides the capping mechanism (default the tension)")


def wants_real(args) -> bool:
    """Whether the real model answers (--line or a physical parameter given)."""
    return any(getattr(args, k, None) is not None for k in REAL_KEYS)


#: options that only a real line's answer takes (refused, not ignored, for the ideal chain's table)
REAL_ONLY = (("quantity", "--quantity"), ("resolve", "--resolve"), ("chis", "--chis"), ("combined", "--combined"))


def refuse_real_only(args) -> None:
    """Refuse an option of a real line's answer given without a real line (--line or a physical
    parameter): the ideal chain's table would silently ignore it."""
    from .._validate import SnappingInputError

    explicit = getattr(args, "_explicit", None)  # (the options typed: main sets it)
    for dest, opt in REAL_ONLY:
        value = getattr(args, dest, None)
        typed = dest in explicit if explicit is not None else value != "sigma_peak"
        if typed and value not in (None, False):
            raise SnappingInputError(f"{opt} is a real line's option: give it with --line NAME or a physical "
                                     f"parameter (--ei, --ea, --diameter, ...); the ideal chain's table has no use "
                                     f"for it")


def _links(args):
    """--links of a real line's runs, checked and named as typed (None: not given)."""
    from .._validate import integer

    return None if args.links is None else integer("links", args.links, *LINKS_RANGE)


def _spec(args):
    from .. import caps

    kw = {k: getattr(args, k) for k in REAL_KEYS if k != "line" and getattr(args, k, None) is not None}
    for k in ("length", "mass"):
        if getattr(args, k, None) is not None:
            kw[k] = getattr(args, k)
    return caps.spec(args.line, g=args.g, **kw)


def _chi(args, sp) -> float:
    from .._validate import SnappingInputError, real
    from ..estimates.catenary import CHI_MIN

    if getattr(args, "curvature", None) is not None:
        raise SnappingInputError("--curvature is not taken with a real line: give --chi or --separation METERS")
    if getattr(args, "separation", None) is not None:
        sep = real("separation", args.separation)
        chi = sep / sp.length
        if not CHI_MIN <= chi < 1.0:
            raise SnappingInputError(f"--separation={sep!r} m is out of range: must lie in the open interval "
                                     f"(0, {sp.length:g}) m, below the line's length (chi = separation/length = "
                                     f"{chi:g} must lie in (0, 1))")
        return chi
    return args.chi


def cmd_real_estimate(args) -> int:
    from .. import caps
    from .._validate import SnappingInputError

    for opt in ("simulate", "table"):
        if getattr(args, opt, False):
            raise SnappingInputError(f"--{opt} is for the ideal chain's table; a real line is always run")
    if args.N is not None:
        raise SnappingInputError("--N is the ideal estimators' option: give --links for a real line's runs")
    if args.tip_mass:
        raise SnappingInputError(f"--tip-mass {args.tip_mass:g} is a ratio for the ideal chain; give --end-mass KG")
    links = _links(args)
    sp = _spec(args)
    if args.resolve and links is not None:
        raise SnappingInputError("--resolve chooses the links itself: give --resolve or --links, not both")
    N = "auto" if args.resolve else links  # (None: caps.cap's "auto", a line of discrete links its own)
    r = caps.cap(sp, _chi(args, sp), N=N, quantity=args.quantity, combined=args.combined)
    if args.json:
        print_json({**r, "dimensionless_numbers": r["numbers"]})
    else:
        print("\n".join(caps.format_answer(r)))
        _print_dimensionless(r["numbers"])
    return 0


def cmd_real_design(args) -> int:
    from .. import caps
    from .._validate import SnappingInputError

    if args.plot is not None:
        raise SnappingInputError("--plot is drawn from the ideal chain's table; a real line's design prints its rows")
    if args.tip_mass is not None:
        raise SnappingInputError(f"--tip-mass {args.tip_mass:g} is a ratio for the ideal chain; give --end-mass KG")
    if getattr(args, "resolve", False):
        raise SnappingInputError("--resolve is snapping estimate's: give --links for a design")
    links = _links(args)
    sp = _spec(args)
    kw = {} if args.chis is None else {"chis": args.chis}
    d = caps.design(sp, N=links, max_tension=args.max_tension,
                    max_speed=args.max_speed, max_acceleration=args.max_acceleration,
                    quantity=getattr(args, "quantity", "sigma_peak"), combined=args.combined, **kw)
    if args.json:
        print_json({**d, "dimensionless_numbers": d["numbers"]})
    else:
        print("\n".join(caps.format_design(d)))
        _print_dimensionless(d["numbers"])
    return 0
