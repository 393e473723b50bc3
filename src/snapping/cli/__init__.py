"""The ``snapping`` command line: thin wrappers over the library.

Each subcommand has an ``_add_<name>`` function that declares its arguments
(with a working example in its epilog) and a ``_cmd_<name>`` function that
calls the library and prints. No physics lives here.

Bad input (a :class:`ValueError` from the library, or an argparse error) prints
one line on stderr and exits with status 2, without a traceback.

The subcommands live in one module per group: ``estimate`` (ideal, estimate,
design), ``simulate``, ``sweep`` (sweep, converge), ``regimes`` and ``analysis`` (fit,
reproduce, plot, animate); ``_common`` holds what they share (printing, the SI
options). This module holds the parser, :func:`main` and the error handling.
"""

from __future__ import annotations

import argparse
import sys

from ._common import PLOT_BYTES, _formatter, print_json, print_table
from .analysis import _add_animate, _add_fit, _add_plot, _add_reproduce
from .estimate import _add_design, _add_estimate, _add_ideal
from .simulate import _add_simulate
from .regimes import _add_regimes
from .sweep import _add_converge, _add_sweep

__all__ = ["EXIT_BAD_INPUT", "EXIT_FAILED", "PLOT_BYTES", "build_parser", "main", "print_json", "print_table"]

EXIT_BAD_INPUT = 2
EXIT_FAILED = 1  # a numerical failure or an I/O fault (e.g. a full disk)

#: the subcommands' ``_add_<name>`` functions, in the order of the help
_SUBCOMMANDS = (_add_ideal, _add_estimate, _add_design, _add_simulate, _add_sweep, _add_fit, _add_converge,
                _add_regimes, _add_reproduce, _add_plot, _add_animate)


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit status 2, and negative numbers in any form taken as
    values (``--bending -1e-4``, ``--wind -0.5,0``: argparse alone reads only ``-1`` and ``-.5``
    as numbers, the rest as unknown options, "expected one argument")."""

    #: a negative number (decimal or scientific, inf, nan) or a comma list starting with one
    _NEGATIVE = r"-(?:\d+\.?\d*|\.\d+|inf|nan)(?:[eE][-+]?\d+)?"

    def __init__(self, *args, **kwargs):
        import re

        super().__init__(*args, **kwargs)
        num = self._NEGATIVE
        self._negative_number_matcher = re.compile(rf"^{num}(?:,\s*[-+]?{num[1:]})*$", re.IGNORECASE)

    def error(self, message: str):  # noqa: D401 - argparse API
        import re

        bad = re.match(r"argument <command>: invalid choice: '([^']*)'", message)
        if bad:  # a mistyped subcommand: suggest the closest
            import difflib

            choices = next(a for a in self._actions if isinstance(a, argparse._SubParsersAction)).choices
            close = difflib.get_close_matches(bad.group(1), list(choices), n=2, cutoff=0.5)
            if close:
                message += f"; did you mean {' or '.join(close)}?"
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message}\n")


class _Version(argparse.Action):
    """--version, reading the installed version only when asked (importlib.metadata is slow to import)."""

    def __call__(self, parser, namespace, values, option_string=None):
        from .. import __version__

        print(f"snapping {__version__}")
        parser.exit(0)


# ---------------------------------------------------------------------------- main
def build_parser() -> argparse.ArgumentParser:
    """The ``snapping`` command's parser, with one subparser per subcommand.

    >>> build_parser().parse_args(["estimate", "--chi", "0.25"]).chi
    0.25
    """
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
            "  snapping plot run.nc -o run.png     # shapes, profiles and maxima of one run\n"
            "  snapping fit run.nc --plot fit.png  # exponents near the snap\n"
            "  snapping reproduce --quick -o out   # every claim and figure of the paper\n"
            "  snapping <command> --help           # each command's options and examples"
        ),
    )
    parser.add_argument("--version", action=_Version, nargs=0, help="show the version and exit")
    sub = parser.add_subparsers(dest="command", metavar="<command>", parser_class=_Parser)
    for add in _SUBCOMMANDS:
        add(sub)
    return parser


#: commands with --length/--mass/--g for SI output (their errors name these options themselves)
_SI_COMMANDS = ("simulate", "fit", "sweep", "converge")
_SI_DESTS = ("length", "mass", "g")

#: library parameters named otherwise than the option that gives them (``chis=[]`` of --chi)
_RENAMED = {"regimes": {"chis": "--chi", "numbers": "--numbers", "out": "--output", "path": "--load",
                        "method": "--elastic-method"}}

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
    for name, opt in _RENAMED.get(command, {}).items():
        msg = re.sub(rf"(?<![\w.\-]){re.escape(name)}(?=[=\[:])", opt, msg)
    for name, opt in _PART_OF.get(command, {}).items():
        if opt not in msg:
            msg = re.sub(rf"(?<![\w.\-]){re.escape(name)}{after}", f"{opt} {name}", msg, count=1)
    return msg


def main(argv: list[str] | None = None) -> int:
    """Run the ``snapping`` command on ``argv`` (default: ``sys.argv[1:]``); returns the exit status
    (0 done, 1 numerical failure or I/O fault, 2 bad input, 130 or 143 interrupted by SIGINT or SIGTERM)."""
    parser = build_parser()
    args, unknown = parser.parse_known_args(argv)
    if unknown:
        print(_unknown_message(parser, getattr(args, "command", None), unknown), file=sys.stderr)
        return EXIT_BAD_INPUT
    if not getattr(args, "func", None):
        parser.print_help()
        return EXIT_BAD_INPUT
    args._explicit = _explicit_dests(argv)
    args._argv = list(sys.argv[1:] if argv is None else argv)  # (an interrupted run's resume command repeats it)
    from ._interrupted import file_states

    args._files_before = file_states(args)  # (an interruption outside a run's loop: what it left, file by file)
    import warnings

    restore = _on_sigterm_raise()
    try:
        with warnings.catch_warnings(record=True) as caught:  # (numpy/scipy warnings: held until the outcome)
            status = _run(parser, args)
    finally:
        restore()
    if status == 0:  # a warning of a command that worked is shown after its output; an error says it all
        for w in caught:
            print(warnings.formatwarning(w.message, w.category, w.filename, w.lineno).rstrip(), file=sys.stderr)
    return status


def _run(parser, args) -> int:
    """``args.func(args)``, every exception mapped to one line on stderr and an exit status."""
    try:
        return int(args.func(args) or 0)
    except _Terminated:  # SIGTERM outside a run's loop (which saves a checkpoint on it itself)
        print(f"snapping {args.command}: terminated by SIGTERM {_outside_run(args)}", file=sys.stderr)
        return 143
    except ValueError as exc:  # SnappingInputError and friends: one line, exit 2
        print(f"snapping {args.command}: error: {_cli_words(_as_typed(parser, args.command, str(exc)))}",
              file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print(f"snapping {args.command}: interrupted by SIGINT {_outside_run(args)}", file=sys.stderr)
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


class _Terminated(KeyboardInterrupt):
    """SIGTERM received while no run loop had its own handler (starting up, compiling, writing)."""


def _on_sigterm_raise():
    """Make SIGTERM raise :class:`_Terminated` (the command then says so and exits 143 instead of
    dying without a word); returns the function that restores the previous handler."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return lambda: None

    def handler(signum, frame):
        raise _Terminated()

    try:
        old = signal.signal(signal.SIGTERM, handler)
    except (ValueError, OSError):  # pragma: no cover - exotic embedding
        return lambda: None
    return lambda: signal.signal(signal.SIGTERM, old)


def _outside_run(args) -> str:
    """What an interruption outside a run's loop left behind (a run's loop says it itself)."""
    from ._interrupted import outside_run

    return outside_run(args)


def _cli_words(msg: str) -> str:
    """A library message in the words of the command line (``--overwrite``, not ``overwrite=True``)."""
    for lib in ("overwrite=True (--overwrite)", "--overwrite (overwrite=True)", "overwrite=True"):
        msg = msg.replace(lib, "--overwrite")
    return msg


def _unknown_message(parser, command, unknown: list[str]) -> str:
    """The one-line error for arguments no option takes, naming the subcommand and suggesting
    the closest options of that subcommand (difflib)."""
    import difflib

    sub = None
    if command:
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices.get(command)
    where = sub or parser
    options = sorted({o for a in where._actions for o in a.option_strings if o.startswith("--")})
    parts, after_option = [], False
    for arg in unknown:
        if arg.startswith("-") and len(arg) > 1 and not arg[1:2].isdigit():
            name = arg.split("=", 1)[0]
            close = difflib.get_close_matches(name, options, n=3, cutoff=0.6)
            hint = f" (did you mean {' or '.join(close)}?)" if close else ""
            parts.append(f"{name}{hint}")
            after_option = "=" not in arg
        elif not after_option:  # (a value right after an unknown option is taken to be its value)
            parts.append(repr(arg))
        else:
            after_option = False
    prog = f"snapping {command}" if command else "snapping"
    return f"{prog}: error: unrecognized argument{'s' if len(parts) > 1 else ''}: {', '.join(parts)}; see `{prog} --help`"


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
