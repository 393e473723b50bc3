"""The stability study of the planar snap (snapping.spatial.stability) and the shape perturbation.

* the linear regime: z/eps and vz/eps at the snap equal to 1e-3 over eps = 1e-6 .. 1e-4
  (the problem is symmetric under z -> -z, so z/eps = G + O(eps^2));
* a mode-0 (k = 0) or eps = 0 perturbation gives exactly zero out-of-plane motion and the
  planar run's peak bit for bit;
* the shape perturbation: every link exactly its length, the displacement eps L sin(pi s/L)
  (computed here) to O(eps^3), in-plane positions moved at O(eps^2);
* the amplification-factor classification on synthetic sequences with known limits and
  exponents, and the verdict on synthetic studies.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from snapping._validate import SnappingInputError
from snapping.spatial import stability as S
from snapping.spatial.solve3d import run3d
from snapping.spatial.starts3d import Problem3D


@pytest.mark.parametrize("name", ["velocity sin", "shape sin", "velocity sin 3"])
def test_out_of_plane_amplitude_is_linear_in_eps(name):
    lin = S.linearity(0.25, 40, name, [1e-6, 1e-5, 1e-4], tol=1e-10)
    z, vz = np.array(lin["z"]), np.array(lin["vz"])
    assert np.all(np.abs(z / z[0] - 1.0) < 1e-3) and np.all(np.abs(vz / vz[0] - 1.0) < 1e-3)
    assert lin["linear"] and lin["spread"] == pytest.approx(max(np.abs(z / z[0] - 1).max(), np.abs(vz / vz[0] - 1).max()))
    assert 0.1 < z[0] < 10.0  # an O(1) factor, not zero


def test_mode_zero_and_zero_eps_give_exactly_planar_runs():
    p = Problem3D.catenary(0.25, 40)
    base = run3d(p, tol=1e-9)
    for q in (p.perturbed(1e-3, k=0), p.perturbed(1e-3, k=0, kind="shape"), p.perturbed(0.0, "random", seed=3),
              p.perturbed(0.0, kind="shape")):
        assert np.all(q.r[:, 2] == 0.0) and np.all(q.v[:, 2] == 0.0)
        r = run3d(q, tol=1e-9)
        assert r["z_amp_max"] == 0.0 and r["vz_amp_max"] == 0.0
        assert r["v_peak"] == base["v_peak"] and r["n_rhs"] == base["n_rhs"]


def test_shape_perturbation_keeps_exact_chords_and_displaces_by_the_mode():
    p = Problem3D.catenary(0.25, 60)
    h = p.links.h
    s = np.concatenate([np.cumsum(h[::-1])[::-1], [0.0]])  # arclength from the held end
    L = s[0]
    for eps in (1e-2, 1e-3):
        q = p.perturbed(eps, kind="shape")
        assert np.abs(np.linalg.norm(np.diff(q.r, axis=0), axis=1) - h).max() < 1e-15
        assert np.all(q.r[-1] == 0.0) and np.all(q.v == 0.0)
        # out of the plane: eps L sin(pi s/L) up to O(eps^3); in the plane: moved at O(eps^2)
        assert np.abs(q.r[:, 2] - eps * L * np.sin(np.pi * s / L)).max() < 30 * eps**3
        dxy = np.abs(q.r[:, :2] - p.r[:, :2]).max()
        assert 0.01 * eps**2 < dxy < 10 * eps**2
        assert q.start["perturbation"] == {"eps": eps, "mode": "sin", "seed": None, "kind": "shape", "k": 1}


def test_shape_perturbation_keeps_link_velocities_normal():
    p = Problem3D.catenary(0.25, 30).perturbed(0.3)  # a start with (out-of-plane) velocities, then a shape kick
    q = p.perturbed(1e-2, kind="shape")  # Problem3D's own check: no link is stretched by v
    d, dv = np.diff(q.r, axis=0), np.diff(q.v, axis=0)
    assert np.abs(np.sum(d * dv, axis=1)).max() < 1e-14


def test_classify_recovers_known_limits_and_exponents():
    N = [100, 200, 400, 800]
    n = np.asarray(N, dtype=float)
    c = S.classify(N, 0.7 + 3.0 * n**-1.5)  # converging, order 1.5
    assert c["bounded"] and c["converging"]
    assert c["limit"] == pytest.approx(0.7, abs=1e-13) and c["order"] == pytest.approx(1.5, abs=1e-9)
    assert c["words"].startswith("bounded: -> 0.7 ")
    g = S.classify(N, 5.0 * n**0.3)  # growing as N^0.3: not bounded
    assert not g["bounded"] and g["p"] == pytest.approx(0.3, abs=1e-12) and g["words"] == "growing as N^0.300"
    f = S.classify(N, [15.7, 16.8, 16.4, 15.9])  # oscillating, no systematic growth
    assert f["bounded"] and not f["converging"] and f["p"] < 0
    w = S.classify(N, 2.0 * n**(0.5 * S.P_FLAT))  # slow power growth below P_FLAT: bounded, not converging
    assert w["bounded"] and not w["converging"]
    w = S.classify(N, 2.0 * n**(2 * S.P_FLAT))
    assert not w["bounded"]
    slow = S.classify(N, 10.0 - 20.0 * n**-0.2)  # converging, but at order 0.2 < ORDER_MIN: not trusted
    assert slow["converging"] and slow["order"] == pytest.approx(0.2, abs=1e-9) and slow["order"] < S.ORDER_MIN
    assert not slow["bounded"] and slow["words"].startswith("growing as N^0.2")
    with pytest.raises(SnappingInputError):
        S.classify(N, [1.0, 0.0, 1.0, 1.0])


def _synthetic(gz, gvz, vpeak, N=(100, 200, 400, 800)):
    rows = []
    for n in N:
        rows.append({"chi": 0.25, "N": n, "perturbation": "planar", "z": 0.0, "vz": 0.0, "v_peak": vpeak(n), "n_rhs": 1})
        rows.append({"chi": 0.25, "N": n, "perturbation": "velocity sin", "z": gz(n), "vz": gvz(n), "v_peak": vpeak(n),
                     "n_rhs": 1})
    return {"chi": [0.25], "N": list(N), "perturbations": ["velocity sin"], "eps": 1e-6, "tol": 1e-10, "seed": 1,
            "rows": rows}


def test_verdict_is_computed_from_the_numbers():
    focus = lambda n: 2.0 * n**0.3  # the in-plane peak speed grows as N^0.3
    ok = S.verdict(_synthetic(lambda n: 0.68 - 1.0 / n, lambda n: 3.0 * n**0.3, focus))
    assert ok["stable"] and ok["text"].startswith("the planar snap is stable")
    assert "G = 0.68 to 0.68" in ok["text"] and "bounded as N grows" in ok["text"]
    bad_z = S.verdict(_synthetic(lambda n: 0.01 * n**0.5, lambda n: 3.0, focus))
    assert not bad_z["stable"] and "z: chi = 0.25, velocity sin, N^0.500" in bad_z["text"]
    bad_vz = S.verdict(_synthetic(lambda n: 0.68, lambda n: 3.0 * n**0.6, focus))
    assert not bad_vz["stable"] and "N^0.600 against v_peak N^0.300" in bad_vz["text"]
    lines = S.report_section(_synthetic(lambda n: 0.68 - 1.0 / n, lambda n: 3.0, focus))
    assert lines[0] == "## Beyond the paper: does the snap stay planar?"
    assert any(l.startswith("**Verdict (computed): the planar snap is stable") for l in lines)


@pytest.mark.parametrize("call, word", [
    (lambda: S.start(0.25, 10, "twist", 1e-3), "perturbation='twist'"),
    (lambda: Problem3D.catenary(0.25, 10).perturbed(1e-3, kind="spin"), "kind='spin'"),
    (lambda: Problem3D.catenary(0.25, 10).perturbed(1e-3, k=-1), "k="),
    (lambda: S.study((0.25,), (10, 20), eps=0.0), "eps=0.0"),
])
def test_bad_input_is_named(call, word):
    with pytest.raises(SnappingInputError, match=word.replace("(", r"\(")):
        call()


def test_smooth_random_mode_is_the_same_field_at_every_N():
    """mode "modes": eight sine modes with normal coefficients / mode number (computed here),
    max 1 over the nodes; refining the chain samples the same field."""
    a = np.random.default_rng(7).standard_normal(8) / np.arange(1, 9)
    for N in (40, 80):
        p = Problem3D.catenary(0.25, N)
        q = p.perturbed(1e-3, "modes", seed=7)
        s = np.concatenate([np.cumsum(p.links.h[::-1])[::-1], [0.0]])
        phi = sum(a[j - 1] * np.sin(j * np.pi * s / s[0]) for j in range(1, 9))
        phi[-1] = 0.0
        np.testing.assert_allclose(q.v[:, 2], 1e-3 * phi / np.abs(phi).max(), rtol=0, atol=1e-17)
    r40 = Problem3D.catenary(0.25, 40).perturbed(1e-3, "modes", seed=7).v[::2, 2]
    r80 = Problem3D.catenary(0.25, 80).perturbed(1e-3, "modes", seed=7).v[::4, 2]
    assert np.abs(r40[: r80.size] - r80).max() < 2e-2 * 1e-3  # (the max normalisation moves with N)


def test_cli_shape_and_mode_number(capsys):
    import json

    from snapping.cli import main

    assert main(["simulate", "--chi", "0.25", "--N", "12", "--perturb", "1e-4", "--perturb-kind", "shape",
                 "--perturb-k", "2", "--tol", "1e-9", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    ref = run3d(Problem3D.catenary(0.25, 12).perturbed(1e-4, k=2, kind="shape"), tol=1e-9)
    assert out["z_amp_snap"] == ref["z_amp_snap"] and out["v_peak"] == ref["v_peak"]
    assert main(["simulate", "--chi", "0.25", "--N", "12", "--perturb", "1e-4", "--perturb-k", "-1"]) == 2
    assert "k=-1" in capsys.readouterr().err
