"""A line of discrete links (``snapping.lines.Line.pitch``; the ball chain): its answers run on its
own round(length/pitch) links by default and for N="auto" (a chain is its links: 1% in N has no
meaning), on N links when N is given; a continuous line is resolved (N="auto", since designres)."""

from __future__ import annotations

import json
import math

import pytest

from snapping import caps, lines, simulate
from snapping._validate import SnappingInputError
from snapping.caps_report import resolved_words
from snapping.cli import main

BALL = lines.get("ball-chain")


def test_own_links_is_length_over_pitch():
    assert BALL.own_links() == 229  # (Tomaszewski et al. 2006: 229 links on 1.022 m)
    assert BALL.own_links(2.044) == 458 and lines.get("fly-line").own_links() is None
    assert caps.spec("ball-chain").own_links() == 229
    assert caps.spec("ball-chain", length=0.513).own_links() == 115  # (0.513 * 229 / 1.022 = 114.95)
    with pytest.raises(SnappingInputError, match=r"pitch=.* m with length=100.0 m is out of range: .* 2 to 20000"):
        caps.spec("ball-chain", length=100.0)
    with pytest.raises(SnappingInputError, match=r"pitch=-0.01"):
        BALL.replace(pitch=-0.01)


def test_ball_chain_answer_on_its_own_links_is_the_direct_run():
    """N None: the 229 links, no N/2 run, no graded links; its ideal peaks those of the ideal chain
    run directly on 229 links (SI: v sqrt(gL), a g, sigma lambda g L)."""
    r = caps.cap("ball-chain", 0.5, alone=False)
    assert r["N"] == 229 and r["own_links"]["used"] and r["resolved"] is True and r["resolution"] is None
    assert sorted({x["N"] for x in r["runs"]}) == [229]
    assert not (r.get("graded") or {}).get("used")
    d = simulate.run(0.5, 229).dataset.attrs
    g, L, m = 9.81, BALL.length, BALL.mass()
    want = {"v_peak": d["v_peak"] * math.sqrt(g * L), "a_peak": d["a_peak"] * g, "sigma_peak": d["sigma_peak"] * m * g}
    for q, v in want.items():
        assert r["ideal"][q] == pytest.approx(v, rel=1e-6), q
    assert "its own 229 links" in resolved_words(r)
    assert "a chain of 229 discrete links (pitch 4.463 mm)" in "\n".join(caps.format_answer(r))


def test_auto_and_given_links_on_a_discrete_line():
    short = BALL.replace(pitch=BALL.length / 40)  # (40 links: cheap)
    r = caps.cap(short, 0.5, N="auto", alone=False)
    assert r["N"] == 40 and r["own_links"]["used"] and "auto_N" not in r
    r = caps.cap(short, 0.5, N=24, alone=False)  # (given: honoured, with its N/2 check)
    assert r["N"] == 24 and not r["own_links"]["used"] and sorted({x["N"] for x in r["runs"]}) == [12, 24]
    assert "answered on N = 24 as asked" in r["own_links"]["why"]
    d = caps.design(short, chis=(0.5,), max_tension=1.0, alone=False)
    assert d["N"] == 40


def test_a_continuous_line_is_resolved_by_default():
    r = caps.cap(None, 0.5, length=1.0, mass=0.1, alone=False, check=False)
    assert r["auto_N"][0] == 100 and r["N"] == r["auto_N"][-1] and "own_links" not in r  # (200 before designres)


def test_cli_estimate_answers_the_ball_chain_on_its_links(capsys):
    short = ["estimate", "--line", "ball-chain", "--chi", "0.5", "--length", str(BALL.length / 229 * 30), "--json"]
    assert main(short) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["N"] == 30 and out["own_links"]["links"] == 30
    assert main([*short, "--links", "20"]) == 0
    assert json.loads(capsys.readouterr().out)["N"] == 20
