"""Dispatch on a chain model's kind: the one right-hand side and the one set of per-step
diagnostics that the steppers call, for every form of the equations.

* the paper's chain (``general.KIND_UNIFORM``): :mod:`snapping.simulate.angles`, unchanged;
* a general chain (``general.KIND_GENERAL``): :func:`snapping.simulate.general.general_rhs`;
* a chain with node forces, a body (``general.KIND_BODY``): :mod:`snapping.simulate.forced`.

It sits above those modules (they do not import it), so the imports stay one way:
``angles``/``general`` -> ``forced`` -> ``models`` -> the steppers.
"""

from __future__ import annotations

from numba import njit

from . import angles as AG
from . import forced as FR
from . import general as G

__all__ = ["model_rhs", "model_measure"]


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy", inline="always")
def model_rhs(N, t, y, f, c, s, S, cp, dp, sig, mdl):
    """The derivative of y at t: the paper's uniform kernel (:func:`angles.angle_rhs`, state
    of length 2N) when ``mdl`` is the uniform model, else :func:`general_rhs`."""
    par, h, invm, invh, snode, tab = mdl
    if par[G.P_KIND] == G.KIND_UNIFORM:
        AG.angle_rhs(N, y, f, c, s, S, cp, dp, sig)
    elif par[G.P_KIND] == G.KIND_BODY:  # node forces (bending, drag): snapping.simulate.forced
        FR.forced_rhs(N, t, y, f, c, s, S, cp, dp, sig, par, h, invm, invh, snode, tab)
    else:
        G.general_rhs(N, t, y, f, c, s, S, cp, dp, sig, par, h, invm, invh, snode, tab)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy", inline="always")
def model_measure(N, t, y, c, s, sig, Z, rinv0, meas, mdl):
    """The per-step diagnostics of y at t (:func:`angles.measure_angles` for the uniform
    model, else :func:`general_measure`)."""
    par, h, invm, invh, snode, tab = mdl
    if par[G.P_KIND] == G.KIND_UNIFORM:
        AG.measure_angles(N, y, c, s, sig, Z, rinv0, meas)
    elif par[G.P_KIND] == G.KIND_BODY:
        FR.forced_measure(N, t, y, c, s, sig, Z, rinv0, meas, par, h, invm, invh, snode, tab)
    else:
        G.general_measure(N, t, y, c, s, sig, Z, rinv0, meas, par, h, invm, invh, snode, tab)
