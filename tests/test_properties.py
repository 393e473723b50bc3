"""Property-based tests (hypothesis, #7): the estimates, the tridiagonal tension solve,
and the power-law fit, on random inputs."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from scipy.linalg import solve_banded

from snapping import estimates
from snapping.scaling import fit_power_law
from snapping.simulate import kernels as K

PROFILE = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
chis = st.floats(min_value=1e-6, max_value=1.0 - 1e-6, allow_nan=False)


# ---------------------------------------------------------------- estimates
@PROFILE
@given(chi=chis)
def test_catenary_parameter_solves_the_length_equation(chi):
    """1 = 2 a sinh(chi / (2 a)) (unit length between ends chi apart), and chi_from_parameter inverts it."""
    a = estimates.catenary_parameter(chi)
    assert a > 0
    b = chi / (2 * a)
    # residual in the form the solver uses, log(sinh(b)/b) = -log(chi), relative to its size
    residual = estimates._log_sinhc(b) + math.log(chi)
    assert abs(residual) <= 1e-12 * max(1.0, -math.log(chi))
    assert estimates.chi_from_parameter(a) == pytest.approx(chi, rel=1e-12, abs=1e-15)


@PROFILE
@given(c1=chis, c2=chis)
def test_available_energy_is_monotone_between_a_quarter_and_a_half(c1, c2):
    assume(c1 != c2)
    lo, hi = sorted((c1, c2))
    p_lo, p_hi = estimates.available_energy(lo), estimates.available_energy(hi)
    assert 0.25 < p_lo <= p_hi < 0.5
    if hi - lo > 1e-6:
        assert p_lo < p_hi


# ---------------------------------------------------------------- tension solve
def _random_chain(N: int, seed: int, spread: float, speed: float):
    """Links of length exactly 1/N at angles of a random walk, node N at the pin, random velocities."""
    rng = np.random.default_rng(seed)
    theta = rng.uniform(0, 2 * np.pi) + np.cumsum(spread * rng.standard_normal(N))
    d = np.stack([np.cos(theta), np.sin(theta)]) / N  # d_j = r_{j+1} - r_j
    r = np.zeros((2, N + 1))
    for j in range(N - 1, -1, -1):
        r[:, j] = r[:, j + 1] - d[:, j]
    v = np.zeros((2, N + 1))
    v[:, :N] = speed * rng.standard_normal((2, N))
    return r, v


def _reference_tension(r, v):
    """The tension system of the appendix assembled as a banded matrix and solved by scipy."""
    N = r.shape[1] - 1
    d = np.diff(r, axis=1)
    dv = np.diff(v, axis=1)
    c = N * N * np.einsum("ij,ij->j", d[:, :-1], d[:, 1:])  # coupling of links j and j+1
    diag = np.full(N, -2.0)
    diag[-1] = -1.0
    rhs = -np.einsum("ij,ij->j", dv, dv)
    rhs[-1] += d[1, -1]
    ab = np.zeros((3, N))
    ab[0, 1:] = c
    ab[1] = diag
    ab[2, :-1] = c
    sig = solve_banded((1, 1), ab, rhs)
    acc = np.zeros((2, N + 1))
    fl = sig * d  # sigma_j d_j
    acc[:, :N] = N * N * (fl - np.concatenate([np.zeros((2, 1)), fl[:, :-1]], axis=1))
    acc[1, :N] += 1.0
    return sig, acc


@PROFILE
@given(N=st.integers(1, 300), seed=st.integers(0, 2**32 - 1), spread=st.floats(0.0, 1.5),
       speed=st.floats(0.0, 5.0))
def test_tension_kernel_matches_banded_solve(N, seed, spread, speed):
    r, v = _random_chain(N, seed, spread, speed)
    Z = np.zeros((K.NROWS, N + 1))
    Z[K.RX], Z[K.RY], Z[K.RVX], Z[K.RVY] = r[0], r[1], v[0], v[1]
    w = np.zeros((4, N))
    sig_ref, acc_ref = _reference_tension(r, v)
    for kernel in (K.rhs, K.rhs_thomas):
        Zk = Z.copy()
        kernel(N, Zk, w[0], w[1], w[2], w[3])
        scale = 1.0 + np.abs(sig_ref).max()
        tol = 1e-15 * scale * (N + 1) ** 2  # the system's condition number grows like N^2 (seen: ~2e-17 N^2)
        np.testing.assert_allclose(Zk[K.RSIG, :N], sig_ref, rtol=0, atol=tol)
        np.testing.assert_allclose(Zk[K.RAX], acc_ref[0], rtol=0, atol=tol * (N + 1))
        np.testing.assert_allclose(Zk[K.RAY], acc_ref[1], rtol=0, atol=tol * (N + 1))
        assert Zk[K.RSIG, N] == 0.0 and Zk[K.RAX, N] == 0.0 and Zk[K.RAY, N] == 0.0


# ---------------------------------------------------------------- power-law fits
@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(beta=st.floats(-2.0, 1.5).filter(lambda b: abs(b) > 0.05), log_A=st.floats(-3.0, 3.0),
       t_star=st.floats(0.2, 5.0), lo=st.floats(-7.0, -4.0), n=st.integers(60, 400))
def test_fit_recovers_exact_power_laws(beta, log_A, t_star, lo, n):
    A = 10.0**log_A
    tau = np.logspace(lo, 0.0, n)
    t = t_star - tau
    y = A * tau**beta
    f = fit_power_law(t, y, t_star=t_star)
    assert f.beta == pytest.approx(beta, abs=1e-8)
    assert f.A == pytest.approx(A, rel=1e-7)
    assert f.beta_err < 1e-6 and f.t_star == t_star


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(beta=st.floats(-1.5, -0.2), log_A=st.floats(-1.0, 1.0), t_star=st.floats(0.5, 2.0))
def test_joint_fit_recovers_the_singular_time(beta, log_A, t_star):
    A = 10.0**log_A
    tau = np.logspace(-6, 0, 300)
    f = fit_power_law(t_star - tau, A * tau**beta)
    assert f.t_star_fitted
    assert f.t_star == pytest.approx(t_star, abs=1e-6)
    assert f.beta == pytest.approx(beta, abs=2e-3)
