"""How stiff a 3D chain with bending is for the 3D stepper, and the warning before a costly run.

The 3D stepper (:mod:`snapping.spatial.solve3d`) is explicit (DOP853): with bending stiffness
its steps are limited by the shortest bending wave, exactly as the planar DOP853's
(:mod:`snapping.simulate.stiffness`: ``omega_max^2 = 16 (B/l)/(m h^2) + 4 T/(m h)``, at most
``R_DOP853/omega_max`` per step; its damping ratio ``zeta`` makes the fastest eigenvalue
``omega (zeta + sqrt(zeta^2 - 1))`` when overdamped). The same formula holds in space: the
bending energy is the planar one, a zigzag out of the plane is the same wave. There is no
stiff 3D method (no 3D RODAS4): a planar problem that is too stiff runs with
``snapping.simulate.run(method="rodas4")``; in space, :func:`check_cost3d` warns
(:class:`snapping.simulate.stiffness.CostWarning`) above ``WARN_STEPS`` estimated steps and
refuses above ``REFUSE_STEPS``, as the planar explicit method does.

Measured (``python benchmarks/bench_body3d.py``: chi = 0.25, beta = 1e-4, tol 1e-8, to
t = 0.3, the planar problem in both): the 3D run takes the planar DOP853's steps (N = 100:
108 and 108 undamped, 38 and 38 at damping ratio 1; N = 300: 917 against 919, 211 and 211)
and 0.98-1.03x its evaluations; the median step is 1.2/omega_max undamped (accuracy-limited
by the release's shortest waves, as in the plane) and 4.2-5.5/omega_max at damping ratio 1
(near the stability limit 5.96). Bending makes the 3D run exactly as stiff as the planar
DOP853 run, no more; only the planar runs have a stiff method to escape it.

>>> from snapping.simulate import Body
>>> from snapping.spatial import Problem3D
>>> om, zeta = shortest_wave3d(Problem3D.catenary(0.25, 100, body=Body(1e-4)))
>>> round(om), float(zeta)         # (about 4 N^2 sqrt(beta) = 400, and the tension's part)
(447, 0.0)
"""

from __future__ import annotations

import warnings


from .. import _validate as V
from ..simulate import stiffness as S

__all__ = ["shortest_wave3d", "explicit_steps3d", "check_cost3d"]


def shortest_wave3d(problem) -> tuple[float, float]:
    """``(omega_max, zeta)`` of a :class:`Problem3D`'s shortest bending wave; (0, 0) without bending."""
    body = getattr(problem, "body", None)
    if body is None or not body.active or not body.has_bending:
        return 0.0, 0.0
    h = problem.links.h
    N = h.size
    arr = body.node_arrays(h)
    return S.wave_of(arr["Bl"][:N], arr["El"][:N], h, 1.0 / problem.links.m, problem.gravity)


def explicit_steps3d(problem, t_span: float) -> float:
    """The 3D stepper's steps over ``t_span`` at its stability limit (a lower bound of its cost)."""
    om, zeta = shortest_wave3d(problem)
    return t_span * S.largest_eigenvalue(om, zeta) / S.R_DOP853


def check_cost3d(problem, t_end=None) -> None:
    """Before a 3D run: a CostWarning when the stability limit alone needs more than
    ``WARN_STEPS`` steps, a SnappingInputError above ``REFUSE_STEPS`` (a shorter ``t_end``
    runs it anyway)."""
    span = float(t_end) if t_end else S.T_SNAP
    n = explicit_steps3d(problem, span)
    if n <= S.WARN_STEPS:
        return
    om, zeta = shortest_wave3d(problem)
    lim = S.R_DOP853 / S.largest_eigenvalue(om, zeta)
    N = problem.N
    msg = (f"3D run: the bending stiffness limits the explicit 3D stepper (DOP853; there is no stiff method in "
           f"space) to dt < {lim:.3g} (shortest wave omega_max={om:.3g} at N={N}): at least ~{n:.3g} steps "
           f"({12 * n:.3g} evaluations of {N} links) to t={span:g}; a planar problem can run with "
           f"snapping.simulate.run(method='rodas4')")
    if n > S.REFUSE_STEPS:
        raise V.SnappingInputError(msg + f"; refused above {S.REFUSE_STEPS:.0e} steps (a shorter t_end runs it "
                                         f"anyway)")
    warnings.warn(msg, S.CostWarning, stacklevel=3)


