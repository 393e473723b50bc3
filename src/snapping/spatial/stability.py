"""Does the planar snap stay planar? The out-of-plane amplification at the snap, against N.

A planar start (the catenary of ``chi``) perturbed out of its plane with amplitude ``eps``
(:meth:`snapping.spatial.starts3d.Problem3D.perturbed`: a velocity ``eps sin(k pi s/L)``,
a smooth random one (eight sine modes, random coefficients: the same field at every N; the
rough node-by-node ``"random"`` mode is a different field at every N and cannot be refined), or the shape displaced by ``eps L sin(pi s/L)`` and placed with exact chords)
is run to the snap (:func:`snapping.spatial.solve3d.run3d`). In the linear regime (eps
small: the problem is symmetric under z -> -z, so z/eps = G + O(eps^2)) the out-of-plane
amplitude at the speed peak is ``G_z eps`` (largest distance of a node from the plane) and
its speed ``G_vz eps``. The amplification factors are measured on N = 100, 200, 400, 800
links and extrapolated to the string (:func:`snapping.continuum.extrapolate`: Richardson
with the observed order, where the sequence converges); where it does not, the growth is
the log-log slope ``p`` over the finest levels, against the in-plane focusing (the planar
peak speed's own slope). :func:`verdict` says, from those numbers, whether the planar snap
is stable: every ``G_z`` bounded as N grows (converging, or ``p <= P_FLAT``) and every
``G_vz`` growing no faster than the in-plane peak speed.

* :func:`gains`: one run's amplification factors;
* :func:`study`: the grid chi x perturbation x N (and the planar runs);
* :func:`classify`: one sequence G(N): its limit, or its growth exponent;
* :func:`linearity`: z/eps over several eps (the linear regime);
* :func:`verdict`, :func:`report_section`, :func:`figure`: the conclusion, in words, the
  report's lines and the figure.

Example
-------
>>> from snapping.spatial.stability import classify
>>> c = classify([100, 200, 400, 800], [2.0 - 1 / 100, 2.0 - 1 / 200, 2.0 - 1 / 400, 2.0 - 1 / 800])
>>> c["bounded"], round(c["limit"], 12), round(c["order"], 6)
(True, 2.0, 1.0)
"""

from __future__ import annotations

import math

import numpy as np

from .. import _validate as V

__all__ = ["PERTURBATIONS", "start", "gains", "study", "classify", "linearity", "verdict", "report_section",
           "figure"]

#: the perturbations of the study: name -> keywords of Problem3D.perturbed
PERTURBATIONS = {
    "velocity sin": {"kind": "velocity", "mode": "sin", "k": 1},
    "velocity sin 3": {"kind": "velocity", "mode": "sin", "k": 3},
    "velocity random": {"kind": "velocity", "mode": "modes"},
    "shape sin": {"kind": "shape", "mode": "sin", "k": 1},
}
#: the perturbations in words (the report)
DESCRIPTIONS = {
    "velocity sin": "the velocity eps sin(pi s/L)",
    "velocity sin 3": "the velocity eps sin(3 pi s/L)",
    "velocity random": "a smooth random velocity, 8 sine modes with normal coefficients / mode number, seed {seed}",
    "shape sin": "the shape displaced by eps L sin(pi s/L), placed with exact chords",
}
#: the seed of the random perturbation
SEED = 1
#: a growth exponent at most this is "no systematic growth" (bounded)
P_FLAT = 0.05
#: a Richardson limit is trusted only with an observed order at least this (increments
#: shrinking by 2^0.5 or more per doubling of N; slower is not told apart from slow growth)
ORDER_MIN = 0.5
#: the linear regime: z/eps equal over the eps studied to this relative spread
LINEAR_RTOL = 1e-3
#: default amplitude (linear regime) and tolerance of the study's runs
EPS = 1e-6
TOL = 1e-10


def start(chi: float, N: int, name: str, eps: float, *, seed: int = SEED):
    """The catenary of ``chi``, ``N`` with the perturbation ``name`` (:data:`PERTURBATIONS`) of amplitude ``eps``."""
    from .starts3d import Problem3D

    if name not in PERTURBATIONS:
        raise V.SnappingInputError(f"perturbation={name!r} is not one of {tuple(PERTURBATIONS)}")
    kw = dict(PERTURBATIONS[name])
    return Problem3D.catenary(chi, N).perturbed(eps, kw.pop("mode"), seed=seed, **kw)


def gains(problem, eps: float, *, tol: float = TOL) -> dict:
    """Run ``problem`` (a start perturbed with amplitude ``eps``) to the snap: ``z`` and ``vz``
    (the out-of-plane amplitude and speed at the speed peak over eps), ``v_peak``, ``n_rhs``."""
    from .solve3d import run3d

    r = run3d(problem, tol=tol)
    return {"z": r["z_amp_snap"] / eps, "vz": r["vz_amp_snap"] / eps, "v_peak": r["v_peak"], "n_rhs": r["n_rhs"]}


def study(chi_values=(0.1, 0.25, 0.5), N_values=(100, 200, 400, 800), perturbations=tuple(PERTURBATIONS), *,
          eps: float = EPS, tol: float = TOL, seed: int = SEED, log=None) -> dict:
    """Run the grid: for each chi and N the planar start and every perturbation of amplitude
    ``eps``. Returns a dict (JSON-able): the parameters and ``rows``, one per run: ``chi``,
    ``N``, ``perturbation`` (``"planar"`` for the unperturbed run), ``z``, ``vz``, ``v_peak``, ``n_rhs``."""
    from .solve3d import run3d
    from .starts3d import Problem3D

    Ns = [V.integer("N", n, 2) for n in N_values]
    e = V.real("eps", eps)
    if not (math.isfinite(e) and e > 0.0):
        raise V.SnappingInputError(f"eps={eps!r} is out of range: must be finite and > 0")
    rows = []
    for chi in chi_values:
        for N in Ns:
            r0 = run3d(Problem3D.catenary(chi, N), tol=tol)
            rows.append({"chi": float(chi), "N": N, "perturbation": "planar", "z": 0.0, "vz": 0.0,
                         "v_peak": r0["v_peak"], "n_rhs": r0["n_rhs"]})
            for name in perturbations:
                g = gains(start(chi, N, name, e, seed=seed), e, tol=tol)
                rows.append({"chi": float(chi), "N": N, "perturbation": name, **g})
                if log:
                    log(f"stability chi = {chi:g}, N = {N}, {name}: z/eps {g['z']:.6g}, vz/eps {g['vz']:.6g}")
    return {"chi": [float(c) for c in chi_values], "N": Ns, "perturbations": list(perturbations), "eps": e,
            "tol": float(tol), "seed": seed, "rows": rows}


def series(st: dict, chi: float, name: str, q: str) -> np.ndarray:
    """``q`` of the study's runs at ``chi`` with the perturbation ``name``, in the order of ``st["N"]``."""
    by = {(r["chi"], r["perturbation"], r["N"]): r[q] for r in st["rows"]}
    return np.array([by[(float(chi), name, N)] for N in st["N"]], dtype=float)


def classify(N_values, G) -> dict:
    """One amplification factor against N (N doubling): ``limit``, ``error``, ``order`` and
    ``converging`` of :func:`snapping.continuum.extrapolate` on the resolutions 1/N, the
    log-log slope ``p`` over the two finest N, ``bounded`` (converging with an observed order
    of at least :data:`ORDER_MIN`, or ``p <= P_FLAT``) and ``words``."""
    from ..continuum import extrapolate

    N = np.asarray(N_values, dtype=float)
    G = np.asarray(G, dtype=float)
    if N.size < 2 or not np.all(G > 0.0):
        raise V.SnappingInputError("classify needs two N or more and positive amplification factors")
    ex = extrapolate(1.0 / N, G)
    p = float(math.log(G[-1] / G[-2]) / math.log(N[-1] / N[-2]))
    limit = bool(ex["converging"]) and ex["order"] >= ORDER_MIN
    bounded = limit or p <= P_FLAT
    if limit:
        words = f"bounded: -> {ex['limit']:.4g} ± {ex['error']:.1g} (order {ex['order']:.2f}; N^{p:.3f} at the finest N)"
    elif bounded:
        words = f"bounded: no systematic growth (N^{p:+.3f} at the finest N)"
    else:
        words = f"growing as N^{p:.3f}"
    return {**ex, "p": p, "bounded": bounded, "words": words}


def linearity(chi: float, N: int, name: str, eps_values, *, tol: float = TOL, seed: int = SEED) -> dict:
    """z/eps and vz/eps over ``eps_values`` at one chi, N and perturbation; ``spread``: the
    largest relative deviation of z/eps (and of vz/eps) from the value at the smallest eps,
    ``linear``: both at most :data:`LINEAR_RTOL`."""
    eps = np.asarray(eps_values, dtype=float)
    rows = [gains(start(chi, N, name, e, seed=seed), e, tol=tol) for e in eps]
    z = np.array([r["z"] for r in rows])
    vz = np.array([r["vz"] for r in rows])
    i0 = int(np.argmin(eps))
    spread = float(max(np.max(np.abs(z / z[i0] - 1.0)), np.max(np.abs(vz / vz[i0] - 1.0))))
    return {"chi": float(chi), "N": int(N), "perturbation": name, "eps": eps.tolist(), "z": z.tolist(),
            "vz": vz.tolist(), "v_peak": [r["v_peak"] for r in rows], "spread": spread,
            "linear": spread <= LINEAR_RTOL}


def verdict(st: dict) -> dict:
    """The conclusion from the study's numbers: per chi and perturbation the classification
    of ``z`` and ``vz`` (:func:`classify`) and the planar peak speed's slope ``p_v``; ``stable``:
    every z bounded and every vz bounded or growing no faster than ``N^(p_v + P_FLAT)``;
    ``text``: the sentence."""
    cases, stable, growing = [], True, []
    for chi in st["chi"]:
        v0 = series(st, chi, "planar", "v_peak")
        pv = float(math.log(v0[-1] / v0[-2]) / math.log(st["N"][-1] / st["N"][-2]))
        for name in st["perturbations"]:
            cz = classify(st["N"], series(st, chi, name, "z"))
            cv = classify(st["N"], series(st, chi, name, "vz"))
            ok = cz["bounded"] and (cv["bounded"] or cv["p"] <= pv + P_FLAT)
            stable &= ok
            if not cz["bounded"]:
                growing.append(f"z: chi = {chi:g}, {name}, N^{cz['p']:.3f}")
            if not (cv["bounded"] or cv["p"] <= pv + P_FLAT):
                growing.append(f"vz: chi = {chi:g}, {name}, N^{cv['p']:.3f} against v_peak N^{pv:.3f}")
            cases.append({"chi": chi, "perturbation": name, "z": cz, "vz": cv, "p_v": pv, "ok": ok})
    Gz = [c["z"]["limit"] for c in cases]
    text = (f"the planar snap is {'stable' if stable else 'unstable'} to out-of-plane perturbations: the out-of-plane "
            f"amplitude at the snap is G eps with G = {min(Gz):.3g} to {max(Gz):.3g} "
            f"(chi = {', '.join(f'{c:g}' for c in st['chi'])}; N = {st['N'][0]} to {st['N'][-1]} and the limit)")
    text += (", bounded as N grows; its speed grows no faster than the in-plane focusing" if stable
             else "; growing: " + "; ".join(growing))
    return {"stable": stable, "cases": cases, "text": text}


def report_section(st: dict, lin: dict | None = None, figure_name: str | None = None) -> list[str]:
    """Markdown lines of the report's section "Beyond the paper: does the snap stay planar?"."""
    vd = verdict(st)
    Ns = st["N"]
    lines = ["## Beyond the paper: does the snap stay planar?", "",
             f"The catenary start of `snapping.spatial` perturbed out of its plane with amplitude eps = {st['eps']:g} "
             f"({'; '.join(f'{n}: ' + DESCRIPTIONS[n].format(seed=st['seed']) for n in st['perturbations'])}), "
             f"run to the snap at tol {st['tol']:g}. G_z = (largest distance of a "
             "node from the plane at the speed peak) / eps, G_vz = (largest out-of-plane speed there) / eps; limit: "
             "Richardson in 1/N with the observed order (`snapping.continuum.extrapolate`) where G converges "
             f"(order >= {ORDER_MIN:g}), otherwise the log-log slope p over N = {Ns[-2]} -> {Ns[-1]} (bounded: "
             f"p <= {P_FLAT:g}); in-plane "
             "focusing: the planar peak speed's slope over the same N.", ""]
    if lin is not None:
        lines += ["| claim | measured here | paper | verdict |", "|---|---|---|---|",
                  f"| out-of-plane amplitude at the snap linear in eps (chi = {lin['chi']:g}, N = {lin['N']}, "
                  f"{lin['perturbation']}) | z/eps " + ", ".join(f"{z:.7g}" for z in lin["z"]) + " at eps "
                  + ", ".join(f"{e:g}" for e in lin["eps"]) + f"; largest relative spread of z/eps, vz/eps "
                  f"{lin['spread']:.1e} | not studied | "
                  f"{'linear' if lin['linear'] else 'not linear'} (spread {'<=' if lin['linear'] else '>'} "
                  f"{LINEAR_RTOL:g}) |", ""]
    lines += ["| chi | perturbation | G_z at N = " + ", ".join(map(str, Ns)) + " | G_z | G_vz at N = "
              + ", ".join(map(str, Ns)) + " | G_vz | planar v_peak (slope) | verdict |",
              "|---|---|---|---|---|---|---|---|"]
    for c in vd["cases"]:
        chi, name = c["chi"], c["perturbation"]
        z = ", ".join(f"{x:.5g}" for x in series(st, chi, name, "z"))
        vz = ", ".join(f"{x:.4g}" for x in series(st, chi, name, "vz"))
        v0 = ", ".join(f"{x:.4g}" for x in series(st, chi, "planar", "v_peak"))
        lines.append(f"| {chi:g} | {name} | {z} | {c['z']['words']} | {vz} | {c['vz']['words']} | {v0} "
                     f"(N^{c['p_v']:.3f}) | {'stable' if c['ok'] else 'unstable'} |")
    lines += ["", f"**Verdict (computed): {vd['text']}.**", ""]
    if figure_name:
        lines += [f"![{figure_name}](figures/{figure_name}.png)", ""]
    return lines


def figure(st: dict, lin: dict | None = None):
    """Left: the amplitude at the snap against eps (``lin``), log-log, with the line of linear
    growth. Middle: G_z against N per chi and perturbation. Right: G_vz against N, and the
    planar peak speed (the in-plane focusing), dashed."""
    from ..figures import _plt

    plt = _plt()
    fig, axs = plt.subplots(1, 3, figsize=(13, 4.0), constrained_layout=True)
    ax, bx, cx = axs
    if lin is not None:
        eps = np.asarray(lin["eps"])
        for key, mk, lab in (("z", "o", "distance from the plane"), ("vz", "s", "out-of-plane speed")):
            amp = np.asarray(lin[key]) * eps
            ax.loglog(eps, amp, mk, label=lab)
            ax.loglog(eps, lin[key][int(np.argmin(eps))] * eps, "k:", lw=0.8)
        ax.set_title(f"chi = {lin['chi']:g}, N = {lin['N']}, {lin['perturbation']}; dotted: linear", fontsize=9)
        ax.legend(fontsize=8)
    ax.set_xlabel("eps")
    ax.set_ylabel("at the snap")
    Ns = np.asarray(st["N"])
    colors = plt.cm.viridis(np.linspace(0, 0.85, len(st["chi"])))
    marks = "osd^v<>"
    for col, chi in zip(colors, st["chi"]):
        for mk, name in zip(marks, st["perturbations"]):
            lab = f"chi {chi:g}, {name}"
            bx.loglog(Ns, series(st, chi, name, "z"), mk + "-", color=col, ms=4, lw=0.8, label=lab)
            cx.loglog(Ns, series(st, chi, name, "vz"), mk + "-", color=col, ms=4, lw=0.8)
        cx.loglog(Ns, series(st, chi, "planar", "v_peak"), "--", color=col, lw=1.5, label=f"planar v_peak, chi {chi:g}")
    bx.set_xlabel("N")
    bx.set_ylabel("G_z = z at the snap / eps")
    bx.set_title("out-of-plane distance amplification", fontsize=9)
    bx.legend(fontsize=6, ncol=2)
    cx.set_xlabel("N")
    cx.set_ylabel("G_vz = out-of-plane speed / eps; planar v_peak")
    cx.set_title("out-of-plane speed against the in-plane focusing (dashed)", fontsize=9)
    cx.legend(fontsize=6)
    return fig
