"""One command reproduces the paper: a tiny plan runs end to end and its report says true things."""

import re

import pytest

from snapping import SnappingInputError, ideal
from snapping.reproduce import PLANS, Plan, expected_seconds, reproduce

TINY = Plan(name="tiny", shapes_chi=(0.5, 0.25), shapes_N=40, speed_chi=(0.25,), speed_N=(20, 40),
            scaling_chi=(0.25, 0.4), scaling_N=40, tol_chi=0.25, tol_N=40, tols=(1e-7, 1e-8))


def test_tiny_reproduction_writes_report_and_figures(tmp_path):
    report = reproduce(tmp_path, TINY, workers=2, progress=False, log=lambda *a: None)
    text = report.read_text()
    # t* row: the exact value, agreeing with the paper's 1.19814
    assert f"| {ideal.t_star_str(15)} | ≈ 1.19814 | agrees |" in text
    assert "typo in the paper (sign)" in text
    for name in ("fig1_shapes", "fig1e_pin_force", "fig2_profiles", "fig2d_peak_speed_vs_N", "fig3_maxima", "fig4_delta"):
        assert (tmp_path / "figures" / f"{name}.png").stat().st_size > 5000, name
        assert f"figures/{name}.png" in text
    assert (tmp_path / "figures" / "fig1_shapes.pdf").is_file()
    # every claim row has four cells and a verdict
    rows = [l for l in text.splitlines() if l.startswith("| ") and not l.startswith("| claim") and "seconds" not in l]
    assert len(rows) >= 15
    # a rerun reuses every run file (no simulation), so it is fast and gives the same table
    again = reproduce(tmp_path, TINY, workers=1, progress=False, log=lambda *a: None).read_text()
    strip = lambda t: re.sub(r"## Wall time.*", "", t, flags=re.S)
    assert strip(again) == strip(text)


def test_plans_and_bad_mode(tmp_path):
    assert PLANS["full"].scaling_N == 5000 and PLANS["full"].shapes_N == 2000
    assert expected_seconds(PLANS["full"]) > 3 * expected_seconds(PLANS["quick"])
    with pytest.raises(SnappingInputError, match="mode='fast'"):
        reproduce(tmp_path, "fast")
