"""``.. snapping-help:: [SUBCOMMAND]``: the ``--help`` text of the ``snapping`` command.

The text is formatted from :func:`snapping.cli.build_parser` at build time, exactly as
``snapping [SUBCOMMAND] --help`` prints it in a terminal 100 columns wide, so the
command-line page cannot drift from the code.
"""

from __future__ import annotations

import argparse
import os

from docutils import nodes
from sphinx.util.docutils import SphinxDirective

WIDTH = 100


def help_text(command: str | None = None) -> str:
    """``snapping [command] --help`` as printed at ``WIDTH`` columns."""
    from snapping.cli import build_parser

    parser = build_parser()
    if command:
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        if command not in sub.choices:
            raise ValueError(f"snapping has no subcommand {command!r} (it has {', '.join(sub.choices)})")
        parser = sub.choices[command]
    old = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = str(WIDTH)
    try:
        return parser.format_help()
    finally:
        if old is None:
            del os.environ["COLUMNS"]
        else:
            os.environ["COLUMNS"] = old


class SnappingHelp(SphinxDirective):
    optional_arguments = 1
    has_content = False

    def run(self):
        command = self.arguments[0] if self.arguments else None
        try:
            text = help_text(command)
        except ValueError as exc:
            raise self.error(str(exc)) from None
        block = nodes.literal_block(text, text)
        block["language"] = "text"
        return [block]


def setup(app):
    app.add_directive("snapping-help", SnappingHelp)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
