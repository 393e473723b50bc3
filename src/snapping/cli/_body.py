"""Command-line options of a line's body (bending stiffness, damping, drag, wind, a clamped
held end) for ``snapping simulate``, ``sweep`` and ``converge``: :class:`snapping.simulate.Body`,
nondimensional, or in SI with --length/--mass (--ei, --diameter, --air-density, --cd-normal,
--cd-tangential, --tip-drag-area, --wind-si: :func:`snapping.units.body_numbers`). The option
dests are the Body's parameter names, so that its messages name the options as typed
(``bending=-1`` -> ``--bending=-1``)."""

from __future__ import annotations

BODY_DESTS = ("bending", "damping", "drag_normal", "drag_tangential", "drag_linear", "wind", "tip_drag", "clamp")
#: what each of the body's summary numbers is (snapping.simulate.body.summarize)
BODY_NOTES = {"beta": "bending number B/(lambda g L^3)", "bending_damping": "units of lambda g L^3 sqrt(L/g)",
              "curvature": "natural curvature, units of 1/L",
              "drag_normal": "c_n: force per length c_n |u_n| u_n, units of lambda/L (terminal speed 1/sqrt(c_n))",
              "drag_tangential": "c_t: force per length c_t |u_t| u_t, units of lambda/L",
              "drag_linear_normal": "units of lambda sqrt(g/L)", "drag_linear_tangential": "units of lambda sqrt(g/L)",
              "wind": "units of sqrt(g L)", "tip_drag": "c_d: tip force c_d |u| u, units of M/L",
              "clamp": "held end clamped (angle in radians)"}
#: the SI options (dest: the keyword of snapping.units.body_numbers, SI units, the nondimensional option it replaces)
SI_BODY = {"ei": ("ei", "N m2", "--bending"), "diameter": ("diameter", "m", "--drag-normal/--drag-tangential"),
           "air_density": ("air_density", "kg m-3", None), "cd_normal": ("cd_normal", "1", None),
           "cd_tangential": ("cd_tangential", "1", None), "tip_drag_area": ("tip_drag_area", "m2", "--tip-drag"),
           "wind_si": ("wind", "m s-1", "--wind")}


def add_body_options(p) -> None:
    g = p.add_argument_group("the line's body (nondimensional; any of them makes a general problem, method fast)")
    g.add_argument("--bending", type=float, default=0.0, metavar="B",
                   help="bending stiffness EI in units of lambda g L^3 (default 0: a chain)")
    g.add_argument("--bending-damping", dest="damping", type=float, default=0.0, metavar="ETA",
                   help="Kelvin-Voigt bending damping (moment per curvature rate), units of lambda g L^3 sqrt(L/g) "
                        "(default 0)")
    g.add_argument("--drag-normal", type=float, default=0.0, metavar="CN",
                   help="quadratic normal air drag per length, units of lambda/L (terminal speed 1/sqrt(CN))")
    g.add_argument("--drag-tangential", type=float, default=0.0, metavar="CT",
                   help="quadratic tangential (skin friction) drag per length, units of lambda/L")
    g.add_argument("--drag-linear", default=None, metavar="KN[,KT]",
                   help="linear (Stokes) drag per length, normal [and tangential], units of lambda sqrt(g/L)")
    g.add_argument("--wind", default=None, metavar="WX,WY[,WZ]",
                   help="uniform wind velocity (y downward), units of sqrt(gL); WZ (out of the plane) with --dims 3")
    g.add_argument("--tip-drag", type=float, default=0.0, metavar="CD",
                   help="body drag of the free end's tip body, force CD |u| u, units of M/L")
    g.add_argument("--clamped", dest="clamp", nargs="?", const="start", default=None, metavar="ANGLE",
                   help="clamp the held end at ANGLE (radians, the direction the line leaves it, from +x towards "
                        "+y downward; no ANGLE: the start's direction); needs --bending")
    g.add_argument("--line", default=None, metavar="NAME",
                   help="a real line of the catalogue (snapping.lines: ball-chain, nylon-monofilament, fly-line, "
                        "bullwhip, climbing-rope, bungee-cord): its --length, --mass and SI body (and, with "
                        "simulate, its tapered masses and tip body); every value overridable by the options")
    si = p.add_argument_group(
        "the line's body in SI (with --length METERS --mass KG [--g]; the nondimensional numbers are printed)",
        "drag per length 0.5 rho C_n d |v_n| v_n (normal) and 0.5 rho C_t pi d |v_t| v_t (tangential); "
        "beta = EI/(lambda g L^3), lambda = M/L")
    si.add_argument("--ei", type=float, default=None, metavar="N_M2", help="bending stiffness EI in N m^2")
    si.add_argument("--diameter", type=float, default=None, metavar="METERS",
                    help="the line's diameter in m: air drag with --cd-normal and --cd-tangential")
    si.add_argument("--air-density", type=float, default=None, metavar="KG_M3",
                    help="air density in kg/m^3 (default 1.2)")
    si.add_argument("--cd-normal", type=float, default=None, metavar="CN",
                    help="cross-flow drag coefficient of the line, on d per length (default: the --line's, else 1.2, "
                         "a cylinder)")
    si.add_argument("--cd-tangential", type=float, default=None, metavar="CT",
                    help="skin-friction coefficient, on pi d per length (default: the --line's, else 0.01, an "
                         "estimate)")
    si.add_argument("--tip-drag-area", type=float, default=None, metavar="M2",
                    help="drag area C_d A of the free end's tip body in m^2 (a fly, a popper)")
    si.add_argument("--wind-si", default=None, metavar="WX,WY", help="uniform wind in m/s (y downward)")


#: the SI options a line fills (dest: the nondimensional options that replace it instead)
_LINE_TWINS = {"ei": ("bending",), "diameter": ("drag_normal", "drag_tangential"), "cd_normal": (),
               "cd_tangential": (), "tip_drag_area": ("tip_drag",)}


def apply_line(args):
    """Fill --length, --mass and the SI body options of ``args`` from --line NAME
    (:mod:`snapping.lines`) where they were not given (an option given, or its nondimensional
    twin, wins); returns the :class:`snapping.lines.Line` or None. A bad name lists the valid ones."""
    from .. import lines
    from .._validate import SnappingInputError

    name = getattr(args, "line", None)
    if name is None:
        return None
    try:
        line = lines.get(name)
    except SnappingInputError as exc:
        raise SnappingInputError(f"--{exc}") from None  # (its message starts with line=)
    if args.length is None:
        args.length = line.length
    if args.mass is None:
        try:
            args.mass = line.mass(args.length)
        except SnappingInputError as exc:
            raise SnappingInputError(f"--{exc}") from None
    si = line.si(args.length)
    for dest, twins in _LINE_TWINS.items():
        if dest not in si or getattr(args, dest, None) is not None:
            continue
        if any(getattr(args, t, None) not in (None, 0.0) for t in twins):
            continue
        if dest.startswith("cd_") and args.diameter is None:
            continue
        setattr(args, dest, si[dest])
    args.line_obj = line
    return line


def line_links(args):
    """The chain of --line where the line has a taper or a tip body (None otherwise, or when
    --taper/--tip-mass/--lumping were given: they win)."""
    line = getattr(args, "line_obj", None)
    if line is None or (line.taper is None and line.tip_mass == 0.0):
        return None
    if getattr(args, "taper", None) is not None or getattr(args, "tip_mass", 0.0) or getattr(args, "lumping", None):
        return None
    return line.links(args.N, args.length)


def refuse_line_masses(args, command: str) -> None:
    """``sweep`` and ``converge`` build their own uniform chains: a --line with a taper or a
    tip body would run without its masses, so it is refused (its body alone: the SI options)."""
    from .._validate import SnappingInputError

    line = getattr(args, "line_obj", None)
    if line is not None and (line.taper is not None or line.tip_mass):
        raise SnappingInputError(f"--line {line.name} has tapered masses or a tip body, which snapping {command} "
                                 f"does not build (uniform chains): use snapping simulate --line {line.name}, or "
                                 f"give its body with the SI options (--ei, --diameter, ...)")


def body_from_args(args):
    """The :class:`Body` of the options, or None when none was given."""
    from .._validate import SnappingInputError
    from ..simulate import Body
    from ._common import _numbers

    si = body_si_inputs(args)
    if all(getattr(args, k, None) in (None, 0.0) for k in BODY_DESTS) and si is None:
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
            raise SnappingInputError(f"--wind={args.wind!r} must be two comma-separated numbers WX,WY (three, "
                                     f"WX,WY,WZ, with --dims 3)") from None
        kw["wind"] = w
    clamp = args.clamp
    if clamp is not None and clamp != "start":
        try:
            clamp = float(clamp)
        except ValueError:
            raise SnappingInputError(f"--clamped={args.clamp!r} must be an angle in radians (or no value: the "
                                     f"start's direction)") from None
    kw["clamp"] = clamp
    if si is not None:
        kw.update(_si_numbers(args, si))
    body = Body(**kw)
    if any(body.wind) and body.tip_drag == 0.0 and all(
            body._zero(k) for k in ("drag_normal", "drag_tangential", "drag_linear_normal", "drag_linear_tangential")):
        # (the API's Body takes it, as an inactive body; on the command line it would be an option silently dropped)
        opt = "--wind-si" if args.wind is None else "--wind"
        raise SnappingInputError(f"{opt} needs drag: the wind acts on the line only through its drag (give "
                                 f"--drag-normal, --drag-tangential, --drag-linear or --tip-drag, or --diameter "
                                 f"or --tip-drag-area with --length and --mass)")
    return body


def body_si_inputs(args) -> dict | None:
    """The SI body options given (``{dest: value}``; --wind-si as two numbers), checked
    against their nondimensional twins and --length/--mass; None when none was given."""
    from .._validate import SnappingInputError
    from ._common import _numbers

    given = {k: getattr(args, k, None) for k in SI_BODY if getattr(args, k, None) is not None}
    if not given:
        return None
    opts = ", ".join("--" + k.replace("_", "-") for k in given)
    if getattr(args, "length", None) is None or getattr(args, "mass", None) is None:
        verb = "needs" if len(given) == 1 else "need"
        raise SnappingInputError(f"{opts} {verb} --length METERS and --mass KG: the line's body in SI is made "
                                 f"nondimensional with the chain's length and mass per length")
    twins = {"ei": ("bending",), "diameter": ("drag_normal", "drag_tangential"), "tip_drag_area": ("tip_drag",),
             "wind_si": ("wind",)}
    for k, dests in twins.items():
        for d in dests:
            if k in given and getattr(args, d, None) not in (None, 0.0):
                raise SnappingInputError(f"--{k.replace('_', '-')} and --{d.replace('_', '-')} give the same "
                                         f"thing twice (SI and nondimensional): give one of them")
    for k in ("cd_normal", "cd_tangential"):
        if k in given and "diameter" not in given:
            raise SnappingInputError(f"--{k.replace('_', '-')} needs --diameter METERS: the drag per length is "
                                     f"0.5 rho C d |v| v")
    if "air_density" in given and "diameter" not in given and "tip_drag_area" not in given:
        raise SnappingInputError("--air-density needs --diameter or --tip-drag-area (it only scales air drag)")
    if "wind_si" in given:
        given["wind_si"] = _numbers("--wind-si", given["wind_si"], 2, 2)
    return given


def _si_numbers(args, si: dict) -> dict:
    """The Body keywords of the SI options (snapping.units.body_numbers); a bad value names its option."""
    from .. import units
    from .._validate import SnappingInputError

    kw = {SI_BODY[k][0]: v for k, v in si.items()}
    try:
        out = units.body_numbers(args.length, args.mass, args.g, **kw)
    except SnappingInputError as exc:
        msg = str(exc)
        for k, (name, _, _) in SI_BODY.items():
            if msg.startswith(name + "=") or msg.startswith(name + " "):
                msg = "--" + k.replace("_", "-") + msg[len(name):]
                break
        else:
            if msg.startswith(("length=", "mass=", "g=")):
                msg = "--" + msg
        raise SnappingInputError(msg) from None
    made = {"ei": ("bending",), "diameter": ("drag_normal", "drag_tangential"), "tip_drag_area": ("tip_drag",),
            "wind_si": ("wind",)}
    kw = {d: out.get(d, 0.0) for k, dests in made.items() if k in si for d in dests}
    from ..simulate import Body

    for k, dests in made.items():  # the numbers in range (a huge EI makes a beta beyond the doubles' use)
        if k in si:
            try:
                Body(**{d: kw[d] for d in dests})
            except SnappingInputError as exc:
                raise SnappingInputError(f"--{k.replace('_', '-')}={args_text(si[k])} gives {exc}") from None
    return kw


def args_text(v) -> str:
    if callable(v):
        return _si_value(v)
    return ",".join(f"{x:g}" for x in v) if isinstance(v, (list, tuple)) else f"{v:g}"


def si_summary(si: dict | None) -> dict | None:
    """The SI body options as ``{name: {"value", "units"}}`` (for the summary), None without."""
    if not si:
        return None
    out = {k: {"value": _si_value(v), "units": SI_BODY[k][1]} for k, v in si.items()}
    if "diameter" in si or "tip_drag_area" in si:
        from .. import units

        out.setdefault("air_density", {"value": units.AIR_DENSITY, "units": "kg m-3"})
        if "diameter" in si:
            out.setdefault("cd_normal", {"value": units.CD_NORMAL, "units": "1"})
            out.setdefault("cd_tangential", {"value": units.CD_TANGENTIAL, "units": "1"})
    return out


def _si_value(v):
    """An SI option's value for the summary: a profile of a --line (a function of s) by its name."""
    return f"profile: {getattr(v, '__name__', 'function of s')}" if callable(v) else v


def attach_body(problem, body, args):
    """The problem (None: the paper's, from --chi and --N) with the body of :func:`body_from_args`
    (and the start shape of ``--start`` where the command has it)."""
    from ..simulate import Problem

    if problem is None:
        problem = Problem.catenary(args.chi, args.N, chords=args.chords)
    return problem.with_body(body, start=getattr(args, "start", None))
