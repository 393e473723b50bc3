"""The run :class:`xarray.Dataset`: building it, saving, loading, reading inputs back.

All names, units and long names come from :mod:`snapping.schema`.
"""

from __future__ import annotations

import math

from dataclasses import dataclass

import numpy as np
import xarray as xr

from .. import _validate as V
from .. import schema
from . import kernels as K
from ._netcdf import open_netcdf, records_from_dataset  # noqa: F401 (re-exported: dataset.open_netcdf, ...)
from .chain import ChainState, curvature_profile, link_arclength, node_arclength

__all__ = ["Run", "summary", "build_dataset", "save", "load_run", "inputs_from_attrs", "initial_from_dataset",
           "problem_from_dataset"]


@dataclass
class Run:
    """Result of :func:`run`: the run Dataset, and the final state to continue from.

    Attributes
    ----------
    dataset : xarray.Dataset
        The run (see :mod:`snapping.schema`).
    state : ChainState
        The state at the last accepted step.
    path : str or None
        Where the dataset was saved, if anywhere.
    """

    dataset: xr.Dataset
    state: ChainState
    path: str | None = None

    def summary(self) -> dict:
        """The detected results and inputs as a plain dict (also the CLI's --json)."""
        return summary(self.dataset)

    def save(self, path, *, overwrite: bool = False) -> str:
        """Write the dataset as netCDF4 (atomically; an existing file only with ``overwrite=True``)."""
        self.path = save(self.dataset, path, overwrite=overwrite)
        return self.path


#: the units of every number of a run (file, summary, CLI table)
UNITS = "nondimensional (length L, mass M, time sqrt(L/g), force M g)"

SUMMARY_KEYS = (
    "chi", "N", "method", "chords", "tol", "dt0", "status", "stop_reason", "snap_reached", "snap_note",
    "t_snap_v", "t_snap_a", "t_snap_sigma", "v_peak", "a_peak", "sigma_peak", "kappa_peak", "kappa_max_0",
    "energy_drift", "link_drift", "link_drift_initial", "length_drift", "link_error_initial",
    "t_final", "dt_min_accepted", "n_steps", "n_rejected", "n_rhs", "wall_time", "snapping_version",
    "start", "tip_mass", "pin_motion", "gravity",  # (general problems only)
    "method_choice", "n_jacobians", "n_factorizations",  # (schema.METHOD_ATTRS: a body's method)
    "drag_jacobian",  # (stored only when not the default, "banded")
    "min_tension", "t_compression",  # (files written before sigma_min existed have none)
    "start_rest",  # (problems with a body only)
)


#: The snapping times: absent (None in :func:`summary`) when the run did not reach the snap.
SNAP_TIMES = ("t_snap_v", "t_snap_a", "t_snap_sigma")
#: The peaks: maxima over the run when it did not reach the snap.
PEAKS = ("v_peak", "a_peak", "sigma_peak", "kappa_peak")


def summary(ds: xr.Dataset) -> dict:
    """Inputs and detected results of a run Dataset, as a dict of plain Python values.

    Only what was computed is claimed: when the run did not reach the snap
    (``snap_reached`` false, e.g. it ended at ``t_end`` before it), ``snap_reached``
    is False, the snapping times ``t_snap_*`` are None (absent, not a number) and
    ``snap_note`` says why; the ``*_peak`` values are then the maxima over the run.
    A snapping time whose peak was at the run's last step is None too. Files written
    before ``snap_reached`` existed have none and are summarised as they are. Where the rigid
    links carried compression, ``t_compression`` and ``compression_note`` say from when.
    """
    V.run_dataset("ds", ds)
    out = {}
    for k in SUMMARY_KEYS:
        if k in ds.attrs:
            v = ds.attrs[k]
            out[k] = v.item() if isinstance(v, np.generic) else v
    if "method" in out:
        out["units"] = str(ds.attrs.get("units", UNITS))
    if ds.attrs.get("body"):  # a line's body: its nondimensional numbers (beta, drag, ...; snapping.simulate.body)
        from .body import summarize

        out["body"] = summarize(str(ds.attrs["body"]))
    for k in ("min_tension", "t_compression"):  # NaN: no compression (or no sigma_min record): nothing to say
        if isinstance(out.get(k), float) and np.isnan(out[k]):
            out.pop(k)
    if "t_compression" in out:
        from .compression import compression_note

        out["compression_note"] = compression_note(ds.attrs)
    if isinstance(out.get("chi"), float) and np.isnan(out["chi"]):
        out["chi"] = None  # a general problem's start is not a catenary of some chi ('start' says what it is)
    if "snap_reached" in out:
        out["snap_reached"] = bool(out["snap_reached"])
        for k in SNAP_TIMES:
            if k in out and isinstance(out[k], float) and np.isnan(out[k]):
                out[k] = None  # deliberately absent: the peak was not reached (snap_note says why)
        if not out["snap_reached"]:
            out["peaks"] = "maxima over the run (the run did not reach the snap)"
        else:
            out.pop("snap_note", None)
    return out


def relative_fall(records: np.ndarray, settle: float, f: float) -> bool:
    """Whether the recorded speed relative to a moving held end (``v_rel_max``) rose after
    ``settle`` (the held end's settle time, :func:`snapping.simulate.general.settle_time`)
    above its value then and fell below ``f`` of its running peak since then: the stop
    rule of :func:`snapping.simulate.rk.after_attempt` for a moving held end, on the record."""
    from . import general as G

    col = K.NREC + G.RECORD_NAMES_G.index("v_rel_max")
    rec = np.asarray(records, dtype=float)
    if rec.ndim != 2 or rec.shape[1] <= col:
        return False
    v = rec[rec[:, K.R_T] >= settle, col]
    if v.size < 2:
        return False
    running = np.fmax.accumulate(v)
    return bool(np.any((running > v[0]) & (v < f * running)))


def snap_results(records: np.ndarray, inputs: dict, results: dict) -> dict:
    """The result attributes with what the run did not compute taken out.

    ``snap_reached`` is 1 if, at some recorded step, v_max fell below
    ``stop_fraction`` of its running peak (with a moving held end: the speed relative to
    it, from its settle time on, :func:`relative_fall`; the rule that stops an automatic run; for
    a run with ``t_end`` it is applied to the record), or at the last step below
    ``stop_fraction`` of ``v_peak`` (what the compiled loop tests). If not, the
    snapping times ``t_snap_*`` are NaN and ``snap_note`` says why; the peaks stay,
    as maxima over the run. A snapping time whose peak lies at the run's last step
    (not strictly inside the run) is NaN as well.
    """
    res = dict(results)
    if "v_peak" not in res or "stop_fraction" not in inputs:
        return res
    f = float(inputs["stop_fraction"])
    rec = np.asarray(records, dtype=float)
    v = rec[:, K.R_VMAX] if rec.ndim == 2 and len(rec) else np.zeros(0)
    t_final = float(res.get("t_final", rec[-1, K.R_T] if len(v) else 0.0))
    v_peak = float(res["v_peak"])
    reached = False
    settle = float(res.get("t_pin_settled", math.nan))
    if settle >= 0.0:  # (NaN or absent: a fixed held end)
        reached = relative_fall(rec, settle, f)
    elif v.size and np.isfinite(v_peak) and v_peak > 0.0:
        running = np.fmax.accumulate(v)
        reached = bool(np.any(v < f * running) or v[-1] < f * v_peak)
    res["snap_reached"] = int(reached)
    for q in ("v", "a", "sigma"):
        k = f"t_snap_{q}"
        if k in res and not (reached and float(res[k]) < t_final):
            res[k] = float("nan")
    if reached:
        res["snap_note"] = ""
    else:
        status = str(res.get("status", ""))
        why = {"failed": "failed", "checkpoint": "has run so far", "interrupted": "was interrupted"}.get(status,
                                                                                                   "ended")
        res["snap_note"] = (f"the run {why} at t={t_final:.9g} before the snap (v_max never fell below "
                            f"stop_fraction={f:g} of its running peak; a larger stop_fraction accepts a smaller fall): "
                            f"no snapping time; the peaks are maxima over the run")
    return res


def _attr_value(v):
    """netCDF-friendly attribute value."""
    if v is None:
        return ""
    if isinstance(v, (bool, np.bool_)):
        return int(v)
    if isinstance(v, (list, tuple)):
        return np.asarray(v, dtype=float)
    if isinstance(v, np.generic):
        return v.item()
    return v


def build_dataset(records: np.ndarray, snapshots: list, N: int, inputs: dict, results: dict) -> xr.Dataset:
    """Assemble a run Dataset.

    Parameters
    ----------
    records : ndarray, shape (n_steps, kernels.NREC [+ general, body columns])
        Per-step rows in the column order of ``kernels.RECORD_NAMES``.
    snapshots : list of (t, kind, Z)
        Full states in the (7, N + 1) kernel layout.
    N : int
        Number of links.
    inputs, results : dict
        Global attributes (schema.INPUT_ATTRS, schema.RESULT_ATTRS).
    """
    from . import general as G

    inputs = dict(inputs)
    problem = inputs.pop("problem", None)
    t = records[:, K.R_T]
    data_vars = {}
    for col, name in enumerate(K.RECORD_NAMES):
        if name == "t":
            continue
        data_vars[name] = (schema.STEP_DIM, records[:, col].copy(), dict(schema.STEP_VARS[name]))
    step_vars_g = {**schema.PIN_STEP_VARS, **schema.BODY_STEP_VARS}  # (BODY_STEP_VARS: runs with a Body)
    for col, name in enumerate((G.RECORD_NAMES_G + tuple(schema.BODY_STEP_VARS))[:records.shape[1] - K.NREC],
                               start=K.NREC):
        data_vars[name] = (schema.STEP_DIM, records[:, col].copy(), dict(step_vars_g[name]))
    snapshots = sorted(snapshots, key=lambda s: s[0])
    ns = len(snapshots)
    prof = {name: np.full((ns, N + 1), np.nan) for name in schema.NODE_PROFILE_VARS}
    tension = np.full((ns, N), np.nan)
    for i, (_, _, Z) in enumerate(snapshots):
        prof["x"][i], prof["y"][i] = Z[K.RX], Z[K.RY]
        prof["vx"][i], prof["vy"][i] = Z[K.RVX], Z[K.RVY]
        prof["ax"][i], prof["ay"][i] = Z[K.RAX], Z[K.RAY]
        prof["speed"][i] = np.hypot(Z[K.RVX], Z[K.RVY])
        prof["accel"][i] = np.hypot(Z[K.RAX], Z[K.RAY])
        prof["curvature"][i] = curvature_profile(Z[K.RX], Z[K.RY],
                                                 None if problem is None else problem.links.h)
        tension[i] = Z[K.RSIG, :N]
    for name, arr in prof.items():
        data_vars[name] = ((schema.SNAPSHOT_DIM, schema.NODE_DIM), arr, dict(schema.NODE_PROFILE_VARS[name]))
    data_vars["tension"] = ((schema.SNAPSHOT_DIM, schema.LINK_DIM), tension, dict(schema.LINK_PROFILE_VARS["tension"]))
    coords = {
        "t": (schema.STEP_DIM, t.copy(), dict(schema.COORDS["t"])),
        "t_snapshot": (schema.SNAPSHOT_DIM, np.array([s[0] for s in snapshots], dtype=float),
                       dict(schema.COORDS["t_snapshot"])),
        "snapshot_kind": (schema.SNAPSHOT_DIM, np.array([s[1] for s in snapshots], dtype=str),
                          dict(schema.COORDS["snapshot_kind"])),
        "s_node": (schema.NODE_DIM, node_arclength(N), dict(schema.COORDS["s_node"])),
        "s_link": (schema.LINK_DIM, link_arclength(N), dict(schema.COORDS["s_link"])),
    }
    attrs = {"title": "snapping: falling-chain run (nondimensional: length l, g, rho = 1)",
             "Conventions": "CF-1.8", "units": UNITS}
    results = snap_results(records, inputs, results)
    from .compression import compression_results

    results.update(compression_results(records, N))
    for k, v in {**inputs, **results}.items():
        attrs[k] = _attr_value(v)
    if problem is not None:
        _add_problem(problem, data_vars, coords, attrs)
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def _add_problem(problem, data_vars: dict, coords: dict, attrs: dict) -> None:
    """The problem of a general run: link lengths, node masses, arclength coordinates, the
    pin table, and its description (schema.PROBLEM_VARS, schema.PROBLEM_ATTRS)."""
    h, m = problem.links.h, problem.links.m
    N = h.size
    s_node = np.zeros(N + 1)
    s_node[:N] = np.cumsum(h[::-1])[::-1]
    coords["s_node"] = (schema.NODE_DIM, s_node, dict(schema.COORDS["s_node"]))
    coords["s_link"] = (schema.LINK_DIM, s_node[1:] + 0.5 * h, dict(schema.COORDS["s_link"]))
    data_vars["link_length"] = (schema.LINK_DIM, h.copy(), dict(schema.PROBLEM_VARS["link_length"]))
    data_vars["node_mass"] = (schema.NODE_DIM, np.concatenate([m, [0.0]]), dict(schema.PROBLEM_VARS["node_mass"]))
    for name, arr in (("start_x", problem.x), ("start_y", problem.y), ("start_vx", problem.vx),
                      ("start_vy", problem.vy)):
        data_vars[name] = (schema.NODE_DIM, np.asarray(arr, dtype=float).copy(), dict(schema.PROBLEM_VARS[name]))
    if problem.pin.kind == "table":
        tt, xx, yy = problem.pin.table
        for name, arr in (("pin_table_t", tt), ("pin_table_x", xx), ("pin_table_y", yy)):
            data_vars[name] = (schema.PIN_TABLE_DIM, np.asarray(arr, dtype=float).copy(),
                               dict(schema.PROBLEM_VARS[name]))
    attrs["problem"] = problem.describe_json()
    if getattr(problem, "body", None) is not None:
        import json

        attrs["body"] = json.dumps(problem.body.describe(problem.links.h), sort_keys=True)
    attrs["tip_mass"] = float(problem.links.tip_mass)
    attrs["gravity"] = float(problem.gravity)
    attrs["pin_motion"] = problem.pin.kind
    attrs["start"] = str(problem.start.get("kind", ""))
    if getattr(problem, "body", None) is not None:  # (new names: the shape the line was released from)
        kind = str(problem.start.get("kind", ""))
        attrs["start_rest"] = str(problem.start.get("rest", "catenary" if kind in ("catenary", "supports") else
                                                    "as given"))


def check_writable(path, *, overwrite: bool = False, name: str = "output", need_bytes: float = 0.0) -> str:
    """The path to write for output ``path`` (a symbolic link's target), checked before a run; raises
    :class:`SnappingInputError` when it cannot be written, is not a regular file or a new path,
    already exists (unless ``overwrite``), or its filesystem lacks ``need_bytes`` of space
    (the rules: :mod:`snapping._files`)."""
    from .. import _files

    return _files.check_output(path, name=name, overwrite=overwrite, need_bytes=need_bytes)


def save(ds: xr.Dataset, path, *, overwrite: bool = False) -> str:
    """Write a run Dataset as netCDF4, atomically; returns the path written.

    The file is written to a temporary file in the same directory, flushed to
    disk and renamed over ``path`` (``os.replace``), under the output's exclusive
    lock: a reader, or a run killed while saving, never sees a half-written file.
    An existing file is refused unless ``overwrite=True``, and then only replaced by
    a complete one; a symbolic link is written through; a full disk raises
    :class:`snapping._files.OutputWriteError` saying so (the rules: :mod:`snapping._files`).
    """
    from .. import _files

    if not isinstance(ds, xr.Dataset):
        raise V.SnappingInputError(f"ds={type(ds).__name__} is not an xarray.Dataset")
    encoding = {name: {"zlib": True, "complevel": 1} for name in ds.data_vars if ds[name].dtype.kind not in "OUS"}
    return _files.write_atomic(path, lambda tmp: ds.to_netcdf(tmp, format="NETCDF4", engine="netcdf4",
                                                              encoding=encoding),
                               overwrite=overwrite, dataset=ds)


def _canonical(value) -> bytes:
    """Bytes of an attribute value that survive a netCDF round trip unchanged (numbers as
    float64 lists, strings as text)."""
    if isinstance(value, (str, bytes)):
        return b"s" + (value.encode() if isinstance(value, str) else value)
    a = np.asarray(value)
    if a.dtype.kind in "biuf":
        return b"n" + np.ascontiguousarray(a.astype(np.float64).ravel()).tobytes()
    return b"r" + repr(a.ravel().tolist()).encode()


def content_digest(ds: xr.Dataset) -> str:
    """SHA-256 (hex) of a run Dataset's content: every attribute except
    ``schema.DIGEST_ATTR``, and every variable's name, dimensions, dtype and values. The same
    before writing and after reading back the netCDF file; any edit changes it.

    >>> import numpy as np, xarray as xr
    >>> ds = xr.Dataset({"a": ("x", np.arange(3.0))}, attrs={"chi": 0.25})
    >>> d = content_digest(ds)
    >>> ds.attrs["chi"] = 0.5
    >>> content_digest(ds) == d
    False
    """
    import hashlib

    h = hashlib.sha256()
    for k in sorted(ds.attrs):
        if k != schema.DIGEST_ATTR:
            h.update(b"\0attr\0" + k.encode() + b"\0" + _canonical(ds.attrs[k]))
    for name in sorted(map(str, ds.variables)):
        var = ds.variables[name]
        a = np.asarray(var.values)
        h.update(b"\0var\0" + name.encode() + b"\0" + repr(tuple(var.dims)).encode() + repr(a.shape).encode())
        if a.dtype.kind in "OUS":
            h.update(repr(a.ravel().tolist()).encode())
        else:
            h.update(a.dtype.str.encode() + np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def seal(ds: xr.Dataset) -> xr.Dataset:
    """``ds`` with its integrity digest (``schema.DIGEST_ATTR``) set, in place; returned."""
    ds.attrs[schema.DIGEST_ATTR] = content_digest(ds)
    return ds


def verify_digest(ds: xr.Dataset, what: str) -> None:
    """Raise :class:`SnappingInputError` (naming ``what``) unless ``ds`` carries its own
    content digest: an edited or corrupted run file is not trusted."""
    stored = ds.attrs.get(schema.DIGEST_ATTR)
    if not isinstance(stored, str) or not stored:
        raise V.SnappingInputError(f"{what} has no integrity digest (attribute {schema.DIGEST_ATTR!r}): it was "
                                   f"written by another program or an older snapping, or edited; it is not resumed")
    if content_digest(ds) != stored:
        raise V.SnappingInputError(f"{what} fails its integrity check: its inputs or state were changed after it "
                                   f"was written (edited or corrupted); it is not resumed, start the run again")


def load_run(path) -> xr.Dataset:
    """Open a run file (loaded into memory, the file is closed).

    >>> import tempfile, os
    >>> from snapping.simulate import run
    >>> r = run(0.5, 4, t_end=0.01, progress=False)
    >>> p = os.path.join(tempfile.mkdtemp(), "run.nc"); _ = r.save(p)
    >>> int(load_run(p).attrs["N"])
    4
    """
    p = V.file_path("path", path)
    ds = open_netcdf(p)
    if "t" not in ds.variables or "N" not in ds.attrs:
        raise V.SnappingInputError(f"path={p!r} is not a snapping run file (no time 't' or attribute 'N'; "
                                   f"variables: {sorted(map(str, ds.variables))[:6]})")
    return ds


def initial_from_dataset(ds: xr.Dataset) -> ChainState:
    """The initial state stored in a run (its snapshot of kind 'initial')."""
    if not isinstance(ds, xr.Dataset) or "snapshot_kind" not in ds.variables:
        raise V.SnappingInputError("ds is not a run Dataset with snapshots (no 'snapshot_kind')")
    kinds = [str(k) for k in ds["snapshot_kind"].values]
    if "initial" not in kinds:
        raise V.SnappingInputError("the run has no snapshot of kind 'initial'")
    i = kinds.index("initial")
    sn = ds.isel({schema.SNAPSHOT_DIM: i})
    return ChainState(sn["x"].values, sn["y"].values, sn["vx"].values, sn["vy"].values, float(sn["t_snapshot"]))


def inputs_from_attrs(ds: xr.Dataset) -> dict:
    """Keyword arguments of :func:`snapping.simulate.run` that reproduce a run.

    Runs are deterministic (no fastmath, fixed operation order), so
    ``run(**inputs_from_attrs(ds))`` recomputes the same numbers.
    """
    if not isinstance(ds, xr.Dataset):
        raise V.SnappingInputError(f"ds={type(ds).__name__} is not a run Dataset (expected an xarray.Dataset)")
    missing = [k for k in ("chi", "N", "tol", "method", "dt0", "t_end", "stop_fraction", "snapshot_times",
                           "record_thin", "chords", "t_end_max", "max_link_error") if k not in ds.attrs]
    if missing:
        raise V.SnappingInputError(f"ds is not a snapping run: input attributes {missing} are missing")
    try:
        return _inputs_from_attrs(ds)
    except (TypeError, ValueError) as exc:
        raise V.SnappingInputError(f"ds has input attributes that cannot be read back ({exc})") from None


def _inputs_from_attrs(ds: xr.Dataset) -> dict:
    a = ds.attrs
    out = {
        "chi": None if not np.isfinite(float(a["chi"])) else float(a["chi"]),
        "N": int(a["N"]),
        "tol": float(a["tol"]),
        "method": str(a["method"]),
        "dt0": float(a["dt0"]),
        "t_end": None if float(a["t_end"]) == 0.0 else float(a["t_end"]),
        "stop_fraction": float(a["stop_fraction"]),
        "snapshot_times": tuple(float(v) for v in np.atleast_1d(np.asarray(a["snapshot_times"], dtype=float))),
        "record_thin": float(a["record_thin"]),
        "chords": str(a["chords"]),
        "t_end_max": float(a["t_end_max"]),
        "max_link_error": float(a["max_link_error"]),
    }
    for k, default in schema.INPUT_DEFAULTS.items():  # files written before these inputs existed
        v = a.get(k, default)
        if k == "max_rejections":
            out[k] = int(v)
        else:
            out[k] = None if float(v) == 0.0 and k == "max_energy_drift" else float(v)
    if "drag_jacobian" in a:  # (stored only when not the default)
        out["drag_jacobian"] = str(a["drag_jacobian"])
    if str(a.get("initial", "catenary")) == "snapshot":
        out["initial"] = initial_from_dataset(ds)
    if str(a.get("initial", "catenary")) == "problem":
        out["problem"] = problem_from_dataset(ds)
        out["chi"] = None
        out["chords"] = None  # (the default: the problem's start holds its own)
    return out


def problem_from_dataset(ds: xr.Dataset):
    """The :class:`snapping.simulate.problem.Problem` of a general run (the inverse of what
    :func:`build_dataset` records): links and masses from ``link_length``/``node_mass``,
    the start from ``start_x`` ... ``start_vy``, the pin motion and gravity from the
    ``problem`` attribute (and the pin table variables)."""
    import json

    from .problem import Links, PinMotion, Problem

    for k in ("link_length", "node_mass", "start_x", "start_y", "start_vx", "start_vy"):
        if k not in ds.variables:
            raise V.SnappingInputError(f"ds is a general run without its {k!r} variable")
    try:
        desc = json.loads(str(ds.attrs["problem"]))
        h = np.asarray(ds["link_length"].values, dtype=float)
        m = np.asarray(ds["node_mass"].values, dtype=float)[:-1]
        tip = float(ds.attrs.get("tip_mass", 0.0))
        ch = desc["chain"]
        links = Links(h, m, tip, str(ch.get("kind", "explicit")),
                      {k: v for k, v in ch.items() if k not in ("kind", "N", "tip_mass")}, None)
        pd = desc["pin"]
        kind = pd["kind"]
        if kind == "fixed":
            pin = PinMotion.fixed()
        elif kind == "pull":
            pin = PinMotion.pull(pd["accel"], pd["duration"], pd["t0"])
        elif kind == "flick":
            pin = PinMotion.flick(pd["accel"], pd["period"], pd["t0"])
        else:
            pin = PinMotion.from_table(ds["pin_table_t"].values, ds["pin_table_x"].values, ds["pin_table_y"].values)
        st = dict(desc["start"])
        vel = (ds["start_vx"].values, ds["start_vy"].values) if st.get("velocities") else (None, None)
        body = None
        if "body" in desc:
            from .body import Body

            body = Body.from_describe(desc["body"])
        p = Problem._make(links, ds["start_x"].values, ds["start_y"].values, *vel, pin,
                          float(desc["gravity"]), st, chi=st.get("chi"), chords=st.get("chords"), body=body)
    except (KeyError, TypeError, ValueError, json.JSONDecodeError) as exc:
        if isinstance(exc, V.SnappingInputError):
            raise
        raise V.SnappingInputError(f"ds has a problem description that cannot be read back ({exc})") from None
    return p
