"""Compression in the rigid-link model: where and when a run's link tension went negative.

A chain of rigid links can push: its tension ``sigma`` solves a linear system (the
constraint rows of :mod:`snapping.simulate.angles`) and nothing keeps it positive. A real
chain or rope cannot push; where the model's tension is negative a real line would go
slack, and the history after that point is not what a real line does (the extensible,
tension-only model is the one that goes slack). Each recorded step carries the minimum
link tension ``sigma_min`` and the arclength ``s_sigma_min`` of its link's midpoint
(:mod:`snapping.schema`); this module turns them into the run's attributes
(:func:`compression_results`) and the line its summary prints (:func:`compression_note`).

*The threshold* (why a tension below it is compression, not round-off). The tensions of a state solve ``A sigma = b`` with ``A`` symmetric tridiagonal,
diagonal ``-2`` (``-1`` in the row of the link at the held end), off-diagonal
``cos(theta_{k+1} - theta_k)``, and ``sigma_0 = 0`` at the free end. ``-A`` is positive
definite; by Perron-Frobenius (``x.(-A)x >= |x|.(D - E_1)|x|``, ``E_1`` the off-diagonal
with every cosine 1) its smallest eigenvalue is at least that string's,
``2 - 2 cos(pi/(2N + 1)) = 4 sin^2(pi/(4N + 2)) >= 4/(2N + 1)^2`` (``sin y >= 2y/pi``),
and its largest at most 4. Hence the
2-norm condition number is at most ``(2N + 1)^2``, and the computed tensions (the
Thomas elimination is backward stable on this weakly diagonally dominant system, a
backward error of a few units of round-off per row) are in error by at most about
``(2N + 1)^2 eps ||sigma||`` with ``||sigma|| = max_k |sigma_k|``. A step counts as
compressed when::

    sigma_min < -COMPRESSION_SAFETY (2N + 1)^2 eps max(1, sigma_max)

the floor 1 being the chain's weight (the force unit M g), the scale of the terms of
``b`` when every tension is near zero (a chain in free fall). (Where ``|sigma_min|`` is the
largest tension in magnitude, ``||sigma||`` is ``|sigma_min|`` and its sign is certain; the
rule then holds whichever scale is used, so ``max(1, sigma_max)`` is the whole rule.) With the safety factor 8
this is 4.3e-12 of the tension scale at N = 24 and 7e-7 at N = 10^4: far below any
tension a line notices, far above what round-off makes of a chain that never pushes.
For a general chain (unequal links or masses) the entries are rescaled by the link
lengths and masses and the bound is the uniform chain's, approximately.

Only recorded steps are seen (``record_thin = 0``, the default, records every step).

Example
-------
>>> import numpy as np
>>> from snapping.simulate import kernels as K
>>> rec = np.zeros((3, K.NREC)); rec[:, K.R_T] = [0.0, 0.1, 0.2]
>>> rec[:, K.R_SIGMAX] = 1.0; rec[:, K.R_SIGMIN] = [0.01, -1e-16, -0.5]; rec[:, K.R_SSIGMIN] = 0.9
>>> r = compression_results(rec, 24)
>>> r["t_compression"], r["min_tension"]
(0.2, -0.5)
"""

from __future__ import annotations

import math

import numpy as np

from . import kernels as K

__all__ = ["COMPRESSION_SAFETY", "compression_tolerance", "compressed_steps", "compression_results",
           "compression_note"]

#: safety factor over the condition-number bound (2N + 1)^2 eps of the tension solve
COMPRESSION_SAFETY = 8.0


def compression_tolerance(N: int) -> float:
    """The relative round-off bound ``COMPRESSION_SAFETY (2N + 1)^2 eps`` of the link tensions of an
    N-link chain (see the module's docstring).

    >>> f"{compression_tolerance(24):.3g}"
    '4.27e-12'
    """
    return COMPRESSION_SAFETY * (2.0 * N + 1.0) ** 2 * float(np.finfo(float).eps)


def compressed_steps(records: np.ndarray, N: int) -> np.ndarray:
    """Boolean mask of the recorded steps whose minimum tension is compression (below
    ``-compression_tolerance(N) max(1, sigma_max)``); False where the
    record has no ``sigma_min`` (NaN: a file written before it existed)."""
    rec = np.asarray(records, dtype=float)
    smin, smax = rec[:, K.R_SIGMIN], rec[:, K.R_SIGMAX]
    with np.errstate(invalid="ignore"):
        return smin < -compression_tolerance(N) * np.fmax(1.0, smax)


def compression_results(records: np.ndarray, N: int) -> dict:
    """The compression attributes of a run (:data:`snapping.schema.RESULT_ATTRS`) from its
    per-step record: ``min_tension`` (the smallest ``sigma_min`` recorded), ``t_min_tension``
    and ``s_min_tension`` (when and where), ``t_compression`` (the first recorded time the
    step was compressed, :func:`compressed_steps`; NaN: never) and ``compression_tolerance``.
    Empty when the record has no ``sigma_min`` column or no finite value in it."""
    rec = np.asarray(records, dtype=float)
    if rec.ndim != 2 or rec.shape[1] <= K.R_SSIGMIN or not np.any(np.isfinite(rec[:, K.R_SIGMIN])):
        return {}
    smin = rec[:, K.R_SIGMIN]
    i = int(np.nanargmin(smin))
    mask = compressed_steps(rec, N)
    t_c = float(rec[int(np.argmax(mask)), K.R_T]) if mask.any() else math.nan
    return {"min_tension": float(smin[i]), "t_min_tension": float(rec[i, K.R_T]),
            "s_min_tension": float(rec[i, K.R_SSIGMIN]), "t_compression": t_c,
            "compression_tolerance": compression_tolerance(N)}


def compression_note(attrs) -> str:
    """The summary's line on compression, or '' when the run carried none (``t_compression``
    NaN or absent)."""
    t_c = float(attrs.get("t_compression", math.nan))
    if not math.isfinite(t_c):
        return ""
    note = (f"the model carried compression from t = {t_c:.6g} on (a real line would go slack there; "
            f"see the elastic model)")
    if "min_tension" in attrs:
        note += (f"; minimum link tension {float(attrs['min_tension']):.4g} at t = "
                 f"{float(attrs.get('t_min_tension', math.nan)):.6g}, s = {float(attrs.get('s_min_tension', math.nan)):.4g}")
    return note
