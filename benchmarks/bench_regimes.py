"""The regime studies shipped with the package, their cost, and the bending damping check (issue 24).

``--study MECH`` runs (or resumes) one mechanism's 4 chi x 8 numbers scan with the settings
of :data:`STUDIES` into ``src/snapping/data/regimes/MECH.nc`` (the file
:func:`snapping.regimes.bundled_study` loads): a study is resumable, so an interrupted
run loses nothing. ``--cost MECH`` reads a finished (or partial) study file and prints
what its scan cost: the CPU time and right-hand-side evaluations of every run (recorded
by each worker with ``time.process_time``), by level and by chi, and the error bars it
reached (the largest relative error bar of v_peak, a_peak and sigma_peak over the
resolved cells). ``--damping-check`` runs one bending cell at grid damping ratios 0.5, 1
and 2 and prints the three continuum limits with their error bars: the physics of the
study must not depend on the grid damping (it vanishes as h^2 with the links).

Timings are CPU seconds of the runs themselves (not the ~35 s of one-off compilation per
worker process); the machine is shared, so wall times mean little (load printed).

Usage::

    python benchmarks/bench_regimes.py --study end-mass --workers 1
    python benchmarks/bench_regimes.py --extend bending --seed benchmarks/results/bendconv_chi0.*.json
    python benchmarks/bench_regimes.py --cost end-mass
    python benchmarks/bench_regimes.py --study drag --escalate-from old_drag.nc   # the 3-level file's runs, then --study
    python benchmarks/bench_regimes.py --study stretching --rerun-cells OLD.nc --out new.nc  # OLD's ideal runs only, then
    python benchmarks/bench_regimes.py --study stretching --out new.nc                      # ... its cells run again
    python benchmarks/bench_regimes.py --damping-check --chi 0.3 --beta 1e-4
    python benchmarks/bench_regimes.py --report --figures docs/guide     # the analysis and the maps
    python benchmarks/bench_regimes.py --study stretching --chis 0.1 --out lo.nc   # a part (some chi) ...
    python benchmarks/bench_regimes.py --study stretching --merge lo.nc hi.nc       # ... put into the shipped file
    python benchmarks/bench_regimes.py --starts 0.3:38 0.5:7.5 0.2:196 --level -3  # matched vs stretched start
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "src", "snapping", "data", "regimes")

#: the shipped studies: chi, numbers, and the regimes() settings
STUDIES = {
    # end-mass and drag: 3 fold levels (-1 ... 1) as shipped before, escalated (branch dragesc): a cell (or the ideal
    # at a chi) whose v/a/sigma_peak bar is over 1% runs one more level, up to 2 more (the ideal's own a_peak at
    # chi 0.1 is +-5% on 3 levels, +-2% on 4); `--escalate-from OLD` seeds the file with the 3-level study's runs.
    # A cell whose last level took more than 600,000 evaluations is not escalated (escalate_max_rhs; marked
    # escalation_capped): end mass 0.0072 at chi 0.1 took 987,000 at level 3 (7,328 links, 217 s CPU), its level 4
    # would take ~700 s; 0.0193 took 1,039,000 at level 2. The cap counts the integration's evaluations: n_rhs less
    # n_rhs_approach, those that located kappa_peak_approach (branch emkappa; regimes_escalate.integration_rhs)
    # (the end-mass numbers: the shipped file's since d50abbc; this dict said geomspace(1e-5, 1, 8), not what shipped)
    "end-mass": {"chis": [0.1, 0.2, 0.3, 0.5], "numbers": np.array([1.93e-6, 1e-5, 5.18e-5, 2.68e-4, 1.39e-3,
                                                                    7.2e-3, 0.0193, 0.0373]), "accuracy": "medium",
                 "levels": 3, "escalate": 0.01, "extra_levels": 2, "escalate_max_rhs": 600_000},
    # drag: the escalation capped at 600,000 evaluations a run (escalate_max_rhs): the heavy-drag cells (d = 10 at chi
    # 0.3, 0.5: 3.1e6, 3.9e6 at level 2, their tail compressed and crumpled, peaks growing with the links) are left
    # at 3 levels and marked escalation_capped; every other drag run takes <= 82,000 evaluations at level 2
    "drag": {"chis": [0.1, 0.2, 0.3, 0.5], "numbers": np.geomspace(1e-3, 10.0, 8), "accuracy": "medium",
             "levels": 3, "escalate": 0.01, "extra_levels": 2, "escalate_max_rhs": 600_000},
    # bending: 4 levels (frac 0.08-0.01; was 3 to 0.02, whose small-beta cells at chi 0.1-0.2 sat before their
    # asymptotic regime, see benchmarks/bench_bendconv.py); `--extend bending` reuses the 3-level file's runs.
    # Escalated (branch bendesc): a cell over 1% whose level 4 took <= 40,000 evaluations runs a fifth level (chi 0.2
    # beta 7.2e-8, 5.18e-7; chi 0.3 beta 5.18e-7: a_peak 2.2%, 2.5%, 1.1% on 4 levels, unconverged, branch bend05),
    # and the ideal with them (chi 0.1-0.3, 48 s CPU at chi 0.1, 14,625 links). The cap leaves chi 0.1's four
    # small-beta cells (47,000-72,000 at level 4, 65-104 s; a fifth ~4x) and chi 0.5 beta 1e-2 (78,000: grid
    # damping, no continuum limit) at 4 levels, marked escalation_capped
    "bending": {"chis": [0.1, 0.2, 0.3, 0.5], "numbers": np.geomspace(1e-8, 1e-2, 8), "accuracy": "medium",
                "levels": 4, "escalate": 0.01, "extra_levels": 1, "escalate_max_rhs": 40_000},
    # stretching (number sqrt(gL)/c), shipped since branch shipstretch: benchmarks/stretch_scan.py's scan, RODAS4
    # in link coordinates (regimes_spec.STRETCH_METHOD, its tip links floored at STRETCH_TIP_TIME * c), the 1%
    # levels of the other mechanisms (accuracy "medium": fold levels -1 ... 2) at tol 1e-6, the numbers
    # geomspace(1e-3, 0.3, 8) unrounded (as stretch_scan.py passed them: "exact"); 553 s CPU, v_peak within 1%
    # in 32/32 cells. The node-method study shipped before (method "rodas4", kept in comments below) was:
    # {"chis": [0.1, 0.2, 0.3, 0.5], "numbers": np.geomspace(1e-3, 0.3, 8), "accuracy": "coarse", "first": -4,
    #  "levels": 3, "tol": 1e-6, "damping": 4.0, "start": "matched", "method": "rodas4"}, of which:
    # the elastic line by RODAS4 from the matched start (no release wave: the
    # study measures the snap's own stretching), grid damping zeta = 4 (regimes_spec.STRETCH_DAMPING: at 1 the
    # tip links chatter slack/taut, 12x the evaluations at chi = 0.3, c = 442) and the stop floor of
    # regimes_spec; tol 1e-6 (1e-5 leaves the slow manifold: the tip links chatter from t = 0.04, chi = 0.3,
    # c = 442). c = 1000 down to 3.3 (geomspace(1e-3, 0.3, 8)); fold levels first -4 (chi = 0.1: 155-493 links).
    # Stop 29's partial study (stretched start, zeta 1, chi 0.2-0.5, 7 numbers) is reproduced by
    # {"chis": [0.2, 0.3, 0.5], "numbers": np.geomspace(1e-3, 0.3, 8)[1:], "damping": 1.0, "start": "stretched"}
    # with the other settings as here
    "stretching": {"chis": [0.1, 0.2, 0.3, 0.5], "numbers": np.geomspace(1e-3, 0.3, 8), "exact": True,
                   "accuracy": "medium", "tol": 1e-6, "damping": 4.0, "start": "matched",
                   "escalate": 0.01, "extra_levels": 1},  # (branch stretch1pct: regimes_spec.STRETCH_ESCALATE, ..._EXTRA_LEVELS)
}


def _numbers(v, exact=False):
    if exact:  # the stretching study's (benchmarks/stretch_scan.py passed geomspace's values)
        return [float(x) for x in v]
    return [float(f"{x:.3g}") for x in v]  # as the command line passes them (3 digits)


def study(mech: str, workers: int, chis=None, out=None, levels=None) -> None:
    """Run (or resume) the study of ``mech``; ``chis`` and ``out``: a part of it (some chi) in a
    file of its own, to be put into the shipped study by :func:`merge` (cells are the same runs)."""
    from snapping.regimes import regimes

    s = dict(STUDIES[mech])
    if levels:
        s["levels"] = levels
    os.makedirs(DATA, exist_ok=True)
    out = out or os.path.join(DATA, f"{mech}.nc")
    all_chis = s.pop("chis")
    t = time.time()
    numbers = _numbers(s.pop("numbers"), s.pop("exact", False))
    regimes(mech, chis or all_chis, numbers, out=out, workers=workers, progress=True, **s)
    print(f"{mech}: {out} ({time.time() - t:.0f} s wall, load {os.getloadavg()[0]:.1f})")


def merge(mech: str, parts) -> None:
    """Put part studies (the same settings, each some of the chi) together as the shipped study
    file of ``mech``: the runs of each part, the study key of all their chi (so that ``--study``
    resumes the merged file as one study), the limits recomputed."""
    import json

    import xarray as xr

    from snapping.regimes import _finish, load_study
    from snapping.sweep_files import atomic_to_netcdf

    ds = [load_study(p) for p in parts]
    keys = [json.loads(d.attrs["regimes_study"]) for d in ds]
    for k in keys[1:]:
        if {a: b for a, b in k.items() if a != "chi"} != {a: b for a, b in keys[0].items() if a != "chi"}:
            raise SystemExit("the parts are not parts of one study (their settings differ)")
    runs = [v for v in ds[0].data_vars if v.endswith("_level")]
    whole = xr.concat([d[runs] for d in ds], dim="chi", data_vars="minimal", coords="minimal",
                      compat="override").sortby("chi")
    whole["resolution"], whole["resolution_ideal"] = ds[0]["resolution"], ds[0]["resolution_ideal"]
    whole.attrs = dict(ds[0].attrs)
    whole.attrs["regimes_study"] = json.dumps({**keys[0], "chi": sorted(float(c) for c in whole.chi.values)},
                                              sort_keys=True)
    out = os.path.join(DATA, f"{mech}.nc")
    whole = _finish(whole)
    atomic_to_netcdf(whole, out)
    print(f"{mech}: merged {len(parts)} part(s) into {out}; status {whole.attrs['status']}")


def extend(mech: str, workers: int, seeds=(), old_path=None, out=None, levels=None) -> None:
    """Refine a shipped study by more levels (STUDIES[mech]["levels"]) without redoing its runs: the
    shipped file's levels, and any of the same runs in ``seeds`` (benchmarks/bench_bendconv.py's JSON
    files, keys "chi beta k" with frac = 0.04 * 2**-k), are copied into the new study's file, then
    :func:`snapping.regimes.regimes` computes only the runs missing. Every copied run is the same
    computation (same links, tolerance and grid damping): checked bit for bit on one. ``old_path``,
    ``out``: the study file to refine and the new one (default both the shipped file); ``levels``:
    instead of STUDIES[mech]["levels"]."""
    import json

    from snapping import regimes as R
    from snapping.continuum import QUANTITIES
    from snapping.sweep_files import atomic_to_netcdf

    s = dict(STUDIES[mech])
    if levels:
        s["levels"] = levels
    chis, numbers = sorted(s.pop("chis")), _numbers(s.pop("numbers"), s.pop("exact", False))
    old = R.load_study(old_path or os.path.join(DATA, f"{mech}.nc"))
    acc = dict(R.ACCURACY[s.pop("accuracy")])
    acc.update(s)
    if mech == "bending":
        acc["damping"] = R.GRID_DAMPING
    if mech == "stretching":  # the key regimes() makes (the matched start's)
        from snapping.regimes_spec import STRETCH_TOL_C

        acc.update(elastic_method=R.STRETCH_METHOD, stop_floor=R.STRETCH_STOP_FLOOR,
                   elastic_start=acc.pop("start"), tol_c=STRETCH_TOL_C)
        if R.STRETCH_METHOD == "rodas4-links":  # its tip links floored (regimes_spec.stretch_tip_floor)
            acc["tip_time"] = R.STRETCH_TIP_TIME
    lev, ilev = R._levels(R.MECHANISMS[mech][1], acc, 0.5), R._levels("fold", acc, 0.5)
    ds = R._empty(mech, chis, numbers, lev, ilev, R._study_key(mech, chis, numbers, acc, 0.5), acc, 0.5)
    names = [f"{q}_level" for q in QUANTITIES + ("n_rhs", "cpu_time", "n_links")]
    copied = 0
    for k, p in enumerate(lev):  # the shipped file's levels, matched by their fold fraction
        ko = np.flatnonzero(np.isclose(old.resolution.values, p["frac"], rtol=1e-12))
        if ko.size:
            for n in names:
                ds[n].values[:, :, k] = old[n].sel(chi=chis, number=numbers).values[:, :, ko[0]]
                ds[n.replace("_level", "_ideal_level")].values[:, k] = old[n.replace("_level", "_ideal_level")].sel(
                    chi=chis).values[:, ko[0]]
            copied += 1
    seeded = 0
    for path in seeds:
        for key, row in json.load(open(path)).items():
            if len(key.split()) != 3:  # bench_bendconv's runs at another tolerance: not the study's runs
                continue
            chi, beta, kk = float(key.split()[0]), float(key.split()[1]), int(key.split()[2])
            k = kk - acc["first"]
            if chi not in chis or not 0 <= k < len(lev) or (beta and beta not in numbers):
                continue
            assert np.isclose(lev[k]["frac"], 0.04 * 0.5**kk, rtol=1e-12)
            i = chis.index(chi)
            for q in QUANTITIES + ("n_rhs", "cpu_time", "n_links"):
                if beta == 0:
                    ds[f"{q}_ideal_level"].values[i, k] = row[q]
                else:
                    ds[f"{q}_level"].values[i, numbers.index(beta), k] = row[q]
            seeded += 1
    out = out or os.path.join(DATA, f"{mech}.nc")
    if mech == "stretching":
        ds.attrs["elastic_start"] = acc["elastic_start"]
    atomic_to_netcdf(R._finish(ds), out)
    print(f"{mech}: {copied} levels copied from {old_path or 'the shipped file'}, {seeded} runs from {list(seeds)}; "
          f"resuming")
    study(mech, workers, out=out, levels=levels)


def reuse(old_path: str, out: str) -> None:
    """Start the stretching study's file ``out`` with the runs of an earlier stretching study file
    whose runs are the same computations: the same chi, numbers, levels, start, grid damping and tol,
    its key lacking only ``tol_c`` (:func:`snapping.regimes_spec.stretch_tol`, added after it): every
    ideal run and every run of c <= STRETCH_TOL_C (the same tolerance) is copied; the stiffer lines'
    runs (now at a smaller tolerance) are left to the study. Then ``--study stretching --out OUT``
    resumes it."""
    import json

    from snapping import regimes as R
    from snapping.regimes_spec import STRETCH_TOL_C
    from snapping.sweep_files import atomic_to_netcdf

    old = R.load_study(old_path)
    s = dict(STUDIES["stretching"])
    chis, numbers = sorted(s.pop("chis")), _numbers(s.pop("numbers"), s.pop("exact", False))
    acc = dict(R.ACCURACY[s.pop("accuracy")])
    start, damping = s.pop("start"), s.pop("damping")
    acc.update(s, damping=damping, elastic_method=R.STRETCH_METHOD, stop_floor=R.STRETCH_STOP_FLOOR,
               elastic_start=start)
    want = json.loads(R._study_key("stretching", chis, numbers, acc, 0.5))
    have = json.loads(old.attrs["regimes_study"])
    if have != want:
        raise SystemExit(f"{old_path} is not this study's earlier run: {have} against {want}")
    acc["tol_c"] = STRETCH_TOL_C
    lev, ilev = R._levels("fold", acc, 0.5), R._levels("fold", acc, 0.5)
    ds = R._empty("stretching", chis, numbers, lev, ilev, R._study_key("stretching", chis, numbers, acc, 0.5), acc, 0.5)
    ds.attrs["elastic_start"] = start
    keep = np.array([1.0 / n <= STRETCH_TOL_C for n in numbers])
    copied = 0
    for name in [v for v in old.data_vars if v.endswith("_level")]:
        if "ideal" in name:
            ds[name].values[...] = old[name].values
        else:
            ds[name].values[:, keep, :] = old[name].values[:, keep, :]
    copied = int(np.isfinite(ds.v_peak_level.values).sum() + np.isfinite(ds.v_peak_ideal_level.values).sum())
    atomic_to_netcdf(R._finish(ds), out)
    print(f"stretching: {copied} runs copied from {old_path} into {out} (c <= {STRETCH_TOL_C:g} and the ideal's)")


def rerun_cells(mech: str, old_path: str, out: str) -> None:
    """Start ``out`` as the study of ``old_path`` (the same key: ``--study MECH --out OUT`` resumes
    it) with its ideal runs (every level it ran) and none of its cells' runs: the cells are run
    again (branch stretchk: the stretching study's cells then record kappa_peak, NaN in a file
    made before; the ideal chain's runs had it and are the same computations)."""
    from snapping import regimes as R
    from snapping.sweep_files import atomic_to_netcdf

    old = R.load_study(old_path)
    if old.attrs["mechanism"] != mech:
        raise SystemExit(f"{old_path} is a {old.attrs['mechanism']} study, not {mech}")
    if out is None or os.path.lexists(out):
        raise SystemExit(f"--rerun-cells: give a new --out (got {out!r}): the shipped file is not overwritten")
    ds = old.copy(deep=True)
    cells = [v for v in ds.data_vars if v.endswith("_level") and "ideal" not in v]
    for name in cells:
        ds[name].values[...] = np.nan
    atomic_to_netcdf(R._finish(ds), out)
    print(f"{mech}: {out} holds the {int(np.isfinite(ds.v_peak_ideal_level.values).sum())} ideal runs of {old_path} "
          f"and no cell run ({len(cells)} cell variables emptied); --study {mech} --out {out} runs the cells")


def escalate_from(mech: str, old_path: str, out=None) -> None:
    """Start the escalating study of ``mech`` (STUDIES: ``escalate``, ``extra_levels``) in ``out``
    (default the shipped file) with the runs of ``old_path``, the same study without escalation (its
    key equal to the new one less ``escalate`` and ``extra_levels``): every run it holds is one of the
    new study's base levels (the same links, tolerance and method), copied; then ``--study MECH``
    runs only the levels the error bars ask for."""
    import json

    from snapping import regimes as R
    from snapping.sweep_files import atomic_to_netcdf

    s = dict(STUDIES[mech])
    chis, numbers = sorted(s.pop("chis")), _numbers(s.pop("numbers"), s.pop("exact", False))
    acc = dict(R.ACCURACY[s.pop("accuracy")])
    acc.update(s)
    if "escalate" not in acc or mech in ("bending", "stretching"):
        raise SystemExit(f"--escalate-from: {mech} is not an escalating drag/end-mass study in STUDIES")
    acc["escalate"], acc["extra_levels"] = float(acc["escalate"]), int(acc["extra_levels"])
    old = R.load_study(old_path)
    want = json.loads(R._study_key(mech, chis, numbers, acc, 0.5))
    have = json.loads(old.attrs["regimes_study"])
    esc = ("escalate", "extra_levels", "escalate_max_rhs")
    if ({k: v for k, v in have.items() if k not in esc} != {k: v for k, v in want.items() if k not in esc}
            or any(k in have and have[k] != want[k] for k in esc[:2])):
        raise SystemExit(f"{old_path} is not this study (escalated or not, under any cap): {have} against {want}")
    every = dict(acc, levels=acc["levels"] + acc["extra_levels"])
    grading = R.MECHANISMS[mech][1]
    ds = R._empty(mech, chis, numbers, R._levels(grading, every, 0.5), R._levels("fold", every, 0.5),
                  R._study_key(mech, chis, numbers, acc, 0.5), acc, 0.5)
    nl = old.sizes["level"]
    assert np.allclose(ds.resolution.values[:nl], old.resolution.values, rtol=1e-12)
    for name in [v for v in old.data_vars if v.endswith("_level") and v in ds]:
        ds[name].values[..., :nl] = old[name].values
    if "escalate_max_rhs" in acc:  # an escalated level copied must be one this cap lets the study run
        from snapping.regimes_escalate import integration_rhs, prefix

        extra = ds.n_rhs_approach_level.values if "n_rhs_approach_level" in ds else None
        for row in integration_rhs(ds.n_rhs_level.values, extra).reshape(-1, ds.sizes["level"]):  # (the cap's count)
            n = prefix(row)
            if n > acc["levels"] and np.any(row[acc["levels"] - 1:n - 1] > acc["escalate_max_rhs"]):
                raise SystemExit(f"{old_path}: a cell escalated past the cap {acc['escalate_max_rhs']}: not this study")
    out = out or os.path.join(DATA, f"{mech}.nc")
    if os.path.exists(out):  # a file there keeps every run it holds, or it is not overwritten
        lost = _runs_lost(R.load_study(out), ds)
        if lost:
            raise SystemExit(f"--escalate-from: {out} holds {lost} runs that {old_path} does not (an escalated "
                             f"study's?): not overwritten; give --out another file or move it away")
    atomic_to_netcdf(R._finish(ds), out)
    copied = int(np.isfinite(ds.v_peak_level.values).sum() + np.isfinite(ds.v_peak_ideal_level.values).sum())
    print(f"{mech}: {copied} runs copied from {old_path} into {out}; --study {mech} escalates")


def _runs_lost(cur, ds) -> int:
    """How many of the runs (finite v_peak of a cell or the ideal at a level) of the study file ``cur``
    the study ``ds`` would not hold, equal, if written over it."""
    lost = 0
    for name in ("v_peak_level", "v_peak_ideal_level"):
        a = cur[name].values if name in cur else np.array([])
        same = (cur.sizes.get("chi") == ds.sizes["chi"] and a.shape[:-1] == ds[name].shape[:-1]
                and a.shape[-1] <= ds.sizes["level"])
        b = ds[name].values[..., :a.shape[-1]] if same else None
        lost += int(np.sum(np.isfinite(a) & ~(a == b))) if same else int(np.sum(np.isfinite(a)))
    return lost


def cost(mech: str, path=None) -> dict:
    """What a study file's scan cost (CPU s, evaluations), by level and chi, and its error bars."""
    from snapping.regimes import load_study
    from snapping.regimes_analysis import resolved

    ds = load_study(path or os.path.join(DATA, f"{mech}.nc"))
    cpu, ic = ds.cpu_time_level.values, ds.cpu_time_ideal_level.values
    rhs, ir = ds.n_rhs_level.values, ds.n_rhs_ideal_level.values
    done = int(np.isfinite(cpu).sum() + np.isfinite(ic).sum())
    total = int(cpu.size + ic.size)
    print(f"{mech}: status {ds.attrs['status']}, {done}/{total} runs; CPU {np.nansum(cpu) + np.nansum(ic):.0f} s "
          f"({np.nansum(ic):.0f} s the ideal's), {np.nansum(rhs) + np.nansum(ir):.3g} evaluations")
    for k in range(ds.sizes["level"]):
        print(f"  level {k}: CPU {np.nansum(cpu[:, :, k]) + np.nansum(ic[:, k]):7.1f} s, links "
              f"{np.nanmin(ds.n_links_level.values[:, :, k]):.0f}..{np.nanmax(ds.n_links_level.values[:, :, k]):.0f}")
    for i, chi in enumerate(ds.chi.values):
        print(f"  chi {chi:g}: CPU {np.nansum(cpu[i]) + np.nansum(ic[i]):7.1f} s; per number "
              + " ".join(f"{x:.0f}" for x in np.nansum(cpu[i], axis=-1)))
    if "levels_run" in ds:  # an escalating study: the levels each cell ran, and those the cost cap stopped
        print(f"  levels run (escalated): cells {np.bincount(ds.levels_run.values.ravel()).tolist()} (count by levels), "
              f"ideal {ds.levels_run_ideal.values.tolist()}")
    if "escalation_capped" in ds:
        cc = np.argwhere(ds.escalation_capped.values == 1)
        print(f"  escalation capped (over {ds.attrs['escalate_max_rhs']} evaluations at the last level, the integration's: "
              f"n_rhs less n_rhs_approach): "
              + (", ".join(f"chi {ds.chi.values[i]:g} number {ds.number.values[j]:g}" for i, j in cc) or "none"))
    worst = {}
    for q in ("kappa_peak", "kappa_peak_approach"):  # (the curvature: error bar within 1% of the value, any order)
        if q in ds:
            rel = np.abs(ds[f"{q}_error"].values / ds[q].values)
            print(f"  {q}: {int(np.sum(rel <= 0.01))}/{rel.size} cells within 1% (any order); ideal's error bars "
                  + " ".join(f"{x:.2%}" for x in np.abs(ds[f"{q}_ideal_error"].values / ds[f"{q}_ideal"].values)))
    for q in ("v_peak", "a_peak", "sigma_peak", "kappa_peak"):  # (kappa_peak: the stretching cells' since stretchk)
        if q not in ds:
            continue
        ok = resolved(ds[q].values, ds[f"{q}_error"].values, ds[f"{q}_order"].values)
        rel = np.abs(ds[f"{q}_error"].values / ds[q].values)
        worst[q] = float(np.nanmax(np.where(ok, rel, np.nan))) if ok.any() else float("nan")
        print(f"  {q}: {int(ok.sum())}/{ok.size} cells resolved; largest error bar of those {worst[q]:.2%}; "
              f"median {np.nanmedian(np.where(ok, rel, np.nan)):.2%}; {int(np.sum(ok & (rel <= 0.01)))} cells within 1%")
    if ds.attrs["mechanism"] == "stretching":  # its verdicts use the same-links ratios, extrapolated
        from snapping.regimes_analysis import level_ratios

        for q in ("v_peak", "sigma_peak"):
            lr = level_ratios(ds, q)
            for chi, r in lr["chi"].items():
                ok = np.isfinite(r["ratio"]) & np.isfinite(r["error"])
                rel = np.abs(r["error"] / r["ratio"])
                print(f"  {q} same-links ratio, chi {chi:g}: {int(ok.sum())} cells extrapolated, "
                      f"{int(np.sum(ok & (rel <= 0.01)))} within 1%; error bars "
                      + " ".join("-" if not k else f"{x:.1%}" for k, x in zip(ok, rel)))
    return {"cpu": float(np.nansum(cpu) + np.nansum(ic)), "worst": worst}


def estimates(mech: str, ds, a) -> list[str]:
    """The issue's order-of-magnitude starting points against the measured crossovers (per chi):

    * bending: the rod's fold radius sqrt(B/T) reaches the ideal fold's radius 1/kappa at the
      ideal's tension T = sigma: beta_c ~ sigma_ideal / kappa_ideal^2;
    * end mass: the fold's length (~ its radius 1/kappa_ideal) reaches M/lambda: M_c ~ 1/kappa_ideal;
    * stretching: the speed approaches the wave speed, c_c ~ v_ideal (number_c ~ 1/v_ideal);
    * drag: the drag length 2 lambda/(rho C_n d) = 1/d (chain lengths; d the normal drag number)
      reaches the fold's length 1/kappa_ideal: d_c ~ kappa_ideal (an upper estimate: the drag acts
      over the whole fast part of the line, longer than the fold).
    """
    out = []
    for chi, r in a["chi"].items():
        c = ds.sel(chi=chi)
        kap, sig = float(c["kappa_peak_ideal"]), float(c["sigma_peak_ideal"])
        est = {"bending": sig / kap**2, "end-mass": 1.0 / kap, "drag": kap,
               "stretching": 1.0 / float(c["v_peak_ideal"])}.get(mech, float("nan"))
        x = r["crossover"]
        meas = f"{x['number']:.3g} ({x['lo']:.3g}..{x['hi']:.3g})" if x["bracketed"] else x["statement"]
        ratio = x["number"] / est if x["bracketed"] else float("nan")
        extra = ""
        if mech == "drag" and x["bracketed"]:
            extra = f"; drag length at the crossover 1/d_c = {1 / x['number']:.3g} chain lengths"
        if mech == "stretching" and x["bracketed"]:
            extra = (f"; c_c = {1 / x['number']:.3g} = {1 / (x['number'] * float(c['v_peak_ideal'])):.3g} v_ideal "
                     f"(the guess c_c ~ v_ideal)")
        if mech == "bending" and x["bracketed"]:
            extra = (f"; bending length sqrt(beta_c/sigma) = {(x['number'] / sig) ** 0.5:.3g} against the ideal fold's "
                     f"radius {1 / kap:.3g}")
        out.append(f"  chi {chi:g}: measured crossover {meas}; estimate {est:.3g} (ideal kappa {kap:.4g}, "
                   f"sigma {sig:.4g}); measured/estimate {ratio:.3g}{extra}")
    return out


def report(mechs, figdir=None) -> None:
    """Each shipped study's analysis (v_peak and sigma_peak): the capped regime's power law per chi,
    the crossovers and their law in chi, the estimates against them, and the regime maps."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from snapping.regimes import bundled_study
    from snapping.regimes_analysis import analyze, regime_map

    for mech in mechs:
        ds = bundled_study(mech)
        print(f"== {mech}: status {ds.attrs['status']}, numbers {', '.join(f'{x:g}' for x in ds.number.values)}")
        for q in ("v_peak", "sigma_peak"):
            a = analyze(ds, q)
            print(f" {q}: ideal " + ", ".join(f"chi {c:g}: {r['ideal']:.5g} +- {r['ideal_error']:.2g}"
                                             for c, r in a["chi"].items()))
            for chi, r in a["chi"].items():
                c = ds.sel(chi=chi)
                cells = " ".join(f"{float(v):.3f}" for v in c[f"{q}_ratio"].values)
                print(f"  chi {chi:g}: ratios {cells}")
                print(f"    {r['fit']['statement']}; {r['crossover']['statement']}")
            print(f"  {a['crossover_law']['statement']}")
            if q == "v_peak":
                print("\n".join(estimates(mech, ds, a)))
        if figdir:
            path = os.path.join(figdir, f"regimes_{mech}.png")
            if mech == "stretching":  # the same-links ratios, extrapolated (the node-method study's limits were not
                # resolved apart; the links study's are, and its crossovers agree within 1% at chi 0.1-0.3)
                from snapping.regimes_analysis import with_level_ratios

                ds = with_level_ratios(ds)
            plt.close(regime_map(ds, path))
            print(f"  map: {path}")


def damping_check(chi: float, beta: float, zetas=(0.5, 1.0, 2.0), levels: int = 3) -> None:
    from snapping.regimes import regimes

    for z in zetas:
        ds = regimes("bending", [chi], [beta], accuracy="medium", levels=levels, damping=z, progress=False)
        c = ds.sel(chi=chi, number=beta)
        row = " ".join(f"{q} {float(c[q]):.5g} +- {float(c[q + '_error']):.2g} (levels "
                       + ", ".join(f"{v:.5g}" for v in c[q + "_level"].values) + ")" for q in ("v_peak", "sigma_peak"))
        print(f"chi {chi:g} beta {beta:g} grid damping ratio {z:g}: {row}; CPU "
              f"{float(np.nansum(c.cpu_time_level)):.1f} s", flush=True)


def cell(mech: str, chi: float, number: float, levels, first: int = -3, tol: float = 1e-6, damping: float = 1.0) -> None:
    """One cell of a study at some fold levels (the study's own runs, :func:`snapping.regimes._run_task`):
    the peaks, evaluations and CPU seconds of each, beside the ideal chain's on the same links."""
    from snapping.continuum import level_parameters
    from snapping.regimes import _run_task

    lv = level_parameters(max(levels) - first + 1, 0.5, first=first)
    for k in levels:
        for m, n in ((None, 0.0), (mech, number)):
            r = _run_task(chi, m, n, lv[k - first], tol, damping)
            print(f"chi {chi:g} {m or 'ideal'} {n:g} level {k} ({r['n_links']} links): v_peak {r['v_peak']:.6g} "
                  f"a_peak {r['a_peak']:.6g} sigma_peak {r['sigma_peak']:.6g}; {r['n_rhs']} evaluations, "
                  f"{r['cpu_time']:.2f} s CPU", flush=True)


def starts(cells, level: int, tol: float = 1e-6, damping: float = 4.0) -> None:
    """The two releases of the stretching study side by side: each cell (chi, c) at one fold level from
    the ``matched`` and the ``stretched`` start (the study's own runs, :func:`snapping.regimes._run_task`),
    each peak over the ideal chain's on the same links, and the two ratios' relative difference."""
    from snapping.continuum import level_parameters
    from snapping.regimes import _run_task

    lv = level_parameters(1, 0.5, first=level)[0]
    for chi, c in cells:
        ideal = _run_task(chi, None, 0.0, lv, tol)
        r = {st: _run_task(chi, "stretching", 1.0 / c, lv, tol, damping, st) for st in ("matched", "stretched")}
        for q in ("v_peak", "a_peak", "sigma_peak"):
            m, s_ = r["matched"][q] / ideal[q], r["stretched"][q] / ideal[q]
            print(f"chi {chi:g} c {c:g} level {level} ({ideal['n_links']} links) {q}: ratio matched {m:.6f}, "
                  f"stretched {s_:.6f}, difference {(s_ - m) / m:+.2e}", flush=True)
        print("  cost: " + "; ".join(f"{st} {x['n_rhs']} evaluations, {x['cpu_time']:.1f} s CPU" for st, x in r.items())
              + f"; ideal {ideal['n_rhs']}", flush=True)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--study", choices=sorted(STUDIES))
    ap.add_argument("--chis", default=None, help="--study: only these chi (comma-separated) into --out")
    ap.add_argument("--out", default=None, help="--study: the file of a part study (with --chis)")
    ap.add_argument("--merge", nargs="+", default=None, help="part study files to merge into the shipped --cost/--study MECH")
    ap.add_argument("--reuse", default=None, metavar="OLD",
                    help="start --out with the same runs of an earlier stretching study file OLD (before tol_c)")
    ap.add_argument("--escalate-from", default=None, metavar="OLD",
                    help="start --study MECH's escalating file (or --out) with the runs of OLD, its study unescalated")
    ap.add_argument("--rerun-cells", default=None, metavar="OLD",
                    help="start --study MECH's --out (a new file) with OLD's ideal runs only: the cells run again")
    ap.add_argument("--cost", choices=sorted(STUDIES))
    ap.add_argument("--extend", choices=sorted(STUDIES), help="refine the shipped study to STUDIES' levels, "
                    "reusing its runs (and --seed FILES of benchmarks/bench_bendconv.py)")
    ap.add_argument("--seed", nargs="*", default=[])
    ap.add_argument("--levels", type=int, default=None, help="--study/--extend: levels instead of STUDIES'")
    ap.add_argument("--file", default=None, help="the study file of --cost (default: the shipped one)")
    ap.add_argument("--damping-check", action="store_true")
    ap.add_argument("--report", nargs="*", default=None, metavar="MECH",
                    help="analyse the shipped studies (these, default all; and --figures DIR)")
    ap.add_argument("--figures", default=None, help="write the regime maps there (regimes_MECH.png)")
    ap.add_argument("--cell", nargs="+", type=float, default=None, metavar="X",
                    help="--cell CHI NUMBER LEVEL...: one cell of --study MECH at these fold levels (first -3)")
    ap.add_argument("--starts", nargs="+", default=None, metavar="CHI:C",
                    help="the matched and stretched starts at these stretching cells (chi:c) at --level")
    ap.add_argument("--level", type=int, default=-4)
    ap.add_argument("--chi", type=float, default=0.3)
    ap.add_argument("--beta", type=float, default=1e-4)
    ap.add_argument("--workers", type=int, default=1)
    a = ap.parse_args(argv)
    print(f"load {os.getloadavg()[0]:.1f}")
    if a.starts:
        starts([tuple(float(x) for x in cs.split(":")) for cs in a.starts], a.level)
    if a.cell:
        cell(a.study, a.cell[0], a.cell[1], [int(k) for k in a.cell[2:]])
    elif a.study and a.merge:
        merge(a.study, a.merge)
    elif a.reuse:
        reuse(a.reuse, a.out)
    elif a.study and a.rerun_cells:
        rerun_cells(a.study, a.rerun_cells, a.out)
    elif a.study and a.escalate_from:
        escalate_from(a.study, a.escalate_from, a.out)
    elif a.study:
        study(a.study, a.workers, [float(x) for x in a.chis.split(",")] if a.chis else None, a.out, a.levels)
    if a.extend:
        extend(a.extend, a.workers, a.seed, a.file, a.out, a.levels)
    if a.cost:
        cost(a.cost, a.file)
    if a.damping_check:
        damping_check(a.chi, a.beta)
    if a.report is not None:
        from snapping.regimes import BUNDLED

        report(a.report or BUNDLED, a.figures)


if __name__ == "__main__":
    main()
