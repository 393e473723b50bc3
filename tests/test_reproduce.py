"""One command reproduces the paper: a tiny plan runs end to end and its report says true things."""

import math
import os
import re

import pytest

from snapping import SnappingInputError, ideal
from snapping.reproduce import PLANS, Plan, expected_seconds, reproduce

TINY = Plan(name="tiny", shapes_chi=(0.5, 0.25), shapes_N=40, speed_chi=(0.25,), speed_N=(20, 40),
            scaling_chi=(0.25, 0.4), scaling_N=40, tol_chi=0.25, tol_N=40, tols=(1e-7, 1e-8),
            continuum_chi=(0.25,), continuum_levels=3, continuum_first=-3,
            stability_chi=(0.25,), stability_N=(20, 40, 80), stability_lin=(0.25, 20), caps_N=20, caps_live="tiny")


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    from snapping.simulate import run

    out = tmp_path_factory.mktemp("tiny")
    # one of the plan's runs made here first, directly (checked below against the reproduction's file):
    # the paper's method compiled here once, the two workers load it from numba's cache (cold: else
    # each worker compiles it)
    direct = run(0.25, 20, **TINY.options(TINY.tol)).dataset
    return out, reproduce(out, TINY, workers=2, progress=False, log=lambda *a: None).read_text(), direct


def test_tiny_reproduction_writes_report_and_figures(tiny, monkeypatch):
    tmp_path, text, direct = tiny
    # t* row: the exact value, agreeing with the paper's 1.19814
    assert f"| {ideal.t_star_str(15)} | ≈ 1.19814 | agrees |" in text
    assert "typo in the paper (sign)" in text
    for name in ("fig1_shapes", "fig1e_pin_force", "fig2_profiles", "fig2d_peak_speed_vs_N", "fig3_maxima", "fig4_delta"):
        assert (tmp_path / "figures" / f"{name}.png").stat().st_size > 5000, name
        assert f"figures/{name}.png" in text
    for name in ("fig1_shapes", "fig1e_pin_force", "fig2_profiles", "fig2d_peak_speed_vs_N", "fig3_maxima",
                 "fig3_local_slopes", "fig4_delta"):
        assert (tmp_path / "figures" / f"{name}.pdf").is_file(), name
    # the continuum-limit section: the study's extrapolated peaks and the uniform chain against them
    assert "## The continuum limit" in text and (tmp_path / "figures" / "fig5_continuum.png").stat().st_size > 5000
    from snapping.simulate import load_run
    from xarray import open_dataset

    with open_dataset(tmp_path / "continuum" / "chi0.25" / "convergence.nc") as conv:
        v_lim = conv.attrs["v_peak_limit"]
    row = next(l for l in text.splitlines() if l.startswith("| 0.25 | 3 ("))
    assert f"{v_lim:.6g} ±" in row
    from snapping.reproduce import _path

    u = load_run(_path(tmp_path, TINY, 0.25, 40, 1e-8))  # the paper's chain at the plan's largest N, tol
    # the reproduction's runs are the runs of simulate.run with the plan's options (deterministic: bit for bit)
    v = load_run(_path(tmp_path, TINY, 0.25, 20, TINY.tol))
    for q in ("v_peak", "a_peak", "sigma_peak", "t_snap_v"):
        assert v.attrs[q] == direct.attrs[q], q
    # the reproduction runs the paper's method and chain, not the library's defaults, and says so
    assert (u.attrs["method"], u.attrs["chords"]) == ("euler-richardson", "arclength")
    assert "method euler-richardson (the paper's), chords arclength" in text
    assert f"{float(u.attrs['v_peak']) / v_lim - 1:+.2%}" in row
    assert any(l.startswith("| 0.25 (") and "| kappa_max |" in l for l in text.splitlines())  # refitted exponents
    # beyond the paper: the planar snap's stability, its figure, and its verdict from its numbers
    import json

    from snapping.spatial import stability as S

    assert "## Beyond the paper: does the snap stay planar?" in text
    assert (tmp_path / "figures" / "fig6_planar_stability.png").stat().st_size > 5000
    saved = json.loads((tmp_path / "stability" / "study.json").read_text())
    st, lin = saved["study"], saved["linearity"]
    assert st["N"] == [20, 40, 80] and st["chi"] == [0.25]
    assert f"**Verdict (computed): {S.verdict(st)['text']}.**" in text
    assert st["perturbations"] == list(TINY.stability_perturbations)
    for name in st["perturbations"]:  # the row prints the study's numbers
        row = next(l for l in text.splitlines() if l.startswith(f"| 0.25 | {name} |"))
        assert ", ".join(f"{x:.5g}" for x in S.series(st, 0.25, name, "z")) in row
    lin_row = next(l for l in text.splitlines() if l.startswith("| out-of-plane amplitude at the snap linear in eps"))
    assert lin_row.endswith(f"| {'linear' if lin['spread'] <= S.LINEAR_RTOL else 'not linear'} (spread "
                            f"{'<=' if lin['spread'] <= S.LINEAR_RTOL else '>'} {S.LINEAR_RTOL:g}) |")
    assert lin["linear"]
    # beyond the paper: what caps the snap -- the catalogue's answers (saved) in the table, with their verdicts
    from snapping import caps_report

    assert "## Beyond the paper: what caps the snap" in text
    answers = json.loads((tmp_path / "caps" / "answers.json").read_text())["answers"]
    assert [a["line"] for a in answers] == __import__("snapping.lines").lines.names()
    for a in answers:
        assert f"| {a['line']} | 0.25 | {a['N']} | {a['ideal']['sigma_peak']:.4g} | {a['real']['sigma_peak']:.4g} | " \
               f"{a['factor']['sigma_peak']:.3f} | {a['cap']} | {caps_report.resolved_words(a)} |" in text
    from snapping.regimes import BUNDLED

    for mech in BUNDLED:  # the shipped studies, each with its computed verdict and its regime map
        assert f"### Regime study: {mech} (shipped study file)" in text
        assert (tmp_path / "figures" / f"fig7_regime_map_{mech}.png").stat().st_size > 5000
    # a verdict per study, per chi (the shipped stretching study's limits are resolved: the generic verdict),
    # and the stretching study's same-links ratios as a second estimate
    assert text.count("**Verdict (computed, v_peak): chi=") == len(BUNDLED)
    assert text.count("**Verdict (computed, v_peak): each cell's own continuum limit is not resolved") == 0
    assert text.count("A second estimate of the crossovers (its discretisation errors shared)") == 1
    # every claim row has four cells and a verdict
    rows = [l for l in text.splitlines() if l.startswith("| ") and not l.startswith("| claim") and "seconds" not in l]
    assert len(rows) >= 15
    # a rerun reuses every run file (no simulation), so it is fast and gives the same table; its figures
    # are made again but not drawn (drawing them is most of a rerun's time; the first run's are checked above)
    import snapping._files as F

    redrawn = []
    monkeypatch.setattr(F, "save_figure", lambda fig, path, **kw: redrawn.append(str(path)) or str(path))
    again = reproduce(tmp_path, TINY, workers=1, progress=False, log=lambda *a: None).read_text()
    assert redrawn and all(os.path.isfile(p) for p in redrawn)  # the same figures, already drawn
    strip = lambda t: re.sub(r"## Wall time.*", "", t, flags=re.S)
    assert strip(again) == strip(text)


def test_plans_and_bad_mode(tmp_path):
    assert PLANS["full"].scaling_N == 5000 and PLANS["full"].shapes_N == 2000
    assert expected_seconds(PLANS["full"]) > 3 * expected_seconds(PLANS["quick"])
    with pytest.raises(SnappingInputError, match="mode='fast'"):
        reproduce(tmp_path, "fast")


def _cells(text: str, claim_start: str) -> list[str]:
    row = next(l for l in text.splitlines() if l.startswith(f"| {claim_start}"))
    return [c.strip() for c in row.strip("|").split(" | ")]


def test_report_verdicts_follow_from_the_numbers_in_their_rows(tiny):
    """The verdict of each computed claim is recomputed here from the numbers printed in its row."""
    from snapping import reproduce_verdicts as R

    text = tiny[1]
    num = r"([-+0-9.e]+)"
    # delta rows: the ratios printed, against the paper's bands
    for scale in R.DELTA_BANDS:
        claim, measured, _, verdict = _cells(text, f"predicted/computed peaks with {scale} ")
        ratios = [dict(v=float(v), a=float(a), sigma=float(s))
                  for v, a, s in re.findall(rf"v ×{num}, a ×{num}, σ ×{num}", measured)]
        assert len(ratios) == len(TINY.scaling_chi)
        assert verdict == R.delta_verdict(scale, ratios)
    # the three snapping times: the digit their spread touches
    _, measured, _, verdict = _cells(text, "t*_chi from max speed")
    found = re.findall(rf"t\*_chi {num}, spread {num} \(digit (\d+)\)", measured)
    assert len(found) == len(TINY.scaling_chi)
    for t, sp, d in found:
        assert int(d) == R.changed_digit(float(t), float(sp))
    assert verdict.startswith("agrees" if all(int(d) >= R.T_STAR_DIGIT for *_, d in found) else "differs")
    # t*_chi row: monotone towards the ideal t*
    _, measured, _, verdict = _cells(text, "t*_chi approaches")
    pairs = [(float(c), float(t)) for c, t in re.findall(rf"chi={num}: {num}", measured)]
    assert verdict == R.monotone_verdict([c for c, _ in pairs], [t for _, t in pairs], ideal.t_star())
    # curvature amplification against the tension's
    _, measured, _, verdict = _cells(text, "amplification of the maximum curvature")
    amps = re.findall(rf"kappa ×{num} \(tension ×{num}\)", measured)
    k, s = [float(a) for a, _ in amps], [float(b) for _, b in amps]
    weak = all(math.log(x) <= R.WEAK_AMPLIFICATION * math.log(y) for x, y in zip(k, s))
    assert verdict.startswith("agrees" if weak else "differs")
    # tolerance row: the digit each coarsest-vs-finest change touches, against the paper's
    _, measured, _, verdict = _cells(text, "maxima insensitive to tol")
    first = measured.split(";")[0]
    digits = {q: int(d) for q, _, d in re.findall(rf"(v_peak|a_peak|sigma_peak) {num} \(digit (\d+)\)", first)}
    assert set(digits) == set(R.TOL_DIGITS)
    assert verdict == R.tolerance_verdict(digits, TINY.tol_N)
    assert verdict.startswith("agrees" if all(digits[q] >= d for q, d in R.TOL_DIGITS.items()) else "differs")
    assert "N = 5000" in verdict
    # the boundary layer is only judged at the paper's N
    assert _cells(text, "links in the boundary layer")[3].startswith("lower N")


def test_verdict_rules_on_the_papers_own_numbers():
    from snapping import reproduce_verdicts as R

    # Fig. 4 as the paper describes it (chi = 0.1, N = 5000): delta_kappa_m v, a excellent, sigma x2
    assert R.delta_verdict("delta_kappa_m", [dict(v=0.98, a=0.94, sigma=1.95)]).startswith("agrees")
    assert R.delta_verdict("delta_kappa_m", [dict(v=0.98, a=0.94, sigma=1.0)]).startswith("differs")
    assert R.delta_verdict("delta_kappa0", [dict(v=0.33, a=0.01, sigma=0.21)]).startswith("agrees")
    assert R.delta_verdict("delta_kappa0", [dict(v=0.33, a=0.5, sigma=0.21)]).startswith("differs")
    assert R.delta_verdict("delta_kappa0", [dict(v=0.33, a=0.001, sigma=0.21)]).startswith("differs")  # 3 orders
    # the paper's digits: "differ only at the fifth significant digit" admits t* 1.14811 vs 1.14831
    assert R.changed_digit(1.14811, 1.14831 - 1.14811) == 5
    assert R.spread_verdict([1.14811], [2.0e-4]).startswith("agrees")
    assert R.spread_verdict([1.14811], [2.0e-3]).startswith("differs")  # the fourth digit
    # "the ninth significant digit for velocity and the sixth for acceleration and tension" (N = 5000)
    assert R.changed_digit(11.081378, 7e-7) == 9 and R.changed_digit(8638.4, 0.095) == 6
    assert R.changed_digit(24.581, 1.4e-4) == 6 and R.changed_digit(24.581, 0.14) == 3
    ok = {"v_peak": 9, "a_peak": 6, "sigma_peak": 7}
    assert R.tolerance_verdict(ok, 5000).startswith("agrees") and "N = 5000" not in R.tolerance_verdict(ok, 5000)
    assert R.tolerance_verdict(dict(ok, v_peak=8), 5000).startswith("differs (v_peak at digit 8)")
    assert R.changed_digit(3.0, 0.0) > 9
    assert R.boundary_layer_verdict(12.0, 5000).startswith("agrees")
    assert R.boundary_layer_verdict(20.0, 5000).startswith("differs")
    assert R.boundary_layer_verdict(math.nan, 5000).startswith("no data")
    assert R.monotone_verdict([0.1, 0.25, 0.4], [1.1936, 1.1748, 1.1482], 1.19814).startswith("agrees")
    assert R.monotone_verdict([0.1, 0.25, 0.4], [1.1748, 1.1936, 1.1482], 1.19814) == "differs"
    # chi = 0.25, N = 5000: kappa x5.7 against tension x51 (the -1/6 law against -2/3 gives 1/4 of the e-folds)
    assert R.amplification_verdict([5.7], [51.0]).startswith("agrees")
    assert R.amplification_verdict([51.0 ** 0.25], [51.0]).startswith("agrees")
    assert R.amplification_verdict([51.0], [51.0]).startswith("differs")  # the inferred -2/3 law


def test_wall_time_table_times_the_fits_and_each_figure_apart(tiny):
    _, text, _ = tiny
    table = text.split("## Wall time")[1]
    for part in ("runs", "fits (Fig. 3/4 runs)", "fig1_shapes", "fig1e_pin_force", "fig2_profiles",
                 "fig2d_peak_speed_vs_N", "fig3_maxima", "fig3_local_slopes", "fig4_delta", "stability (3D)", "total"):
        assert re.search(rf"^\| {re.escape(part)} \| \d+\.\d \|$", table, re.M), part
