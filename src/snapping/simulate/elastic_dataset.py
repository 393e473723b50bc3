"""The run Dataset of the elastic line (:func:`snapping.simulate.elastic_solve.solve`): the
per-step records, the profiles at the snapshots, the problem's arrays, with the names and
attributes of :mod:`snapping.schema`.

Assembled without xarray's merge and alignment (:func:`_assemble`, ``xr.Dataset._construct_direct``:
the variables share no index, so there is nothing to align; 1-3 ms a run less at N = 100), the
same Dataset as xarray's public constructor builds (:func:`_public`, used where the private
one is absent or raises, and with ``DIRECT_DATASET = False``).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from .. import schema

__all__ = ["dataset", "STEP_NAMES"]

#: the per-step record's columns (the Dataset's step variables, in this order)
STEP_NAMES = ("dt", "v_max", "a_max", "sigma_max", "s_v_max", "s_a_max", "s_sigma_max", "sigma_min", "v_end",
              "a_end", "pin_force_x", "pin_force_y", "energy", "elastic_energy", "pin_work", "dissipated",
              "strain_max", "n_slack", "kappa_max", "s_kappa_max",
              "kappa_max_interior")
#: the Dataset assembled without xarray's merge (:func:`_assemble`); False: its public constructor
DIRECT_DATASET = True


def _attrs(name: str) -> dict:
    for table in (schema.STEP_VARS, schema.PIN_STEP_VARS, schema.BODY_STEP_VARS, schema.ELASTIC_STEP_VARS,
                  schema.NODE_PROFILE_VARS, schema.LINK_PROFILE_VARS, schema.ELASTIC_LINK_VARS,
                  schema.COORDS, schema.PROBLEM_VARS):
        if name in table:
            return dict(table[name])
    raise KeyError(name)


def dataset(line, times, rec, snap_t, snap_z, snap_kind, attrs) -> xr.Dataset:
    """The run Dataset: per-step records, profiles at the snapshots, the problem's arrays."""
    N = line.N
    st, sd, nd, ld = schema.STEP_DIM, schema.SNAPSHOT_DIM, schema.NODE_DIM, schema.LINK_DIM
    data = {name: ((st,), rec[:, k], _attrs(name)) for k, name in enumerate(STEP_NAMES)}
    order = np.argsort(np.asarray(snap_t), kind="stable")
    prof = {k: [] for k in ("x", "y", "vx", "vy", "ax", "ay", "speed", "accel", "tension", "strain")}
    for i in order:
        t, z = snap_t[i], snap_z[i]
        x, y, vx, vy = line.unpack(z, t)
        dz = line.rhs(t, z)
        pa = line.pin.kinematics(float(t))
        ax = np.concatenate([dz[2:4 * N:4], [pa[4]]])
        ay = np.concatenate([dz[3:4 * N:4], [pa[5]]])
        T, E, _ = line.link_state(t, z)
        for k, v in (("x", x), ("y", y), ("vx", vx), ("vy", vy), ("ax", ax), ("ay", ay),
                     ("speed", np.hypot(vx, vy)), ("accel", np.hypot(ax, ay)), ("tension", T), ("strain", E)):
            prof[k].append(v)
    for k, v in prof.items():
        data[k] = ((sd, ld if k in ("tension", "strain") else nd), np.asarray(v), _attrs(k))
    data["link_length"] = ((ld,), line.h, _attrs("link_length"))
    data["node_mass"] = ((nd,), np.concatenate([line.m, [0.0]]), _attrs("node_mass"))
    data["axial_stiffness"] = ((ld,), line.ea, _attrs("axial_stiffness"))
    coords = {"t": ((st,), times, _attrs("t")),
              "t_snapshot": ((sd,), np.asarray(snap_t)[order], _attrs("t_snapshot")),
              "snapshot_kind": ((sd,), np.asarray(snap_kind)[order].astype(str), _attrs("snapshot_kind")),
              "s_node": ((nd,), np.concatenate([line.snode, [0.0]]), _attrs("s_node")),
              "s_link": ((ld,), line.snode - 0.5 * line.h, _attrs("s_link"))}
    attrs = {k: (int(v) if isinstance(v, (bool, np.bool_)) else v) for k, v in attrs.items()}
    attrs["units"] = "nondimensional (length L, mass M, time sqrt(L/g), force M g)"
    return _assemble(data, coords, attrs) if DIRECT_DATASET else _public(data, coords, attrs)


def _public(data, coords, attrs) -> xr.Dataset:
    """The Dataset of ``data`` and ``coords`` ({name: (dims, values, attrs)}) by xarray's
    public constructor (its merge and alignment checks)."""
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update(attrs)
    return ds


def _assemble(data, coords, attrs) -> xr.Dataset:
    """:func:`_public`'s Dataset without its merge (1-3 ms a run: the variables share no index
    and have no conflicts to resolve), by ``xr.Dataset._construct_direct``; the public
    constructor where that is absent or raises (another xarray)."""
    direct = getattr(xr.Dataset, "_construct_direct", None)
    if direct is None:
        return _public(data, coords, attrs)
    try:
        return direct({k: xr.Variable(*v) for k, v in (*data.items(), *coords.items())}, set(coords), attrs=attrs)
    except Exception:  # (another xarray's private constructor)
        return _public(data, coords, attrs)
