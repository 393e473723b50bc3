"""The run Dataset of a 3D run: the planar run's names where they mean the same, and the new ones.

:func:`run3d_dataset` runs a :class:`snapping.spatial.starts3d.Problem3D` with
:func:`snapping.spatial.solve3d.run3d` and returns an :class:`xarray.Dataset` with the
layout of a planar run (:mod:`snapping.schema`; dimensions ``step``, ``snapshot``, ``node``,
``link``): per-step records (``v_max``, ``a_max``, ``sigma_max``, ``v_end``, ``a_end``,
``energy``, ``pin_work``, ``v_rel_max``, ``s_v_max``, ``link_error``, ``dt``,
``error_estimate``), snapshots (``x``, ``y``, ``vx``, ``vy``, ``ax``, ``ay``, ``speed``,
``accel``, ``tension``) and the attributes of the peaks and counts; the names only a 3D run
has are in :data:`snapping.schema.SPATIAL_VARS` and :data:`snapping.schema.SPATIAL_ATTRS`:
``z``, ``vz``, ``az`` (snapshots), ``z_amp``, ``vz_amp``, ``angular_momentum_g`` (records),
``start_z``, ``start_vz``, ``dims = 3``, ``z_amp_snap``, ... A planar run's Dataset is not
touched. Node index 0 is the free end, index N the held end, as in the plane. The planar
step variables a 3D run does not record (curvature, the pin force, ``s_a_max``) are absent.

Snapshots: ``initial`` (t = 0), ``requested`` (``snapshot_times``, from the dense output),
``peak`` (the located speed peak) and ``final``. The file is written by the planar writer,
:func:`snapping.simulate.dataset.save` (netCDF4, atomically).

Example
-------
>>> from snapping.spatial import Problem3D
>>> from snapping.spatial.dataset3d import run3d_dataset
>>> ds = run3d_dataset(Problem3D.catenary(0.5, 10).perturbed(1e-3), tol=1e-8, snapshot_times=[0.5])
>>> int(ds.attrs["dims"]), [str(k) for k in ds["snapshot_kind"].values], float(ds["z"].sel(snapshot=0)[0])
(3, ['initial', 'requested', 'peak', 'final'], 0.0)
"""

from __future__ import annotations

import json
import math

import numpy as np
import xarray as xr

from .. import _validate as V
from .. import schema
from . import chain3d as C
from .solve3d import RECORD_NAMES, run3d

__all__ = ["run3d_dataset", "build_dataset3d", "nodes_at", "problem3d_from_dataset", "rerun3d"]

#: record columns of run3d that go into the Dataset, and their names there (planar names
#: where they mean the same, schema.SPATIAL_STEP_VARS otherwise)
STEP_NAMES = {"dt": "dt", "err": "error_estimate", "v_max": "v_max", "a_max": "a_max", "sigma_max": "sigma_max",
              "v_end": "v_end", "a_end": "a_end", "energy": "energy", "pin_work": "pin_work",
              "v_rel_max": "v_rel_max", "s_v_max": "s_v_max", "link_error": "link_error",
              "z_amp": "z_amp", "vz_amp": "vz_amp", "angular_momentum_g": "angular_momentum_g",
              "bending_energy": "bending_energy", "dissipated": "dissipated"}
METHOD = "dop853-3d"


def _var(name: str) -> dict:
    for table in (schema.STEP_VARS, schema.PIN_STEP_VARS, schema.BODY_STEP_VARS, schema.NODE_PROFILE_VARS, schema.LINK_PROFILE_VARS,
                  schema.PROBLEM_VARS, schema.SPATIAL_VARS):
        if name in table:
            return dict(table[name])
    raise KeyError(name)  # pragma: no cover - a name missing from the schema is a bug


def nodes_at(problem, t: float, y: np.ndarray):
    """Positions, velocities, accelerations ((N + 1, 3) each) and link tensions (N) of the
    state ``y`` at time ``t``: the nodes walked from the held end (its prescribed motion),
    the tensions from the O(N) solve of :func:`snapping.spatial.chain3d.rhs3d` (with a body,
    its node forces in the accelerations)."""
    par, h, invm = problem.model()
    N = h.size
    if t in C.breakpoints(par):  # (the acceleration from t on, the right limit, as the planar snapshots)
        t = float(np.nextafter(t, np.inf))
    k = C.pin3d(float(t), par)
    r, v = C.state_to_nodes(y, h, pin=k[:6])
    w = C.Work(N)
    f = np.empty_like(y)
    C.rhs3d(N, float(t), y, f, w.T, w.cp, w.dp, par, h, invm)
    e = y[:3 * N].reshape(3, N).T
    s = w.T[:, None] * e
    s[1:] -= s[:-1].copy()
    a = np.zeros((N + 1, 3))
    if par[C.P_BODY] > 0.0:  # (the body's node forces, left by rhs3d in the model's scratch)
        from . import forces3d as F3

        s += F3.node_force_arrays(N, par, int(par[C.P_BODY]))[:N]
    a[:N] = s * invm[:, None] + par[[C.P_GX, C.P_GY, C.P_GZ]][None, :]
    a[N] = k[6:9]
    return r, v, a, w.T.copy()


def build_dataset3d(problem, res: dict, *, t_end=None, stop_fraction: float = 0.5) -> xr.Dataset:
    """The run Dataset of ``res`` (what :func:`snapping.spatial.solve3d.run3d` returned for
    ``problem``, run with ``snapshot_times``)."""
    h, m = problem.links.h, problem.links.m
    N = h.size
    rec = res["record"]
    col = {name: rec[:, i] for i, name in enumerate(res.get("record_names", RECORD_NAMES))}
    s_node = np.concatenate([np.cumsum(h[::-1])[::-1], [0.0]])
    # energy: the planar zero (hanging straight down at rest from the origin) is -g sum m_j s_j
    e_hang = -problem.gravity * float(np.sum(m * s_node[:N]))
    data_vars = {}
    for src, name in STEP_NAMES.items():
        if src not in col:
            continue
        vals = col[src].copy()
        if name == "energy":
            vals -= e_hang
        data_vars[name] = (schema.STEP_DIM, vals, _var(name))
    y0 = problem.initial_state()
    snaps = [(0.0, "initial", y0)] + [s for s in res["snapshots"] if s[0] > 0.0]
    tp, yp = res["peak_state"]
    if math.isfinite(res["t_snap_v"]) and tp > 0.0:
        yp = yp.copy()
        C.project(N, yp)
        snaps.append((float(tp), "peak", yp))
    snaps.append((float(res["t_final"]), "final", res["state"]))
    snaps.sort(key=lambda s: s[0])
    ns = len(snaps)
    prof = {name: np.full((ns, N + 1), np.nan) for name in ("x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az",
                                                           "speed", "accel")}
    tension = np.full((ns, N), np.nan)
    for i, (t, _, y) in enumerate(snaps):
        r, v, a, T = nodes_at(problem, t, y)
        for c, (pn, vn, an) in enumerate((("x", "vx", "ax"), ("y", "vy", "ay"), ("z", "vz", "az"))):
            prof[pn][i], prof[vn][i], prof[an][i] = r[:, c], v[:, c], a[:, c]
        prof["speed"][i] = np.linalg.norm(v, axis=1)
        prof["accel"][i] = np.linalg.norm(a, axis=1)
        tension[i] = T
    for name, arr in prof.items():
        data_vars[name] = ((schema.SNAPSHOT_DIM, schema.NODE_DIM), arr, _var(name))
    data_vars["tension"] = ((schema.SNAPSHOT_DIM, schema.LINK_DIM), tension, _var("tension"))
    data_vars["link_length"] = (schema.LINK_DIM, h.copy(), _var("link_length"))
    data_vars["node_mass"] = (schema.NODE_DIM, np.concatenate([m, [0.0]]), _var("node_mass"))
    for c, (pn, vn) in enumerate((("start_x", "start_vx"), ("start_y", "start_vy"), ("start_z", "start_vz"))):
        data_vars[pn] = (schema.NODE_DIM, problem.r[:, c].copy(), _var(pn))
        data_vars[vn] = (schema.NODE_DIM, problem.v[:, c].copy(), _var(vn))
    if problem.pin.kind == "table":
        for name, arr in zip(("pin_table_t", "pin_table_x", "pin_table_y", "pin_table_z"), problem.pin.table):
            data_vars[name] = (schema.PIN_TABLE_DIM, np.asarray(arr, dtype=float).copy(), _var(name))
    coords = {
        "t": (schema.STEP_DIM, col["t"].copy(), dict(schema.COORDS["t"])),
        "t_snapshot": (schema.SNAPSHOT_DIM, np.array([s[0] for s in snaps]), dict(schema.COORDS["t_snapshot"])),
        "snapshot_kind": (schema.SNAPSHOT_DIM, np.array([s[1] for s in snaps], dtype=str),
                          dict(schema.COORDS["snapshot_kind"])),
        "s_node": (schema.NODE_DIM, s_node, dict(schema.COORDS["s_node"])),
        "s_link": (schema.LINK_DIM, s_node[1:] + 0.5 * h, dict(schema.COORDS["s_link"])),
    }
    from .. import __version__

    snap = res["stop_reason"] == "snap"
    start = problem.start
    pert = start.get("perturbation")
    attrs = {
        "title": "snapping: falling-chain run in 3D (nondimensional: length l, g, rho = 1)",
        "Conventions": "CF-1.8", "units": "nondimensional (length L, mass M, time sqrt(L/g), force M g)",
        # inputs (the planar names)
        "chi": float(start.get("chi", math.nan)), "N": int(N), "method": METHOD, "tol": float(res["tol"]),
        "t_end": 0.0 if t_end is None else float(t_end), "stop_fraction": float(stop_fraction),
        "snapshot_times": np.asarray([s[0] for s in snaps if s[1] == "requested"], dtype=float),
        "initial": "problem", "tip_mass": float(problem.links.tip_mass), "gravity": float(problem.gravity),
        "pin_motion": problem.pin.kind, "start": str(start.get("kind", "")),
        "problem": json.dumps({"start": start, "pin": problem.pin.describe()}, sort_keys=True, default=float),
        # the 3D inputs
        "dims": 3, "g_dir": np.asarray(problem.g_dir, dtype=float), "normal": np.asarray(problem.normal, dtype=float),
        "perturbation": "" if pert is None else json.dumps(pert, sort_keys=True),
        "whirl": float(start.get("omega", math.nan)) if start.get("kind") == "whirling" else math.nan,
        # results (the planar names)
        "status": "completed" if res["status"] == "ok" else "failed", "stop_reason": res["stop_reason"],
        "failure": "" if res["status"] == "ok" else res["stop_reason"], "snap_reached": int(snap),
        "snap_note": "" if snap else f"the run stopped by {res['stop_reason']!r} before the speed fell",
        "t_final": float(res["t_final"]), "energy_initial": float(data_vars["energy"][1][0]),
        "energy_drift": float(res["energy_drift"]), "n_steps": int(res["n_steps"]),
        "n_rejected": int(res["n_rejected"]), "n_rhs": int(res["n_rhs"]), "wall_time": float(res["wall_time"]),
        "snapping_version": __version__,
        # the 3D results
        "z_amp_snap": float(res["z_amp_snap"]), "vz_amp_snap": float(res["vz_amp_snap"]),
        "z_amp_max": float(res["z_amp_max"]), "angular_momentum_drift": float(res["angular_momentum_drift"]),
        "link_error_max": float(res["link_error_max"]),
    }
    if problem.body_active:
        attrs["body"] = json.dumps(problem.body.describe(h), sort_keys=True)
    for q in ("v", "a", "sigma"):
        attrs[f"{q}_peak"] = float(res[f"{q}_peak"])
        attrs[f"t_snap_{q}"] = float(res[f"t_snap_{q}"]) if snap else math.nan
    dt = col["dt"][1:]
    attrs["dt_min_accepted"] = float(dt.min()) if dt.size else math.nan
    attrs["dt_max_accepted"] = float(dt.max()) if dt.size else math.nan
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def run3d_dataset(problem, *, tol: float = 1e-8, t_end: float | None = None, stop_fraction: float = 0.5,
                  snapshot_times=(), output=None, overwrite: bool = False, **kw) -> xr.Dataset:
    """Run ``problem`` (:func:`snapping.spatial.solve3d.run3d`, same keywords) and return its
    run Dataset; with ``output`` also write it (netCDF4, :func:`snapping.simulate.dataset.save`;
    the path is checked before the run)."""
    from ..simulate.dataset import check_writable, save
    from ..simulate.options import _times

    times = _times(list(snapshot_times))
    if output is not None:
        output = check_writable(output, overwrite=overwrite)
    if t_end is not None:
        t_end = V.real("t_end", t_end)
        if not (math.isfinite(t_end) and t_end > 0.0):
            raise V.SnappingInputError(f"t_end={t_end!r} is out of range: must be finite and > 0")
    res = run3d(problem, tol=tol, t_end=t_end, stop_fraction=stop_fraction, snapshot_times=times, **kw)
    ds = build_dataset3d(problem, res, t_end=t_end, stop_fraction=stop_fraction)
    if output is not None:
        save(ds, output, overwrite=True)
    return ds


def problem3d_from_dataset(ds: xr.Dataset):
    """The :class:`snapping.spatial.starts3d.Problem3D` a 3D run file was run for: its chain
    (``link_length``, ``node_mass``, ``tip_mass``), start (``start_*``), held end (the
    ``problem`` attribute's ``pin``, a table's samples ``pin_table_*``), gravity and planes."""
    from ..simulate.links import Links
    from .held3d import Pin3D
    from .starts3d import Problem3D

    if int(ds.attrs.get("dims", 2)) != 3 or "start_z" not in ds.variables:
        raise V.SnappingInputError("ds is not a 3D run file (no attribute dims = 3 or no start_z)")
    desc = json.loads(str(ds.attrs["problem"]))
    pin_d = desc.get("pin", {"kind": "fixed"})
    table = None
    if pin_d.get("kind") == "table":
        table = tuple(np.asarray(ds[f"pin_table_{c}"].values, dtype=float) for c in "txyz")
    N = int(ds.attrs["N"])
    links = Links(np.asarray(ds["link_length"].values, dtype=float), np.asarray(ds["node_mass"].values[:N], dtype=float),
                  float(ds.attrs["tip_mass"]))
    r = np.column_stack([np.asarray(ds[f"start_{c}"].values, dtype=float) for c in "xyz"])
    v = np.column_stack([np.asarray(ds[f"start_v{c}"].values, dtype=float) for c in "xyz"])
    return Problem3D(links, r, v, pin=Pin3D.from_description(pin_d, table), gravity=float(ds.attrs["gravity"]),
                     g_dir=tuple(np.asarray(ds.attrs["g_dir"], dtype=float).tolist()),
                     normal=tuple(np.asarray(ds.attrs["normal"], dtype=float).tolist()), start=desc.get("start", {}))


def rerun3d(ds: xr.Dataset, *, snapshot_times=(), output=None, overwrite: bool = False) -> xr.Dataset:
    """The 3D run of the file ``ds`` run again (same problem, tolerance and stop), with
    ``snapshot_times``: the same steps, so the same peaks (``snapping animate --frames``)."""
    problem = problem3d_from_dataset(ds)
    t_end = float(ds.attrs.get("t_end", 0.0))
    return run3d_dataset(problem, tol=float(ds.attrs["tol"]), t_end=t_end if t_end > 0.0 else None,
                         stop_fraction=float(ds.attrs["stop_fraction"]), snapshot_times=snapshot_times, output=output,
                         overwrite=overwrite)
