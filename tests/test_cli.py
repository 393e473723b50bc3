"""The command line: every help shows working examples, and bad input is one line with exit status 2."""

import shlex

import pytest

from snapping.cli import build_parser, main

COMMANDS = ["ideal", "estimate", "simulate", "sweep", "fit", "reproduce"]


def _examples(text: str) -> list[str]:
    lines = text.split("example", 1)[1].splitlines()[1:]
    return [l.split("#")[0].strip() for l in lines if l.strip().startswith("snapping ")]


@pytest.mark.parametrize("command", COMMANDS)
def test_every_command_help_shows_examples_that_parse(command, capsys):
    with pytest.raises(SystemExit) as e:
        main([command, "--help"])
    assert e.value.code == 0
    examples = _examples(capsys.readouterr().out)
    assert examples, f"snapping {command} --help shows no example"
    parser = build_parser()
    own = 0
    for ex in examples:
        args = parser.parse_args(shlex.split(ex)[1:])  # raises SystemExit(2) if the example is wrong
        assert args.command in COMMANDS  # (fit's help first makes the run it fits, with simulate)
        own += args.command == command
    assert own, f"snapping {command} --help shows no example of itself"


def test_top_level_help_lists_examples(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    out = capsys.readouterr().out
    for command in COMMANDS:
        assert command in out
    for ex in _examples(out):
        if "<command>" not in ex:
            build_parser().parse_args(shlex.split(ex)[1:])


def test_no_command_prints_help_and_exits_2(capsys):
    assert main([]) == 2
    assert "usage" in capsys.readouterr().out


def test_ideal_bad_digits_is_one_line(capsys):
    assert main(["ideal", "--digits", "0"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "digits=0" in err
