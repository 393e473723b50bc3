"""The exact motion of the folded string: s0(t) and its derivatives, the tensions and the free end's
speed and acceleration at any t in [0, t*) (:func:`kink_state`, by inverting the first integral's
time map), and the energy of a kink state (:func:`kink_energy`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .. import _validate as V
from .._validate import SnappingInputError
from .snap_time import _T_HI, _T_LO, _T_STR


_GL_N = 24
_GL_V, _GL_W = np.polynomial.legendre.leggauss(_GL_N)
_GL_V = 0.5 * (_GL_V + 1.0)  # nodes on [0, 1]
_GL_W = 0.5 * _GL_W
_CHUNK = 1 << 15


def _tau_of_theta(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """tau(theta) = int_0^theta sqrt(sin u) du and d tau/d theta = sqrt(sin theta).

    With x = sin(theta)/2 this is t* - t (dt = -dx/s0' and s0' = cos th /(2 sqrt(sin th))).
    Computed as 2 theta^(3/2) int_0^1 v^2 sqrt(sinc(theta v^2)) dv by Gauss-Legendre
    (smooth for theta <= ~2): full relative precision as theta -> 0.
    """
    z = theta[:, None] * (_GL_V**2)[None, :]
    sinc = np.sinc(z / np.pi)
    integral = np.sqrt(sinc) @ (_GL_W * _GL_V**2)
    return 2.0 * theta**1.5 * integral, np.sqrt(np.sin(theta))


def _t_of_phi(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """t(phi) = int_0^phi sqrt(cos u) du, phi = pi/2 - theta, and dt/dphi (early times)."""
    z = phi[:, None] * _GL_V[None, :]
    integral = np.sqrt(np.cos(z)) @ _GL_W
    return phi * integral, np.sqrt(np.cos(phi))


def _solve_theta(tau: np.ndarray) -> np.ndarray:
    """theta with tau(theta) = tau, Newton on tau(theta)^(2/3) (nearly linear in theta)."""
    target = np.cbrt(tau) ** 2
    theta = np.cbrt(1.5 * tau) ** 2  # leading-order asymptote
    extra = 2  # quadratic convergence: two more steps after |step| < 1e-9 reach rounding level
    for _ in range(40):
        f, df = _tau_of_theta(theta)
        g = np.cbrt(f) ** 2 - target
        dg = (2.0 / 3.0) * df / np.cbrt(f)
        step = g / dg
        theta = theta - step
        if np.all(np.abs(step) <= 1e-9 * np.abs(theta)):
            extra -= 1
            if extra < 0:
                break
    else:  # pragma: no cover - never seen
        raise RuntimeError("kink inversion (theta) did not converge")
    return theta


def _solve_phi(t: np.ndarray) -> np.ndarray:
    """phi with t(phi) = t (early times), Newton."""
    phi = t.copy()
    extra = 2
    for _ in range(40):
        f, df = _t_of_phi(phi)
        step = (f - t) / df
        phi = phi - step
        if np.all(np.abs(step) <= 1e-9 * np.abs(phi)):
            extra -= 1
            if extra < 0:
                break
    else:  # pragma: no cover - never seen
        raise RuntimeError("kink inversion (phi) did not converge")
    return phi


@dataclass(frozen=True)
class KinkState:
    """State of the folded string at times t (arrays of the input's shape).

    Attributes
    ----------
    t : ndarray
        Time.
    tau : ndarray
        Time to snap t* - t, computed with t* in double-double (full relative
        precision even for tau ~ 1e-12).
    s0, s0_dot, s0_ddot : ndarray
        Kink position s0 and its first two time derivatives.
    moving_arm_length : ndarray
        x = 1 - s0, with full relative precision as t -> t*.
    tether_tension : ndarray
        sigma(0, t) = s0 + s0'^2 (pin tension).
    fold_tension : ndarray
        Tension at the kink, s0'^2 (equal on both sides of the energy-conserving fold).
    free_end_speed, free_end_acceleration : ndarray
        2 s0' and 2 s0'' (the whole moving arm moves at this speed; it is the
        maximum speed in the string).
    """

    t: np.ndarray
    tau: np.ndarray
    s0: np.ndarray
    s0_dot: np.ndarray
    s0_ddot: np.ndarray
    moving_arm_length: np.ndarray
    tether_tension: np.ndarray
    fold_tension: np.ndarray
    free_end_speed: np.ndarray
    free_end_acceleration: np.ndarray


def _as_array(name: str, value: ArrayLike) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise SnappingInputError(f"{name}={value!r} is not a real number or array of real numbers") from None
    except OverflowError:  # an integer beyond the doubles (10**400)
        raise SnappingInputError(f"{name} holds a number too large for a float (|x| < 1.8e308)") from None
    if arr.size and not np.all(np.isfinite(arr)):
        bad = float(arr.ravel()[~np.isfinite(arr.ravel())][0])
        raise SnappingInputError(f"{name}={bad!r} must be a finite real number")
    return arr


#: smallest t* - t accepted (below, s0'' ~ tau^(-4/3) overflows a double)
TAU_MIN = 1e-230


def kink_state(t: ArrayLike | None = None, *, tau: ArrayLike | None = None) -> KinkState:
    """Exact state of the perfectly folded string at times ``t`` (or ``t* - t = tau``).

    Solves the kink ODE (paper, before eq. shockvelocity, sign corrected) via its
    first integral, eq. (shockvelocity), by inverting the time map in the
    variable theta with x = 1 - s0 = sin(theta)/2:

        t* - t = int_0^theta sqrt(sin u) du,

    (Newton on tau(theta)^(2/3), which is nearly linear in theta, so x, s0' and
    s0'' keep full relative precision as t -> t*), and for t < t*/2 in
    phi = pi/2 - theta with t = int_0^phi sqrt(cos u) du (full precision as
    t -> 0). Then s0' = cos(theta)/(2 sqrt(sin theta)) and
    s0'' = 1/2 + cot(theta)^2/4.

    Parameters
    ----------
    t : array_like, optional
        Times in [0, t*).
    tau : array_like, keyword-only, optional
        Times to snap t* - t in [TAU_MIN, t*] (TAU_MIN = 1e-230), instead of ``t``;
        use this to resolve tau below the double spacing near t* (~2e-16).

    Returns
    -------
    KinkState
        Arrays of the shape of the input (0-d arrays for scalars).

    Raises
    ------
    SnappingInputError
        If both or neither of ``t``/``tau`` are given, or a value is not finite
        or outside [0, t*) (``t``) / (0, t*] (``tau``).

    Examples
    --------
    >>> st = kink_state([0.0, 1.0])
    >>> st.s0.round(12)
    array([0.5       , 0.78364712])
    >>> st = kink_state(tau=1e-9)
    >>> float(st.s0_dot * 1e-9 ** (1 / 3))            # -> 12^(-1/3) = 0.43679...
    0.43679...
    """
    if (t is None) == (tau is None):
        raise SnappingInputError("give exactly one of t (in [0, t*)) or tau = t* - t (in (0, t*])")
    if t is not None:
        tt = _as_array("t", t)
        tau_arr = (_T_HI - tt) + _T_LO  # exact difference (Sterbenz) + low part
        bad = (tt < 0.0) | ~(tau_arr > 0.0)
        if np.any(bad):
            val = float(tt.ravel()[bad.ravel()][0])
            raise SnappingInputError(
                f"t={val!r} is out of range: must lie in [0, t*) with t* = 2E(pi/4|2) = {_T_STR}..."
            )
    else:
        tau_arr = _as_array("tau", tau)
        bad = ~(tau_arr >= TAU_MIN) | (tau_arr > _T_HI)
        if np.any(bad):
            val = float(tau_arr.ravel()[bad.ravel()][0])
            raise SnappingInputError(
                f"tau={val!r} is out of range: must lie in [{TAU_MIN:g}, t*] with t* = {_T_HI!r} (tau = t* - t; "
                f"closer to t* the acceleration ~ tau^(-4/3) leaves the doubles)"
            )
        tt = (_T_HI - tau_arr) + _T_LO
        tt = np.where(tau_arr >= _T_HI, 0.0, tt)  # tau = t* (as a double) means t = 0
    shape = tt.shape
    tt = tt.ravel()
    tau_f = tau_arr.ravel()

    sin_th = np.empty_like(tt)
    cos_th = np.empty_like(tt)
    late = tt >= 0.5 * _T_HI
    for start in range(0, tt.size, _CHUNK):
        sl = slice(start, start + _CHUNK)
        lt = late[sl]
        if np.any(lt):
            th = _solve_theta(tau_f[sl][lt])
            sin_th[sl][lt] = np.sin(th)
            cos_th[sl][lt] = np.cos(th)
        if np.any(~lt):
            ph = _solve_phi(tt[sl][~lt])
            sin_th[sl][~lt] = np.cos(ph)
            cos_th[sl][~lt] = np.sin(ph)

    x = 0.5 * sin_th
    s0_ = 1.0 - x
    with np.errstate(over="ignore"):  # tau < ~1e-230 overflows s0'' to inf
        sd = cos_th / (2.0 * np.sqrt(sin_th))
        sdd = 0.5 + 0.25 * (cos_th / sin_th) ** 2
        sd2 = sd * sd

    def r(a: np.ndarray) -> np.ndarray:
        return a.reshape(shape)[()]  # numpy scalars for scalar input

    return KinkState(
        t=r(tt),
        tau=r(tau_f),
        s0=r(s0_),
        s0_dot=r(sd),
        s0_ddot=r(sdd),
        moving_arm_length=r(x),
        tether_tension=r(s0_ + sd2),
        fold_tension=r(sd2),
        free_end_speed=r(2.0 * sd),
        free_end_acceleration=r(2.0 * sdd),
    )


def s0(t: ArrayLike) -> np.ndarray:
    """Kink position s0(t) of the folded string (paper eq. shockvelocity, integrated).

    Parameters
    ----------
    t : array_like
        Times in [0, t*).

    Returns
    -------
    ndarray
        s0 in [1/2, 1), same shape as ``t``.

    Examples
    --------
    >>> s0([0.0, 0.6, 1.19]).round(6)
    array([0.5     , 0.593083, 0.973498])
    """
    return kink_state(t).s0


def s0_dot(t: ArrayLike) -> np.ndarray:
    """Kink speed s0'(t) = sqrt((1 - 4x^2)/(8x)), x = 1 - s0 (paper eq. shockvelocity).

    Near t*: s0' ~ 12^(-1/3) (t* - t)^(-1/3). This is the *kink* speed; the
    free end (and the whole moving arm) moves at twice it, see
    :func:`free_end_speed`.

    Examples
    --------
    >>> s0_dot([0.0, 0.6]).round(6)
    array([0.      , 0.322071])
    """
    return kink_state(t).s0_dot


def s0_ddot(t: ArrayLike) -> np.ndarray:
    """Kink acceleration s0''(t) = (1/2)(1 + s0'^2/(1 - s0)) (the kink ODE, sign-corrected).

    Near t*: s0'' ~ (1/3) 12^(-1/3) (t* - t)^(-4/3).

    Examples
    --------
    >>> float(s0_ddot(0.0))
    0.5
    """
    return kink_state(t).s0_ddot


def moving_arm_length(t: ArrayLike) -> np.ndarray:
    """Length x = 1 - s0 of the moving arm, with full relative precision near t*.

    Near t*: x ~ (9/32)^(1/3) (t* - t)^(2/3). (The paper's cruder line through
    the initial point, (1/2)((t* - t)/t*)^(2/3), has a different prefactor.)

    Examples
    --------
    >>> float(moving_arm_length(0.0))
    0.5
    """
    return kink_state(t).moving_arm_length


def tether_tension(t: ArrayLike) -> np.ndarray:
    """Pin (tether) tension sigma(0, t) = s0 + s0'^2 (paper, after eq. for t*).

    From the momentum balance of the whole string; near t* it is
    ~ 12^(-2/3) (t* - t)^(-2/3).

    Examples
    --------
    >>> float(tether_tension(0.0))
    0.5
    """
    return kink_state(t).tether_tension


def fold_tension(t: ArrayLike) -> np.ndarray:
    """Tension at the kink, s0'^2 (the momentum flux through an energy-conserving fold).

    Examples
    --------
    >>> float(fold_tension(0.0))
    0.0
    """
    return kink_state(t).fold_tension


def free_end_speed(t: ArrayLike) -> np.ndarray:
    """Speed of the free end (and of the whole moving arm), 2 s0'.

    This is the maximum speed in the string; near t* it is
    ~ (2/3)^(1/3) (t* - t)^(-1/3) (twice the kink-speed prefactor 12^(-1/3)).

    Examples
    --------
    >>> float(free_end_speed(0.0))
    0.0
    """
    return kink_state(t).free_end_speed


def free_end_acceleration(t: ArrayLike) -> np.ndarray:
    """Acceleration of the free end, 2 s0'' = 1 + s0'^2/(1 - s0) (> g for t > 0).

    Near t*: ~ (1/3)(2/3)^(1/3) (t* - t)^(-4/3).

    Examples
    --------
    >>> float(free_end_acceleration(0.0))   # released from rest: g
    1.0
    """
    return kink_state(t).free_end_acceleration


def kink_energy(s0: ArrayLike, s0_dot: ArrayLike) -> np.ndarray:
    """Total energy E = 2 (1 - s0) s0'^2 + (1 - s0)^2 - 1/2 (per rho g, pin at y = 0).

    Conserved (= -1/4) along the ideal solution; see :func:`derivation`.

    Examples
    --------
    >>> float(kink_energy(0.5, 0.0))
    -0.25
    """
    s = _as_array("s0", s0)
    v = _as_array("s0_dot", s0_dot)
    x = 1.0 - s
    with np.errstate(over="ignore", invalid="ignore"):
        e = 2.0 * x * v * v + x * x - 0.5
    if not np.all(np.isfinite(e)):
        raise SnappingInputError(f"s0={V._short(s0)} with s0_dot={V._short(s0_dot)} is out of range: the energy "
                                 f"2 (1 - s0) s0'^2 + (1 - s0)^2 - 1/2 overflows a double")
    return e
