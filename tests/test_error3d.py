"""The 3D stepper's error norm (snapping.spatial.solve3d.step_error3d): the planar method's
quantities (each link's angle and angular-velocity errors), not the frame's components.

* against a direct numpy evaluation of Hairer's estimate per link (written here);
* drift along ``e_j`` (what the projection after each step removes) is not an error: adding
  any radial part to the stages leaves the error unchanged;
* invariant under a rotation of space, at the step and for a whole run: a rotated problem
  takes the same steps and gives the same peaks (the per-component norm did not: its
  peaks differed by 6e-9 at tol 1e-6).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from snapping.simulate import rk as R
from snapping.spatial import solve3d as S
from snapping.spatial.solve3d import run3d
from snapping.spatial.starts3d import Problem3D

ROT = Rotation.from_rotvec([0.3, -0.7, 0.5]).as_matrix()


def _state(rng, N):
    e = rng.normal(size=(N, 3))
    e /= np.linalg.norm(e, axis=1)[:, None]
    u = rng.normal(size=(N, 3)) * 5.0
    u -= np.sum(u * e, axis=1)[:, None] * e
    return e, u


def _pack(e, u, W):
    return np.concatenate([e.T.ravel(), u.T.ravel(), [W]])


def _vectors(y, N):
    """(e, u) as (N, 3) arrays from a flat state (or stage) vector."""
    return y[:3 * N].reshape(3, N).T, y[3 * N:6 * N].reshape(3, N).T


def _rotate(y, N, Rm):
    e, u = _vectors(y, N)
    return _pack(e @ Rm.T, u @ Rm.T, y[6 * N])


def _expected(N, h, tol, y0, y1, K):
    """Hairer's per-link estimate, in numpy: the E5/E3 combinations of the stages, their parts
    normal to e_j (at the step's end), scaled by tol (1 + |e_j|), tol (1 + |u_j|)."""
    e5 = R.E5_RK @ K[:R.NS + 1]
    e3 = R.E3_RK @ K[:R.NS + 1]
    e1, _ = _vectors(y1, N)
    eh = e1 / np.linalg.norm(e1, axis=1)[:, None]
    out = []
    for part in range(2):
        sl = slice(3 * N * part, 3 * N * (part + 1))
        a5 = e5[sl].reshape(3, N).T
        a3 = e3[sl].reshape(3, N).T
        a5 = a5 - np.sum(a5 * eh, axis=1)[:, None] * eh
        a3 = a3 - np.sum(a3 * eh, axis=1)[:, None] * eh
        size = np.maximum(np.linalg.norm(y0[sl].reshape(3, N), axis=0), np.linalg.norm(y1[sl].reshape(3, N), axis=0))
        sc = tol * (1.0 + size)
        s5 = np.sum(a5**2, axis=1) / sc**2
        s3 = np.sum(a3**2, axis=1) / sc**2
        out.append(abs(h) * s5 / np.sqrt(s5 + 0.01 * s3))
    sw = tol * (1.0 + max(abs(y0[-1]), abs(y1[-1])))
    w5, w3 = e5[-1] / sw, e3[-1] / sw
    out.append([abs(h) * w5**2 / np.sqrt(w5**2 + 0.01 * w3**2)])
    return float(np.max(np.concatenate(out)))


@pytest.mark.parametrize("seed", [0, 1])
def test_step_error_is_the_links_angle_error_and_frame_free(seed):
    rng = np.random.default_rng(seed)
    N, h, tol = 7, 0.013, 1e-8
    e0, u0 = _state(rng, N)
    e1, u1 = _state(rng, N)
    y0, y1 = _pack(e0, u0, 0.3), _pack(e1, u1, 0.31)
    K = rng.normal(size=(R.NSX, y0.size)) * 1e-6
    ytmp = np.zeros(y0.size)
    err = S.step_error3d(N, h, tol, y0, y1, K, ytmp)
    assert err == pytest.approx(_expected(N, h, tol, y0, y1, K), rel=1e-12)
    assert err > 1.0  # (the e/u terms dominate W's here: the checks below see them)
    # drift along e_j (end-of-step direction) in every stage: removed by the projection, no error
    c = rng.normal(size=(R.NSX, 2, N))
    Kr = K.copy()
    for part in range(2):
        for k in range(3):
            Kr[:, 3 * N * part + k * N:3 * N * part + (k + 1) * N] += c[:, part, :] * e1[:, k][None, :] * 1e-5
    assert S.step_error3d(N, h, tol, y0, y1, Kr, ytmp) == pytest.approx(err, rel=1e-9)
    # a rotation of space
    Kq = np.array([_rotate(k, N, ROT) for k in K])
    assert S.step_error3d(N, h, tol, _rotate(y0, N, ROT), _rotate(y1, N, ROT), Kq, ytmp) == pytest.approx(err, rel=1e-12)


def test_a_rotated_problem_takes_the_same_steps():
    p = Problem3D.catenary(0.25, 30).perturbed(1e-2)
    q = dataclasses.replace(p, r=p.r @ ROT.T, v=p.v @ ROT.T, g_dir=tuple(ROT @ np.array(p.g_dir)),
                            normal=tuple(ROT @ np.array(p.normal)))
    a, b = run3d(p, tol=1e-6), run3d(q, tol=1e-6)
    assert a["n_steps"] == b["n_steps"] and abs(a["n_rejected"] - b["n_rejected"]) <= 2
    for k in ("v_peak", "a_peak", "sigma_peak", "z_amp_snap"):  # (measured <= 4e-12; per-component norm 6e-9)
        assert b[k] == pytest.approx(a[k], rel=1e-10, abs=0)
