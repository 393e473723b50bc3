"""The help of simulate, estimate and regimes says what the options do (a new user's check).

Each wording fixed was wrong or silent against the code: the drag coefficients' "default 1.2
/ 0.01" while a --line brings its own (the ball chain's 0.25 / 0.08, snapping.lines);
--bending-damping without its units (the body's table of units says lambda g L^3 sqrt(L/g));
regimes --numbers without the range regimes refuses outside of (0, NUMBER_MAX].
"""

from __future__ import annotations

import re

import pytest

from snapping.cli import main


def _help(command: str) -> str:
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), pytest.raises(SystemExit):
        main([command, "--help"])
    return buf.getvalue()


def _option(text: str, option: str) -> str:
    """The help of one option: its line and the continuation lines under it, whitespace folded."""
    lines = text.splitlines()
    start = [i for i, ln in enumerate(lines) if re.match(rf"\s+(-\w, )?{re.escape(option)}\b", ln)]
    assert len(start) == 1, option
    out = [lines[start[0]]]
    for ln in lines[start[0] + 1:]:
        if not ln.strip() or re.match(r"\s{1,4}-", ln):
            break
        out.append(ln)
    return re.sub(r"\s+", " ", " ".join(out)).split(option, 1)[1]


@pytest.mark.parametrize("command", ["simulate", "estimate"])
@pytest.mark.parametrize("option, key", [("--cd-normal", "cd_normal"), ("--cd-tangential", "cd_tangential")])
def test_drag_coefficients_default_to_the_line(command, option, key):
    from snapping import lines

    line = lines.get("ball-chain")
    from snapping.units import CD_NORMAL, CD_TANGENTIAL

    plain = {"cd_normal": CD_NORMAL, "cd_tangential": CD_TANGENTIAL}[key]
    assert getattr(line, key) != plain  # a line that does not take the plain default
    words = _option(_help(command), option)
    assert "--line" in words and f"{plain:g}" in words, words


def test_bending_damping_states_its_units():
    from snapping.cli._body import BODY_NOTES

    words = _option(_help("simulate"), "--bending-damping")
    assert BODY_NOTES["bending_damping"] in words, words


def test_regimes_numbers_state_their_range():
    from snapping.regimes_spec import NUMBER_MAX

    words = _option(_help("regimes"), "--numbers")
    m = re.search(r"\(0, ([0-9.e+]+)\]", words)
    assert m and float(m.group(1)) == NUMBER_MAX, words
