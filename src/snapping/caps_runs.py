"""The runs of a design answer (:func:`snapping.caps.cap`): the real model's problem of a line
(:func:`problem`), the method of each run (:func:`method_for`: stiff runs by RODAS4 on grid-damped
fast waves, the others by the fast method as they were), each run made once (:class:`Runs`),
and the stretching factor (:func:`stretch_factor`).

Why the rule. A bending line's shortest waves (frequency ~ 4 sqrt(B/lambda)/h^2) hold an
explicit method to steps ~ 6/omega: at 1000 links the bullwhip's full run took 809,892
evaluations of DOP853 (27 s of CPU) and the bungee cord's 511,706. RODAS4 (L-stable) is not held
by them once they are damped: :func:`snapping.simulate.stiffness.grid_damping` gives the waves
faster than ``omega_min`` (those that would hold DOP853 to more than :data:`STIFF_RATIO` times its
accuracy-limited steps) the damping ratio :data:`GRID_DAMPING`, a damping that vanishes as h^2.
Only those: damping every node (the regime studies' grid damping) moved the bending-alone peaks of
the thin lines (whose fold reaches the grid) by up to 19% at 1000 links; damping the fast waves
only moves every peak of every catalogue answer by at most 0.07% (N 100-1000,
``benchmarks/bench_caps.py``). A run with no such wave is DOP853's, undamped, bit for bit as before.
"""

from __future__ import annotations

import time

__all__ = ["problem", "method_for", "Runs", "stretch_factor", "GRID_DAMPING", "STIFF_TOL", "STIFF_RATIO",
           "STRETCH_N", "QUANTITIES", "MECHANISMS"]

#: links of the elastic and rigid runs that give the stretching factor
STRETCH_N = 30
#: RODAS4's tolerance in the runs it takes (:func:`method_for`)
STIFF_TOL = 1e-4
#: a run is stiff when DOP853's stability limit needs more than this many times its accuracy-limited steps
STIFF_RATIO = 10.0
#: the damping ratio given to the stiff runs' fast waves (:func:`snapping.simulate.stiffness.grid_damping`)
GRID_DAMPING = 1.0
#: the peaks answered: (name, SI units)
QUANTITIES = {"v_peak": "m/s", "a_peak": "m/s^2", "sigma_peak": "N"}
#: the mechanisms, in the order they are tried
MECHANISMS = ("bending", "drag", "end-mass", "taper", "stretching")


def problem(sp, chi: float, N: int, on=MECHANISMS, *, lumping: str = "paper",
            damping: float = 0.0, omega_min: float = 0.0):
    """The catenary start of ``sp`` at ``chi`` on ``N`` links with the mechanisms ``on`` (the
    inextensible model's: stretching is not part of it); with bending, the grid damping of
    ratio ``damping`` on the waves faster than ``omega_min``
    (:func:`snapping.simulate.stiffness.grid_damping`; 0: none)."""
    import numpy as np

    from .simulate import Body, Links, Problem

    tip = sp.end_mass / sp.mass if "end-mass" in on else 0.0
    if "taper" in on and sp.has("taper"):
        ln, L = sp.line, sp.length
        lam = sp.mass / L
        links = Links.from_density(np.full(N, 1.0 / N), lambda u: ln.mass_per_length * ln.ratio(L * (1.0 - u), L) ** 2
                                   / lam, tip_mass=tip, kind="line", params={"line": ln.name})
    else:
        links = Links.uniform(N, tip_mass=tip, lumping=lumping)
    kw = {}
    if "bending" in on and sp.has("bending"):
        kw["ei"] = sp.ei
    if "drag" in on and sp.has("drag"):
        kw.update(diameter=sp.diameter, cd_normal=sp.cd_normal if sp.diameter is not None else None,
                  cd_tangential=sp.cd_tangential if sp.diameter is not None else None, air_density=sp.air_density,
                  tip_drag_area=sp.tip_drag_area)
    body = Body.from_si(sp.length, sp.mass, sp.g, **kw) if kw else None
    if damping > 0.0 and "ei" in kw:
        from .simulate.stiffness import grid_damping

        eta = grid_damping(links.h, links.m, body.node_values("bending", links.h), damping, omega_min)
        body = Body(body.bending, damping=eta, wind=body.wind, tip_drag=body.tip_drag, clamp=body.clamp,
                    **{k: getattr(body, k) for k in ("curvature", "drag_normal", "drag_tangential",
                                                     "drag_linear_normal", "drag_linear_tangential")})
    return Problem.catenary(chi, links=links, body=body if body is not None and body.active else None)


def method_for(problem_, tol: float, stiff_tol: float = None) -> tuple[str, float, float]:
    """``(method, tol, omega_min)`` of one run of :func:`snapping.caps.cap`: a run whose bending waves would hold
    DOP853 to more than :data:`STIFF_RATIO` times its accuracy-limited steps (the shortest wave
    faster than ``omega_min = STIFF_RATIO R_DOP853 n_acc / T_SNAP``, with
    :func:`snapping.simulate.stiffness.accuracy_steps` ``n_acc`` and DOP853's stability boundary
    ``R_DOP853``) is stiff: RODAS4 (``"rodas4"``) at ``stiff_tol`` (default :data:`STIFF_TOL`),
    the waves faster than ``omega_min`` grid-damped (:func:`problem`); any other run is the fast
    method's (DOP853) at ``tol``, undamped, as without this rule (``omega_min`` 0)."""
    from .simulate import stiffness as S

    body = getattr(problem_, "body", None)
    if body is None or not body.has_bending:
        return "fast", tol, 0.0
    om, _ = S.shortest_wave(problem_.model())
    omega_min = STIFF_RATIO * S.R_DOP853 * S.accuracy_steps(problem_.N, tol) / S.T_SNAP
    if om > omega_min:
        return "rodas4", STIFF_TOL if stiff_tol is None else stiff_tol, omega_min
    return "fast", tol, 0.0


def _run(problem_, method: str, tol: float) -> dict:
    from .simulate import run

    t0, c0 = time.perf_counter(), time.process_time()
    r = run(problem_, method=method, tol=tol, progress=False)
    a = r.dataset.attrs
    if a.get("status") != "completed":
        raise RuntimeError(f"a run of the real model did not complete ({a.get('status')}: {a.get('stop_reason', '')})")
    return {**{q: float(a[q]) for q in QUANTITIES}, "n_rhs": int(a["n_rhs"]), "method": str(a["method"]),
            "tol": tol, "wall": time.perf_counter() - t0, "cpu": time.process_time() - c0}


def stretch_factor(sp, chi: float, tol: float = 1e-6, N: int = STRETCH_N) -> dict:
    """The elastic line over the rigid chain on the same ``N`` uniform links (shared lumping),
    peak by peak: the stretching factor of :func:`snapping.caps.cap`."""
    from .simulate import Links, Problem, run
    from .simulate.elastic import Elastic, solve

    t0, c0 = time.perf_counter(), time.process_time()
    p = Problem.catenary(chi, links=Links.uniform(N, lumping="shared"))
    rigid = run(p, method="fast", tol=tol, progress=False).dataset.attrs
    el = solve(p, Elastic(ea=sp.ea / (sp.mass * sp.g), grid_damping=1.0), tol=tol, method="dop853").dataset.attrs
    if el.get("status") != "completed":
        raise RuntimeError(f"the elastic run did not complete ({el.get('stop_reason', '')})")
    return {**{q: float(el[q]) / float(rigid[q]) for q in QUANTITIES}, "N": N,
            "n_rhs": int(el["n_rhs"]) + int(rigid["n_rhs"]), "wall": time.perf_counter() - t0,
            "cpu": time.process_time() - c0,
            "strain_peak": float(el["strain_peak"])}


class Runs:
    """The runs of one answer of :func:`snapping.caps.cap`, each made once: ``get(on, N)`` (``on``
    the mechanisms, () the ideal) runs it or returns it; ``log`` says what each cost."""

    def __init__(self, sp, chi, tol, stiff_tol, damping):
        self.sp, self.chi, self.tol, self.stiff_tol, self.damping = sp, chi, tol, stiff_tol, damping
        self.done, self.log = {}, []

    def get(self, on, N: int) -> dict:
        key = (tuple(on), int(N))
        if key not in self.done:
            p = problem(self.sp, self.chi, N, on)
            method, tol, omega_min = ("fast", self.tol, 0.0) if self.damping <= 0.0 else method_for(
                p, self.tol, self.stiff_tol)
            if method == "rodas4":
                p = problem(self.sp, self.chi, N, on, damping=self.damping, omega_min=omega_min)
            r = _run(p, method, tol)
            self.done[key] = r
            self.log.append({"run": "+".join(on) or "ideal", "N": int(N), "method": r["method"], "tol": r["tol"],
                             "n_rhs": r["n_rhs"], "cpu": r["cpu"]})
        return self.done[key]
