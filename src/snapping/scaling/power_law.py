"""Power-law fits y ~ A (t* - t)^beta on a window, t* given or fitted jointly, with the three
uncertainties of an exponent (statistical, window, t*) (:func:`fit_power_law`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from .. import _validate as V
from ._loglog import _MIN_POINTS, _WLS, _arrays, _loglog, _weights, _wls
from .peak import peak_time
from .slopes import find_window


@dataclass(frozen=True)
class PowerLawFit:
    """A fit y = A (t* - t)^beta on a window of t* - t, with its uncertainty.

    Attributes
    ----------
    beta, beta_err : float
        Exponent and its total uncertainty (the three parts below in quadrature).
    beta_err_stat, beta_err_window, beta_err_t_star, beta_err_drift : float
        Parts of the uncertainty: least-squares standard error, window choice,
        t* (given: its +-t_star_err; fitted: its 1-sigma profile interval), and
        drift (half the change of the local slope across the window, from a
        quadratic fit on log-log axes: the exponent is not constant by that much).
    A, A_err : float
        Prefactor (y at t* - t = 1 on the fitted line) and its uncertainty, combined
        like beta's (from the intercept on log axes).
    t_star, t_star_err : float
        The snapping time used (given or fitted) and its uncertainty.
    t_star_fitted : bool
        Whether t* was fitted jointly.
    tau_lo, tau_hi : float
        The window of t* - t used.
    window_auto : bool
        Whether the window was chosen by :func:`find_window`.
    flat : bool
        Whether the automatic window met the flatness tolerance (always True for a
        given window).
    n_points : int
        Samples in the window.
    rms : float
        Weighted rms residual of log10 y about the line.
    """

    beta: float
    beta_err: float
    A: float
    A_err: float
    t_star: float
    t_star_err: float
    t_star_fitted: bool
    tau_lo: float
    tau_hi: float
    n_points: int
    beta_err_stat: float
    beta_err_window: float
    beta_err_t_star: float
    beta_err_drift: float
    window_auto: bool
    flat: bool
    rms: float
    notes: tuple[str, ...] = field(default_factory=tuple)

    def predict(self, tau) -> np.ndarray:
        """The fitted power law A tau^beta at ``tau``."""
        return self.A * np.asarray(tau, dtype=float) ** self.beta

    def to_dict(self) -> dict:
        d = asdict(self)
        d["notes"] = list(self.notes)
        return d


def _select(t, y, t_star, tau_lo, tau_hi):
    X, Y, w, ts = _loglog(t, y, t_star)
    lo, hi = math.log10(tau_lo), math.log10(tau_hi)
    i0 = np.searchsorted(X, lo - 1e-12, side="left")
    i1 = np.searchsorted(X, hi + 1e-12, side="right")
    return X[i0:i1], Y[i0:i1], w[i0:i1], ts[i0:i1]


def _drift(t, y, t_star, tau_lo, tau_hi) -> tuple[float, float]:
    """Half the change of the local slope across the window, from a weighted quadratic
    fit log10 y = a + b X + c X^2 (local slope b + 2 c X): |c| (X_hi - X_lo)."""
    X, Y, w, _ = _select(t, y, t_star, tau_lo, tau_hi)
    if X.size < _MIN_POINTS:
        return 0.0, 0.0
    xm = float(w @ X) / float(w.sum())
    Xc = X - xm
    sw = np.sqrt(w)
    M = np.stack([np.ones_like(Xc), Xc, Xc * Xc], axis=1) * sw[:, None]
    coef, *_ = np.linalg.lstsq(M, Y * sw, rcond=None)
    # the slope uncertainty pivots the line about the window centre xm: the intercept
    # (log10 A at tau = 1) moves by drift * |xm|
    return float(abs(coef[2]) * (X[-1] - X[0])), xm


def _fit_fixed(t, y, t_star, tau_lo, tau_hi) -> _WLS | None:
    X, Y, w, _ = _select(t, y, t_star, tau_lo, tau_hi)
    if X.size < _MIN_POINTS or X[-1] - X[0] <= 0:
        return None
    return _wls(X, Y, w)


class _Profile:
    """Weighted least squares on a fixed set of samples as a function of t*."""

    def __init__(self, ts: np.ndarray, ys: np.ndarray):
        self.ts = ts
        self.Y = np.log10(ys)
        self.t_b = float(ts.max())

    def fit(self, t_star: float) -> _WLS:
        X = np.log10(t_star - self.ts)
        order = np.argsort(X, kind="stable")
        X, Y = X[order], self.Y[order]
        return _wls(X, Y, _weights(X))

    def wrss(self, u: float) -> float:
        t_star = self.t_b + 10.0**u
        if not t_star > self.t_b:
            return math.inf
        return self.fit(t_star).wrss


def _joint(t, y, t_guess, tau_lo, tau_hi, notes: list[str]):
    """Fit t* by profiling on the samples of the window (chosen with ``t_guess``).

    Returns (t_star, t_star_err, fit, beta range over the 1-sigma t* interval)."""
    _, Y, _, ts = _select(t, y, t_guess, tau_lo, tau_hi)
    if ts.size < _MIN_POINTS + 1:
        return None
    prof = _Profile(ts, 10.0**Y)
    gap = t_guess - prof.t_b  # >= tau_lo
    u_lo = math.log10(max(gap, tau_lo)) - 3.0
    u_lo = max(u_lo, math.log10(64 * np.finfo(float).eps * max(abs(prof.t_b), 1e-300)))
    u_hi = math.log10(tau_hi) + 0.5
    us = np.linspace(u_lo, u_hi, 121)
    rs = np.array([prof.wrss(u) for u in us])
    k = int(np.nanargmin(rs))
    if k == 0 or k == us.size - 1:
        notes.append(
            "t* fit: the best t* lies at the edge of the search range "
            f"(t* - last sample = {10**us[k]:.3g}); t* is not determined by this window"
        )
    a, b = us[max(k - 1, 0)], us[min(k + 1, us.size - 1)]
    res = minimize_scalar(prof.wrss, bounds=(a, b), method="bounded", options={"xatol": 1e-10})
    u_best = float(res.x) if res.fun <= rs[k] else float(us[k])
    best = prof.fit(prof.t_b + 10.0**u_best)
    t_best = prof.t_b + 10.0**u_best
    # 1-sigma profile interval: wrss rises by one residual variance
    target = best.wrss + best.s2

    def g(u):
        return prof.wrss(u) - target

    ends = []
    for direction in (-1.0, 1.0):
        u1 = u_best
        step = 0.01
        found = None
        for _ in range(60):
            u2 = u1 + direction * step
            if g(u2) > 0:
                found = brentq(g, min(u1, u2), max(u1, u2), xtol=1e-12)
                break
            u1, step = u2, step * 1.5
            if u1 < u_lo - 6 or u1 > u_hi + 2:
                break
        ends.append(found)
    t_ends = [prof.t_b + 10.0**u for u in ends if u is not None]
    if len(t_ends) < 2:
        notes.append("t* fit: the 1-sigma profile interval of t* is open on one side")
    t_err = max((abs(te - t_best) for te in t_ends), default=float("inf"))
    betas = [prof.fit(te) for te in t_ends]
    return t_best, t_err, best, betas


#: largest edge displacement of the window uncertainty (decades)
_MAX_PERTURB = 3.0


def fit_power_law(
    t,
    y,
    t_star: float | None = None,
    *,
    t_star_err: float = 0.0,
    t_star_guess: float | None = None,
    window: tuple[float, float] | None = None,
    min_width: float = 1.0,
    tol: float = 1e-3,
    prefer: str = "widest",
    slope_range: tuple[float, float] | None = None,
    perturb: float = 0.25,
    span: float = 0.5,
    spacing: float = 0.05,
    name: str = "y",
) -> PowerLawFit:
    """Fit y(t) = A (t* - t)^beta on a window of t* - t, with an honest uncertainty.

    The paper's asymptotic scalings (eq. asymptoticscalings) are power laws of
    tau = t* - t: v ~ tau^-1/3, a ~ tau^-4/3, sigma ~ tau^-2/3, and the maximum
    curvature's anomalous kappa_m ~ tau^-1/6. This fits such a law by weighted
    least squares on log-log axes (weights: the log10 tau interval of each
    sample).

    * ``t_star`` given: beta and A by least squares; its uncertainty
      ``t_star_err`` (e.g. the spread of the snapping times from v, a, sigma) is
      propagated by refitting at t* +- t_star_err.
    * ``t_star`` None: t* is fitted jointly, by profiling the residual over t*
      (beta and A by least squares for each candidate t*) on the samples of the
      window; the 1-sigma interval of t* is where the residual sum of squares has
      risen by one residual variance. Window and t* are iterated to consistency.
    * ``window`` None: chosen by :func:`find_window` where the local slope is
      flat; otherwise ``(tau_lo, tau_hi)``.

    The uncertainty combines (in quadrature) the least-squares standard error,
    the window choice (largest change of beta when either edge moves by a
    factor 10^(+-perturb)) and the t* choice; see the module docstring.

    Parameters
    ----------
    t, y : array_like
        Samples (e.g. ``run.t`` and ``run.v_max``).
    t_star : float, optional
        Snapping time; fitted when None.
    t_star_err : float
        Uncertainty of a given t* (>= 0).
    t_star_guess : float, optional
        Starting t* of a joint fit (default: the time of the peak of y, or just
        past the last sample if y is still rising there).
    window : (float, float), optional
        ``(tau_lo, tau_hi)`` with 0 < tau_lo < tau_hi, overriding the automatic one.
    min_width, tol, prefer, slope_range, span, spacing
        Automatic window, see :func:`find_window`.
    perturb : float
        Edge displacement in decades for the window uncertainty (>= 0).
    name : str
        Name of the quantity in error messages.

    Returns
    -------
    PowerLawFit

    Raises
    ------
    SnappingInputError
        Bad parameters, or a window holding fewer than 5 samples (outside the data).

    Examples
    --------
    >>> tau = np.logspace(-6, 0, 400)
    >>> f = fit_power_law(1.2 - tau, 0.437 * tau ** (-2 / 3), t_star=1.2)
    >>> round(f.beta, 6), round(f.A, 6)
    (-0.666667, 0.437)
    >>> g = fit_power_law(1.2 - tau, 0.437 * tau ** (-2 / 3))   # t* fitted too
    >>> round(g.t_star, 6)
    1.2
    """
    t_star_err = V.real("t_star_err", t_star_err)
    if not t_star_err >= 0:
        raise V.SnappingInputError(f"t_star_err={t_star_err!r} is out of range: must be a finite number >= 0")
    perturb = V.real("perturb", perturb)
    if not 0 <= perturb <= _MAX_PERTURB:
        raise V.SnappingInputError(f"perturb={perturb!r} is out of range: must lie in [0, {_MAX_PERTURB:g}] (decades)")
    t, y = _arrays(t, y, name)
    if window is not None:
        try:
            tau_lo, tau_hi = (float(window[0]), float(window[1]))
        except (TypeError, ValueError, IndexError, OverflowError):
            raise V.SnappingInputError(f"window={window!r} must be a pair (tau_lo, tau_hi)") from None
        if not (0 < tau_lo < tau_hi < math.inf):
            raise V.SnappingInputError(
                f"window={window!r} is out of range: needs 0 < tau_lo < tau_hi (values of t* - t)"
            )
    notes: list[str] = []
    fitted = t_star is None
    if fitted:
        if t_star_guess is None:
            i = int(np.argmax(y))
            if i < t.size - 1:
                t_guess = peak_time(t, y, name=name).t
            else:
                t_guess = float(t[-1] + (t[-1] - t[-2]))
        else:
            t_guess = V.real("t_star_guess", t_star_guess)
            if not (np.count_nonzero(t < t_guess) >= _MIN_POINTS and t_guess <= t[-1] + (t[-1] - t[0])):
                raise V.SnappingInputError(
                    f"t_star_guess={t_guess!r} is out of range: must lie after {_MIN_POINTS} samples and not past "
                    f"t[-1] + (t[-1] - t[0]) = {2 * t[-1] - t[0]:.6g}")
    else:
        t_star = V.real("t_star", t_star)
        t_guess = t_star
        if t_star > t[0] and not t_star_err < t_star - t[0]:
            raise V.SnappingInputError(f"t_star_err={t_star_err!r} is out of range: must be < t* - t[0] = "
                                       f"{t_star - t[0]:.6g} (the time the data span before t*)")

    kw = dict(min_width=min_width, tol=tol, prefer=prefer, slope_range=slope_range, span=span, spacing=spacing)

    def choose(ts_):
        if window is not None:
            _check_window(t, y, ts_, tau_lo, tau_hi, name)
            return tau_lo, tau_hi, True
        w = find_window(t, y, ts_, **kw, t_star_name="t_star" if not fitted else "t_star_guess")
        if not w.flat:
            notes.append(
                f"no window of {min_width:g} decades is flat within tol={tol:g}; "
                f"accepted local-slope deviation {w.tol:.3g}"
            )
        return w.tau_lo, w.tau_hi, w.flat

    if not fitted:
        lo, hi, flat = choose(t_star)
        f0 = _fit_fixed(t, y, t_star, lo, hi)
        if f0 is None:
            raise V.SnappingInputError(f"window=({lo:.3g}, {hi:.3g}) of t* - t holds fewer than {_MIN_POINTS} samples of {name}")
        t_fit, t_err = t_star, t_star_err
        err_t_b, err_t_a = 0.0, 0.0
        for dt in (-t_star_err, t_star_err):
            if dt == 0:
                continue
            fs = _fit_fixed(t, y, t_star + dt, lo, hi)
            if fs is None:
                notes.append("t* +- t_star_err leaves too few samples in the window")
                continue
            err_t_b = max(err_t_b, abs(fs.b - f0.b))
            err_t_a = max(err_t_a, abs(fs.a - f0.a))
    else:
        t_cur = t_guess
        res = None
        for _ in range(6):
            lo, hi, flat = choose(t_cur)
            res = _joint(t, y, t_cur, lo, hi, notes)
            if res is None:
                raise V.SnappingInputError(
                    f"window=({lo:.3g}, {hi:.3g}) of t* - t holds too few samples of {name} to fit t*"
                )
            t_new = res[0]
            if abs(t_new - t_cur) <= 1e-3 * lo:
                t_cur = t_new
                break
            t_cur = t_new
        t_fit, t_err, f0, fends = res
        # the window in tau relative to the fitted t*
        f0 = _fit_fixed(t, y, t_fit, lo, hi) or f0
        err_t_b = max((abs(fe.b - f0.b) for fe in fends), default=float("inf"))
        err_t_a = max((abs(fe.a - f0.a) for fe in fends), default=float("inf"))

    # window choice
    err_w_b, err_w_a = 0.0, 0.0
    if perturb > 0:
        for dlo in (-perturb, 0.0, perturb):
            for dhi in (-perturb, 0.0, perturb):
                if dlo == 0.0 and dhi == 0.0:
                    continue
                plo, phi = lo * 10.0**dlo, hi * 10.0**dhi
                if math.log10(phi / plo) < 0.5 * math.log10(hi / lo):
                    continue
                if fitted:
                    r = _joint(t, y, t_fit, plo, phi, [])
                    fp = None if r is None else r[2]
                else:
                    fp = _fit_fixed(t, y, t_fit, plo, phi)
                if fp is None:
                    continue
                err_w_b = max(err_w_b, abs(fp.b - f0.b))
                err_w_a = max(err_w_a, abs(fp.a - f0.a))
    drift, xm = _drift(t, y, t_fit, lo, hi)
    beta_err = math.sqrt(f0.se_b**2 + err_w_b**2 + err_t_b**2 + drift**2)
    la_err = math.sqrt(f0.se_a**2 + err_w_a**2 + err_t_a**2 + (drift * xm) ** 2)
    A = 10.0**f0.a
    A_err = A * (10.0**la_err - 1.0)
    return PowerLawFit(
        beta=float(f0.b),
        beta_err=float(beta_err),
        A=float(A),
        A_err=float(A_err),
        t_star=float(t_fit),
        t_star_err=float(t_err),
        t_star_fitted=fitted,
        tau_lo=float(lo),
        tau_hi=float(hi),
        n_points=int(f0.n),
        beta_err_stat=float(f0.se_b),
        beta_err_window=float(err_w_b),
        beta_err_t_star=float(err_t_b),
        beta_err_drift=float(drift),
        window_auto=window is None,
        flat=bool(flat),
        rms=float(math.sqrt(f0.wrss / f0.n_eff)),
        notes=tuple(notes),
    )


def _check_window(t, y, t_star, tau_lo, tau_hi, name):
    tau = t_star - t
    ok = (tau > 0) & (y > 0)
    if not np.any(ok):
        raise V.SnappingInputError(f"t_star={t_star!r}: no samples of {name} before t*")
    dmin, dmax = float(tau[ok].min()), float(tau[ok].max())
    n_in = int(np.count_nonzero(ok & (tau >= tau_lo * (1 - 1e-12)) & (tau <= tau_hi * (1 + 1e-12))))
    if n_in < _MIN_POINTS:
        raise V.SnappingInputError(
            f"window=({tau_lo:.6g}, {tau_hi:.6g}) lies outside the data of {name}: holds {n_in} samples "
            f"(at least {_MIN_POINTS} needed); t* - t spans [{dmin:.6g}, {dmax:.6g}]"
        )
