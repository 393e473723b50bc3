"""Helpers shared by the subcommands of :mod:`snapping.cli`: the help formatter, JSON and
table printing, the check of non-finite results, the SI options (--length/--mass/--g) and
the parsing of comma-separated option values."""

from __future__ import annotations

import argparse
import json
import math
import sys

PLOT_BYTES = 2e6  # free space a figure file needs (checked before the work)


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
        if isinstance(value, float):  # (a count held as a float prints as an integer, not 1e+06)
            value = str(int(value)) if value.is_integer() and 1e6 <= abs(value) < 1e15 else f"{value:.6g}"
        fmt_rows.append((str(name), str(value), *(str(c) for c in r[2:])))
    w0 = max(len(r[0]) for r in fmt_rows)
    w1 = max(len(r[1]) for r in fmt_rows)
    for r in fmt_rows:
        rest = "  ".join(r[2:])
        print(f"  {r[0]:<{w0}}  {r[1]:>{w1}}  {rest}".rstrip())


# ----------------------------------------------------------------------- SI units


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
    from .._validate import SnappingInputError
    from ..units import Scales
    from ._body import apply_line

    apply_line(args)  # --line NAME: its --length, --mass and SI body where not given
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
    from .. import units

    if scales is None:
        return {**obj, "units_note": units.NONDIMENSIONAL_NOTE}
    return {**obj, "si": {"system": "SI", "scales": units._scale_inputs(scales), **si()}}


def _print_si(scales, rows, title: str = "") -> None:
    """The SI part of a text answer: ``rows`` (name, nondimensional, SI, units; from
    :func:`snapping.units.si_rows`) as a table, or, without --length/--mass, the line saying
    the numbers are nondimensional and how to get SI."""
    from .. import units

    if scales is None:
        import textwrap

        head, _, tail = units.NONDIMENSIONAL_NOTE.partition("; ")  # (tail: how to get SI, kept on one line)
        print(textwrap.fill(head + (";" if tail else ""), width=100, initial_indent="  ", subsequent_indent="    "))
        if tail:
            print(f"    {tail}")
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


def _dimensionless(scales, args, *, N=None, tip_mass=None) -> dict | None:
    """The line's dimensionless numbers (:func:`snapping.dimensionless.line_numbers`) from
    --length/--mass/--g, the body's SI options where the command has them (--ei, --diameter,
    --air-density, --cd-normal, --cd-tangential; --bending, --drag-normal, --drag-tangential as
    given), --ea where it has it, ``N`` links and the ``tip_mass`` ratio (None: not said); None
    without SI scales (``scales``: anything with ``length``, ``mass`` and ``g``)."""
    if scales is None:
        return None
    from .. import dimensionless

    kw = {}
    if hasattr(args, "ei"):
        from ._body import SI_BODY, body_si_inputs

        # a tapered line (--line) gives profiles of s: its numbers are those at the held end, s = 0,
        # as snapping.lines.Line.numbers
        kw = {SI_BODY[k][0]: (v(0.0) if callable(v) else v) for k, v in (body_si_inputs(args) or {}).items()
              if k in ("ei", "diameter", "air_density", "cd_normal", "cd_tangential")}
    out = dimensionless.line_numbers(scales.length, scales.mass, scales.g, N=N, ea=getattr(args, "ea", None),
                                     end_mass=None if tip_mass is None else tip_mass * scales.mass, **kw)
    for dest, key in (("bending", "beta"), ("drag_normal", "drag_normal"), ("drag_tangential", "drag_tangential")):
        v = getattr(args, dest, None)
        if isinstance(v, float) and v != 0.0:  # (given nondimensional: the number itself)
            out[key] = v
    return {k: out[k] for k in dimensionless.NUMBERS if k in out}


def _print_dimensionless(numbers) -> None:
    """The block "Dimensionless numbers" of a text answer (nothing when ``numbers`` is None)."""
    if not numbers:
        return
    from ..dimensionless import number_rows

    print()
    print_table(number_rows(numbers), title="Dimensionless numbers")


# ------------------------------------------------------------- option values
def _numbers(option: str, text: str, lo: int, hi: int) -> list[float]:
    """Comma-separated numbers of an option (lo to hi of them), or SnappingInputError naming it."""
    from .._validate import SnappingInputError

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
