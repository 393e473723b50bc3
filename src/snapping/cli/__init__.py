"""The ``snapping`` command line: thin wrappers over the library.

Each subcommand has an ``_add_<name>`` function that declares its arguments
(with a working example in its epilog) and a ``_cmd_<name>`` function that
calls the library and prints. No physics lives here.

Bad input (a :class:`ValueError` from the library, or an argparse error) prints
one line on stderr and exits with status 2, without a traceback.

The subcommands live in one module per group: ``estimate`` (ideal, estimate,
design), ``simulate``, ``sweep`` (sweep, converge) and ``analysis`` (fit,
reproduce, animate); ``_common`` holds what they share (printing, the SI
options). This module holds the parser, :func:`main` and the error handling.
"""

from __future__ import annotations

import argparse
import sys

from ._common import PLOT_BYTES, _formatter, print_json, print_table
from .analysis import _add_animate, _add_fit, _add_reproduce
from .estimate import _add_design, _add_estimate, _add_ideal
from .simulate import _add_simulate
from .sweep import _add_converge, _add_sweep

__all__ = ["EXIT_BAD_INPUT", "EXIT_FAILED", "PLOT_BYTES", "build_parser", "main", "print_json", "print_table"]

EXIT_BAD_INPUT = 2
EXIT_FAILED = 1  # a numerical failure or an I/O fault (e.g. a full disk)

#: the subcommands' ``_add_<name>`` functions, in the order of the help
_SUBCOMMANDS = (_add_ideal, _add_estimate, _add_design, _add_simulate, _add_sweep, _add_fit, _add_converge,
                _add_reproduce, _add_animate)


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit status 2."""

    def error(self, message: str):  # noqa: D401 - argparse API
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message}\n")


# ---------------------------------------------------------------------------- main
def build_parser() -> argparse.ArgumentParser:
    """The ``snapping`` command's parser, with one subparser per subcommand.

    >>> build_parser().parse_args(["estimate", "--chi", "0.25"]).chi
    0.25
    """
    from .. import __version__

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
    for add in _SUBCOMMANDS:
        add(sub)
    return parser


#: commands with --length/--mass/--g for SI output (their errors name these options themselves)
_SI_COMMANDS = ("simulate", "fit", "sweep", "converge")
_SI_DESTS = ("length", "mass", "g")

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
    import warnings

    with warnings.catch_warnings(record=True) as caught:  # (numpy/scipy warnings: held until the outcome)
        status = _run(parser, args)
    if status == 0:  # a warning of a command that worked is shown after its output; an error says it all
        for w in caught:
            print(warnings.formatwarning(w.message, w.category, w.filename, w.lineno).rstrip(), file=sys.stderr)
    return status


def _run(parser, args) -> int:
    """``args.func(args)``, every exception mapped to one line on stderr and an exit status."""
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
    except RuntimeError as exc:  # a numerical failure, or workers that died: one line, exit 1
        if not any(c.__name__ in ("SimulationError", "BrokenExecutor") for c in type(exc).__mro__):
            raise
        first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
        print(f"snapping {args.command}: error: {first}", file=sys.stderr)
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
