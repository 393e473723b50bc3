"""How stiff a chain with a body is for an explicit method, and which method takes it.

The shortest wave. On a chain of links ``h_i`` and node masses ``m_i`` the node moments
``M_i = (B_i/l_i)(theta_i - theta_{i-1})`` make the zigzag of the links around node i a
wave of frequency (the fourth difference's largest eigenvalue, 16/h^4, with the tension's
second difference, 4/h^2)::

    omega_i^2 = 16 (B_i/l_i) / (m_i h_i^2) + 4 T / (m_i h_i)

(uniform links, lambda = 1: ``omega_max = 2 N sqrt(4 beta N^2 + T)``, i.e. ``sqrt(B/lambda)
(2/h)^2`` once bending dominates) with T the chain's weight, the tension scale of a hanging
chain. Kelvin-Voigt damping ``eta_i`` damps it with the ratio ``zeta_i = 8 (eta_i/l_i) /
(m_i h_i^2 omega_i)``. Checked against the eigenvalues of the chain's exact Jacobian
(``tests/test_stiffness.py``: within 10% at the catenary, N 20 and 40, beta 1e-3 and
1e-2; the damping ratio within 0.08 of the eigenvalue's).

The explicit limit. DOP853's region of absolute stability reaches ``|z| = 5.96`` on the
imaginary axis and 6.39 on the negative real axis (computed from its tableau,
:data:`R_DOP853`), so its steps are at most ~6/omega_max. Measured (``run(method="dop853")``
to t = 0.3, N = 100 and 300, beta = 1e-4 and 1e-2): with damping ratio 1 the median
accepted step is 6.3/omega_max (stability-limited: the eigenvalue is -omega_max); undamped
1.2-1.6/omega_max (the release excites the shortest waves, which the error control then
follows: accuracy-limited by them, below the stability limit). The Euler-Richardson scheme
(real-axis boundary 2, none on the imaginary axis) takes only the paper's chain, no body.

With damping ratio zeta > 1 the damping itself is stiff: the fastest eigenvalue is
``-omega (zeta + sqrt(zeta^2 - 1))`` (:func:`largest_eigenvalue`; measured dt omega_max 1.1
at zeta 3, 0.32 at zeta 10).

The choice (:func:`choose`, what ``method="fast"`` does for a problem with bending). RODAS4
(``method="rodas4"``) is L-stable, but it follows, by accuracy, the bending waves that the
damping leaves (damping ratio ``zeta omega_k/omega_max`` for Kelvin-Voigt damping): measured
``13500 sqrt(beta) N^0.37 zeta^-0.42`` steps per unit time (:func:`stiff_steps`), e.g.
N = 1000, zeta = 1: 3.4x (beta 1e-4) and 3.9x (beta 1e-2) fewer steps than DOP853; and a
step costs ~2.5 DOP853 steps of time (:data:`RODAS4_PRICE`: 6 evaluations, 6 banded
solves, a factorisation, a Jacobian). Undamped, the release's grid-scale waves
limit both methods by accuracy and RODAS4 needs 4-8x DOP853's steps. So ``fast`` takes
RODAS4 when the shortest wave is damped (``zeta >= ZETA_MIN``) and DOP853's estimated steps
(the larger of the stability limit and the accuracy-limited :func:`accuracy_steps`) exceed
``CHOICE_RATIO x RODAS4_PRICE`` (3.75) times RODAS4's; else DOP853, bit for bit as before
(with the reason in the run's ``method_choice``). At N = 300, beta = 1e-2: zeta 2 stays
DOP853 (an estimated 2.7x fewer RODAS4 steps: not enough), zeta 3, 5 and 10 are RODAS4's
(5x, 10.6x, 28x); at N = 1000 zeta 1 is RODAS4's (3.9x), at N = 100 only zeta >= ~10. Runs without a body, or
whose body has no bending, never consult this module.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from .. import _validate as V
from . import forced as FR
from . import general as G

__all__ = ["R_DOP853", "ZETA_MIN", "CHOICE_RATIO", "RODAS4_PRICE", "WARN_STEPS", "REFUSE_STEPS", "shortest_wave",
           "grid_damping", "largest_eigenvalue", "explicit_steps", "wave_of", "stiff_steps", "accuracy_steps", "choose", "check_cost",
           "CostWarning"]

#: DOP853's stability boundary (min over the imaginary and negative real axes, from its tableau)
R_DOP853 = 5.96
#: damping ratio of the shortest bending wave from which the stiff method is chosen
ZETA_MIN = 0.5
#: a RODAS4 step's time in DOP853 steps (CPU time, the least of five timings,
#: ``python benchmarks/bench_stiff_costs.py 100,300,1000``: 2.35, 2.49, 2.42 at N = 100, 300,
#: 1000, a step ~31 evaluations' time at N = 1000; whole runs, N = 1000, beta 1e-4, zeta 1,
#: to t = 0.3: 641 against 256 us of CPU per step, 2.5; was 5 before the step was made cheaper)
RODAS4_PRICE = 2.5
#: the stiff method is chosen when it is estimated this much cheaper (a margin for the estimates)
CHOICE_RATIO = 1.5
#: estimated explicit steps above which a run of an explicit method warns / is refused
WARN_STEPS = 1e6
REFUSE_STEPS = 1e9
#: the time span of an automatic run (to the snap): the folded string's t* = 1.198
T_SNAP = 1.2


class CostWarning(UserWarning):
    """A run whose stiffness makes the chosen explicit method take very many steps."""


def shortest_wave(mdl) -> tuple[float, float]:
    """``(omega_max, zeta)`` of a body model: the largest local frequency of the shortest
    wave (bending and tension, see the module) and its damping ratio; (0, 0) without
    bending."""
    par, h, invm, invh, snode, tab = mdl
    if par[G.P_KIND] != G.KIND_BODY or par[FR.P_HASBEND] == 0.0:
        return 0.0, 0.0
    N = h.size
    o = int(par[FR.P_BOFF])
    n1 = N + 1
    Bl = tab[o + FR.B_BL * n1:o + FR.B_BL * n1 + N]
    El = tab[o + FR.B_EL * n1:o + FR.B_EL * n1 + N]
    return wave_of(Bl, El, h, invm, par[G.P_G])


def wave_of(Bl, El, h, invm, g: float) -> tuple[float, float]:
    """``(omega_max, zeta)`` of node arrays ``Bl = B/l``, ``El = eta/l`` (nodes 0 .. N - 1), links
    ``h``, inverse node masses ``invm`` and gravity ``g`` (:func:`shortest_wave`'s formula; the
    3D chain's, :mod:`snapping.spatial`, is the same)."""
    N = h.size
    m = 1.0 / invm  # node masses of nodes 0 .. N - 1 (node N is held)
    hn = np.empty(N)  # a node's shorter neighbouring link
    hn[0] = h[0]
    hn[1:] = np.minimum(h[:-1], h[1:])
    weight = abs(g) * float(np.sum(m))
    w2 = 16.0 * Bl / (m * hn ** 2) + 4.0 * weight / (m * hn)
    i = int(np.argmax(w2))
    om = math.sqrt(w2[i])
    zeta = 8.0 * El[i] / (m[i] * hn[i] ** 2 * om) if om > 0.0 else 0.0
    return om, zeta


def grid_damping(h, m, bending, zeta: float = 1.0, omega_min: float = 0.0) -> np.ndarray:
    """Per-node Kelvin-Voigt damping ``eta`` (N + 1 values, index 0 the free end: a
    :class:`snapping.simulate.Body`'s ``damping``) that gives the shortest bending wave at
    every inner node the damping ratio ``zeta``, on a chain of links ``h``, node masses ``m``
    (N each, index 0 the free end) and bending stiffness ``bending`` (N + 1 node values).

    From the module's bending part of ``omega_i^2 = 16 (B_i/l_i)/(m_i hn_i^2)`` and ``zeta_i =
    8 (eta_i/l_i)/(m_i hn_i^2 omega_i)`` (``l_i`` the node's share of length, ``hn_i`` its
    shorter link): ``eta_i = (zeta/2) hn_i sqrt(B_i l_i m_i)``; on N equal links of a uniform
    line ``(zeta/2) sqrt(B) h^2`` (the regime studies' grid damping). It vanishes as h^2: a
    numerical damping of the grid-scale waves, whose effect on the peaks goes with the links
    (the fold's waves, of wavelength k links, are damped at ratio ~ zeta/k^2). The held end's
    node takes its neighbour's mass (it matters only when clamped). ``omega_min``: nodes whose
    shortest bending wave is not faster than it are left undamped.

    >>> import numpy as np
    >>> eta = grid_damping(np.full(4, 0.25), np.full(4, 0.25), np.full(5, 1e-2))
    >>> [round(float(x), 6) for x in eta]   # (1/2) 0.25^2 sqrt(1e-2) at the inner nodes
    [0.00221, 0.003125, 0.003125, 0.003125, 0.00221]
    """
    h = np.asarray(h, dtype=float)
    N = h.size
    mm = np.empty(N + 1)
    mm[:N] = np.asarray(m, dtype=float)
    mm[N] = mm[N - 1]
    hn = np.empty(N + 1)
    hn[0], hn[N] = h[0], h[N - 1]
    hn[1:N] = np.minimum(h[:-1], h[1:])
    l = np.empty(N + 1)
    l[0], l[N] = 0.5 * h[0], 0.5 * h[N - 1]
    l[1:N] = 0.5 * (h[:-1] + h[1:])
    B = np.asarray(bending, dtype=float)
    eta = 0.5 * float(zeta) * hn * np.sqrt(B * l * mm)
    if omega_min > 0.0:
        eta[16.0 * B / (l * mm * hn**2) <= omega_min**2] = 0.0
    return eta


def largest_eigenvalue(om: float, zeta: float) -> float:
    """|lambda| of the shortest wave's fastest eigenvalue: omega, or overdamped (zeta > 1)
    ``omega (zeta + sqrt(zeta^2 - 1))`` (the damping itself is then the stiffness)."""
    return om * (zeta + math.sqrt(zeta * zeta - 1.0)) if zeta > 1.0 else om


def explicit_steps(mdl, t_span: float) -> float:
    """DOP853's steps over ``t_span`` at its stability limit (a lower bound of its cost)."""
    om, zeta = shortest_wave(mdl)
    return t_span * largest_eigenvalue(om, zeta) / R_DOP853


def stiff_steps(N: int, om: float, zeta: float, t_span: float) -> float:
    """RODAS4's steps over ``t_span`` (default tol) on a chain whose shortest waves are damped:
    it follows the waves the damping leaves (damping ratio ~ zeta omega_k/omega_max), a rate
    measured as ``13500 sqrt(beta) N^0.37 zeta^-0.42`` per unit time (beta from omega_max =
    4 N^2 sqrt(beta); chi 0.25: N 300 and 1000, beta 1e-4 and 1e-2, zeta 1, 3, 10;
    ``benchmarks/bench_stiff.py``; within 1.1x there, 3x low for beta = 1 at N = 100)."""
    sqrt_beta = om / (4.0 * N * N)
    return t_span * 13500.0 * sqrt_beta * N ** 0.37 * max(zeta, 1.0) ** -0.42


def accuracy_steps(N: int, tol: float) -> float:
    """DOP853's accuracy-limited steps to the snap of a chain whose shortest waves are damped
    (measured at chi = 0.25, tol 1e-6, beta = 1e-6, damping ratio 1: 78 at N = 100, 163 at
    N = 300; scaled as N^0.7 and tol^(-1/8))."""
    return 80.0 * (N / 100.0) ** 0.7 * (1e-6 / tol) ** 0.125


def _span(t_end) -> float:
    return float(t_end) if t_end else T_SNAP


def choose(problem, *, tol: float = 1e-6, t_end=None) -> tuple[str, str]:
    """``(method, why)``: the method ``method="fast"`` runs ``problem`` with (``"dop853"``
    or ``"rodas4"``) and one line saying why."""
    body = getattr(problem, "body", None)
    if body is None or not body.has_bending:
        return "dop853", ""
    mdl = problem.model()
    om, zeta = shortest_wave(mdl)
    span = _span(t_end)
    n_acc = accuracy_steps(problem.N, tol) * span / T_SNAP
    n_ex = max(explicit_steps(mdl, span), n_acc)
    n_st = max(stiff_steps(problem.N, om, zeta, span), n_acc)
    stiff = zeta >= ZETA_MIN and n_ex > CHOICE_RATIO * RODAS4_PRICE * n_st
    what = (f"shortest bending wave omega_max={om:.3g}, damping ratio {zeta:.2g}; ~{n_ex:.3g} dop853 steps "
            f"against ~{n_st:.3g} rodas4 steps of ~{RODAS4_PRICE:g} times the cost")
    if stiff:
        return "rodas4", f"rodas4 chosen by method='fast' (stiff: {what})"
    why = "undamped bending waves limit every method by accuracy" if zeta < ZETA_MIN else "not stiff enough"
    return "dop853", f"dop853 chosen by method='fast' ({why}: {what})"


def check_cost(problem, method: str, *, t_end=None) -> None:
    """Before a run of an explicit ``method`` on ``problem``: a :class:`CostWarning` when the
    stability limit alone needs more than :data:`WARN_STEPS` steps, a SnappingInputError
    above :data:`REFUSE_STEPS` (the estimate scales with the run's span: a shorter
    ``t_end`` runs it anyway). Both name the method that can take it."""
    body = getattr(problem, "body", None)
    if method not in ("dop853",) or body is None or not body.has_bending:
        return
    mdl = problem.model()
    om, zeta = shortest_wave(mdl)
    span = _span(t_end)
    n = explicit_steps(mdl, span)
    if n <= WARN_STEPS:
        return
    N = problem.N
    lim = R_DOP853 / largest_eigenvalue(om, zeta)
    msg = (f"method='{method}': the bending stiffness limits its steps to dt < {lim:.3g} (shortest wave "
           f"omega_max={om:.3g} at N={N}): at least ~{n:.3g} steps ({12 * n:.3g} evaluations of {N} links) to "
           f"t={span:g}; method='rodas4' (stiff, L-stable) is not limited by it")
    if zeta < ZETA_MIN:
        msg += (f" once the shortest waves are damped (damping ratio {zeta:.2g}; Body(damping=eta) with eta ~ "
                f"{_eta_for(mdl, om):.3g} gives 1)")
    if n > REFUSE_STEPS:
        raise V.SnappingInputError(msg + f"; refused above {REFUSE_STEPS:.0e} steps (a shorter t_end runs it anyway)")
    warnings.warn(msg, CostWarning, stacklevel=3)


def _eta_for(mdl, om: float) -> float:
    """The damping eta (uniform, nondimensional) that gives the shortest wave ratio 1."""
    par, h, invm, invh, snode, tab = mdl
    hmin = float(np.min(h))
    m = float(np.min(1.0 / invm))
    return om * m * hmin ** 2 / 8.0 * hmin
