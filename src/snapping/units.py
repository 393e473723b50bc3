"""Unit conversion: the nondimensional numbers of the library to SI, and back.

Every run, fit and sweep is nondimensional (:mod:`snapping.schema`): lengths in
chain lengths L, masses in chain masses M, accelerations in g. A real chain fixes
the three scales, ``Scales(length=L [m], mass=M [kg], g [m s-2])``, and every other
unit follows by dimensional analysis: a quantity of dimension
[length]^p [mass]^q [time]^r has the unit L^(p + r/2) M^q g^(-r/2), since the
time unit is sqrt(L/g). So:

=============  ==============  ==========
kind           unit            CF units
=============  ==============  ==========
length         L               ``m``
mass           M               ``kg``
time           sqrt(L/g)       ``s``
speed          sqrt(g L)       ``m s-1``
acceleration   g               ``m s-2``
force          M g             ``N``
energy         M g L           ``J``
curvature      1/L             ``m-1``
rate           sqrt(g/L)       ``s-1``
angular_mom.   M L sqrt(g L)   ``kg m2 s-1``
dimensionless  1               ``1``
=============  ==============  ==========

The exponents are computed from each kind's SI unit with `pint
<https://pint.readthedocs.io>`_ (the unit library), and pint checks that the
product of the scales has that unit's dimension (:class:`Scales`, :data:`KIND_UNITS`,
:data:`G_STANDARD` and the pint registry are defined in :mod:`snapping.unit_scales` and
imported here).

:func:`to_si` converts a run Dataset (variables keep their names; ``units`` becomes
the CF string), :func:`from_si` converts it back, :func:`summary_to_si` converts a
run's summary dict (:func:`snapping.simulate.summary`).

Example
-------
>>> s = Scales(length=1.022, mass=0.0208)        # the paper's chain, g = 9.81
>>> round(s.time, 6), round(s.force, 6)          # sqrt(L/g) in s, M g in N
(0.322768, 0.204048)
>>> s.units("speed")
'm s-1'
"""

from __future__ import annotations

import math

from . import _validate as V
from . import schema
from .unit_scales import (G_STANDARD, KIND_UNITS, SCALE_RANGE, Scales, _1, _A, _E, _F, _H, _K, _L, _M, _T, _V, _W,
                          _scales, registry)

__all__ = ["Scales", "KIND_UNITS", "VARIABLE_KINDS", "VALUE_KINDS", "G_STANDARD", "NONDIMENSIONAL_NOTE",
           "kind_of", "to_si", "from_si", "summary_to_si", "values_to_si", "si_rows", "fit_rows", "fit_to_si",
           "AIR_DENSITY", "CD_NORMAL", "CD_TANGENTIAL", "body_numbers"]

#: What the nondimensional numbers mean, for output that prints no SI.
NONDIMENSIONAL_NOTE = ("units: nondimensional (lengths in chain lengths L, masses in chain masses M, time in "
                       "sqrt(L/g), speed sqrt(g L), acceleration g, force M g, energy M g L, curvature 1/L); "
                       "for SI add --length METERS --mass KG (and --g M_PER_S2, default 9.81)")

#: The kind of every variable and coordinate of a run Dataset (:mod:`snapping.schema`; a test
#: checks that none is missing), and of the ``chi``/``N`` coordinates of a combined sweep.
VARIABLE_KINDS: dict[str, str] = {
    # coordinates
    "t": _T, "t_snapshot": _T, "s_node": _L, "s_link": _L, "chi": _1, "N": _1,
    # per step
    "dt": _T, "v_max": _V, "a_max": _A, "sigma_max": _F, "kappa_max": _K, "s_kappa_max": _L, "s_a_max": _L,
    "s_v_max": _L, "v_end": _V, "a_end": _A, "pin_force_x": _F, "pin_force_y": _F, "energy": _E,
    "link_error": _1, "error_estimate": _1, "sigma_min": _F, "s_sigma_min": _L,
    # profiles
    "x": _L, "y": _L, "vx": _V, "vy": _V, "ax": _A, "ay": _A, "speed": _V, "accel": _A, "curvature": _K,
    "tension": _F,
    # the held end of a general run
    "pin_x": _L, "pin_y": _L, "pin_vx": _V, "pin_vy": _V, "pin_work": _E, "v_rel_max": _V, "kappa_max_interior": _K,
    # a run with a body (bending, drag)
    "bending_energy": _E, "dissipated": _E,
    # the extensible line (snapping.simulate.elastic)
    "s_sigma_max": _L, "elastic_energy": _E, "strain_max": _1, "n_slack": _1, "strain": _1,
    "axial_stiffness": _F,
    # the problem of a general run
    "link_length": _L, "node_mass": _M, "start_x": _L, "start_y": _L, "start_vx": _V, "start_vy": _V,
    "pin_table_t": _T, "pin_table_x": _L, "pin_table_y": _L,
    # a 3D run (snapping.spatial.dataset3d; snapping.schema.SPATIAL_VARS)
    "z": _L, "vz": _V, "az": _A, "start_z": _L, "start_vz": _V, "z_amp": _L, "vz_amp": _V,
    "angular_momentum_g": _H, "pin_table_z": _L,
}

#: The kind of every numeric input and result attribute of a run (the keys of its summary, and
#: the variables of a combined sweep). ``wall_time`` is not here: it is already in seconds.
VALUE_KINDS: dict[str, str] = {
    # inputs
    "chi": _1, "N": _1, "tol": _1, "dt0": _T, "t_end": _T, "stop_fraction": _1, "snapshot_times": _T,
    "record_thin": _1, "t_end_max": _T, "max_link_error": _1, "max_energy_drift": _E, "dt_min": _T,
    "max_rejections": _1, "tip_mass": _M, "gravity": _A, "t_pin_settled": _T, "kappa_peak_approach": _K,
    "t_kappa_peak_approach": _T, "n_rhs_approach": _1,
    # results
    "failure_node": _1, "t_snap_v": _T, "t_snap_a": _T, "t_snap_sigma": _T, "snap_reached": _1,
    "v_peak": _V, "a_peak": _A, "sigma_peak": _F, "kappa_peak": _K, "kappa_max_0": _K, "energy_drift": _E,
    "link_drift": _1, "link_drift_initial": _1, "length_drift": _1, "link_error_initial": _1, "t_final": _T,
    "energy_initial": _E, "dt_min_accepted": _T, "dt_max_accepted": _T, "n_steps": _1, "n_rejected": _1,
    "n_rhs": _1, "min_tension": _F, "t_min_tension": _T, "s_min_tension": _L, "t_compression": _T,
    "compression_tolerance": _1,
    # a 3D run (snapping.schema.SPATIAL_ATTRS)
    "dims": _1, "whirl": _W, "z_amp_snap": _L, "vz_amp_snap": _V, "z_amp_max": _L, "angular_momentum_drift": _H,
    "link_error_max": _1,
}

#: Suffixes of a value that has the kind of the value it is appended to (an error bar, a limit).
_SAME_KIND_SUFFIXES = ("_limit", "_error", "_err")

#: Variables of an unfinished run's checkpoint: its resumable state, not a result; :func:`to_si` leaves them out.
_CHECKPOINT_NAMES = frozenset(schema.CHECKPOINT_VARS) | frozenset(schema.CHECKPOINT_VARS_DOP853) | {
    schema.CHECKPOINT_KIND_VAR}

#: Global attributes :func:`to_si` adds (and :func:`from_si` takes away again).
SI_ATTRS = {
    "units_system": "'SI': the variables are in SI units (their 'units' attribute); the global attributes "
                    "(inputs and results) stay nondimensional, see snapping.units.summary_to_si",
    "si_length": "the length unit L (the chain's length) in m",
    "si_mass": "the mass unit M (the chain's mass) in kg",
    "si_g": "the acceleration unit g in m s-2",
    "nondimensional_title": "the title of the nondimensional Dataset",
}


def kind_of(name: str, kinds: dict | None = None) -> str | None:
    """The kind of the value ``name`` (:data:`VALUE_KINDS`, then :data:`VARIABLE_KINDS`, or
    ``kinds``), also with a suffix ``_limit``/``_error``/``_err``; None if unknown."""
    table = {**VARIABLE_KINDS, **VALUE_KINDS, **(kinds or {})}
    if name in table:
        return table[name]
    for suffix in _SAME_KIND_SUFFIXES:
        if name.endswith(suffix) and name[: -len(suffix)] in table:
            return table[name[: -len(suffix)]]
    return None


# ------------------------------------------------------------------------ Datasets
def to_si(ds, length=None, mass=None, g: float = G_STANDARD, *, scales: Scales | None = None):
    """A run Dataset (or a combined sweep) converted to SI, for a chain of ``length`` [m] and
    ``mass`` [kg] under ``g`` [m s-2] (or ``scales``).

    Every variable and coordinate keeps its name and dimensions; its values are
    multiplied by the SI value of its unit (:class:`Scales`) and its ``units``
    attribute becomes the CF string (``"m"``, ``"m s-1"``, ``"N"``, ...; ``"1"`` for
    dimensionless ones). Variables that already carry SI units (``wall_time`` in s)
    and those without a ``units`` attribute stay as they are; a checkpoint's state
    (an unfinished run's ``checkpoint_*``) is left out, and so is the integrity digest
    (it would no longer match). The global attributes (the run's inputs and
    results) stay nondimensional; ``units_system``, ``si_length``, ``si_mass`` and
    ``si_g`` are added. :func:`from_si` undoes it.

    Raises SnappingInputError for a variable with ``units = "1"`` whose kind is unknown.

    >>> from snapping.simulate import run
    >>> ds = run(0.5, 4, t_end=0.01, progress=False).dataset
    >>> si = to_si(ds, length=1.022, mass=0.0208)
    >>> si["v_max"].attrs["units"], si["tension"].attrs["units"]
    ('m s-1', 'N')
    >>> bool(si["t"][-1] == ds["t"][-1] * Scales(1.022, 0.0208).time)
    True
    """
    import xarray as xr

    if not isinstance(ds, xr.Dataset):
        raise V.SnappingInputError(f"ds={type(ds).__name__} is not an xarray.Dataset")
    V.run_dataset("ds", ds, sweep=True)  # (another program's Dataset: refused, not converted)
    if ds.attrs.get("units_system") == "SI":
        raise V.SnappingInputError("ds is already in SI (its attribute units_system is 'SI')")
    s = _scales(scales, length, mass, g)
    out = ds.drop_vars([n for n in ds.variables if n in _CHECKPOINT_NAMES])
    unknown = [str(n) for n in out.variables if n not in VARIABLE_KINDS and kind_of(str(n)) is None
               and out.variables[n].attrs.get("units") == "1" and out.variables[n].dtype.kind not in "OUS"]
    if unknown:
        raise V.SnappingInputError(f"ds has nondimensional variables of unknown kind {sorted(unknown)}: no SI unit "
                                   f"for them (snapping.units.VARIABLE_KINDS lists the known ones)")
    out = _convert(out, s, to_si=True)
    attrs = {k: v for k, v in ds.attrs.items() if k != schema.DIGEST_ATTR and k not in SI_ATTRS}
    attrs.update(units_system="SI", si_length=s.length, si_mass=s.mass, si_g=s.g,
                 nondimensional_title=str(ds.attrs.get("title", "")))
    attrs["title"] = (f"snapping: falling-chain run in SI (chain length {s.length:g} m, mass {s.mass:g} kg, "
                      f"g = {s.g:g} m s-2)")
    out.attrs = attrs
    return out


def from_si(ds):
    """The nondimensional Dataset of a Dataset from :func:`to_si` (the scales are its
    attributes ``si_length``, ``si_mass``, ``si_g``)."""
    import xarray as xr

    if not isinstance(ds, xr.Dataset) or ds.attrs.get("units_system") != "SI":
        raise V.SnappingInputError("ds is not a Dataset from snapping.units.to_si (no attribute units_system='SI')")
    try:
        s = Scales(ds.attrs["si_length"], ds.attrs["si_mass"], ds.attrs["si_g"])
    except KeyError as exc:
        raise V.SnappingInputError(f"ds has no attribute {exc.args[0]!r}: its SI scales are unknown") from None
    out = _convert(ds, s, to_si=False)
    attrs = {k: v for k, v in ds.attrs.items() if k not in SI_ATTRS}
    if ds.attrs.get("nondimensional_title"):
        attrs["title"] = ds.attrs["nondimensional_title"]
    out.attrs = attrs
    return out


def _convert(ds, s: Scales, *, to_si: bool):
    import numpy as np
    import xarray as xr

    data, coords = {}, {}
    for name, var in ds.variables.items():
        kind = kind_of(str(name))
        if kind is None:
            continue
        units = var.attrs.get("units")
        if units != ("1" if to_si else KIND_UNITS[kind]):
            continue  # already SI (wall_time in s), no units (an index), or not from to_si
        f = s.factor(kind)
        values = var.values
        if f != 1.0 and values.dtype.kind in "fiuc":
            values = np.asarray(values, dtype=float) * f if to_si else np.asarray(values, dtype=float) / f
        new = xr.Variable(var.dims, values, {**var.attrs, "units": KIND_UNITS[kind] if to_si else "1"},
                          encoding=dict(var.encoding))
        (coords if name in ds.coords else data)[name] = new
    return ds.assign(data).assign_coords(coords)


# --------------------------------------------------------------------------- values
def si_rows(values: dict, scales: Scales, kinds: dict | None = None) -> list[tuple[str, object, object, str]]:
    """``(name, nondimensional value, SI value, CF units)`` of each dimensional number of
    ``values`` whose kind is known (:func:`kind_of`, or ``kinds``); absent values (None)
    stay None, lists are converted element by element."""
    rows = []
    for k, v in values.items():
        kind = kind_of(str(k), kinds)
        if kind is None or kind == _1 or isinstance(v, (bool, str, dict)):
            continue
        if v is None:
            rows.append((k, None, None, KIND_UNITS[kind]))
        elif isinstance(v, (list, tuple)):
            rows.append((k, list(v), [None if x is None else scales.to_si(float(x), kind) for x in v],
                         KIND_UNITS[kind]))
        else:
            try:
                x = float(v)
            except (TypeError, ValueError):
                continue
            rows.append((k, v, scales.to_si(x, kind), KIND_UNITS[kind]))
    return rows


def values_to_si(values: dict, scales: Scales, kinds: dict | None = None) -> dict:
    """``{name: {"value": SI value, "units": CF string}}`` of the dimensional numbers of
    ``values`` (see :func:`si_rows`)."""
    return {k: {"value": si, "units": u} for k, _, si, u in si_rows(values, scales, kinds)}


def summary_to_si(summary: dict, length=None, mass=None, g: float = G_STANDARD, *,
                  scales: Scales | None = None) -> dict:
    """The SI part of a run's summary (:func:`snapping.simulate.summary`):
    ``{"scales": ..., "values": {name: {"value", "units"}}}`` with every dimensional input
    and result (peaks, snapping times, drifts, time steps, tip mass, gravity, ...) in SI.
    Dimensionless entries (chi, N, tol, counts) are not repeated.

    >>> si = summary_to_si({"chi": 0.25, "v_peak": 10.0, "t_snap_v": None}, 1.022, 0.0208)
    >>> si["values"]["v_peak"]["units"], round(si["values"]["v_peak"]["value"], 3)
    ('m s-1', 31.664)
    >>> si["values"]["t_snap_v"]["value"] is None    # absent stays absent
    True
    """
    if not isinstance(summary, dict):
        raise V.SnappingInputError(f"summary={type(summary).__name__} is not a dict (a run's summary)")
    s = _scales(scales, length, mass, g)
    return {"system": "SI", "scales": _scale_inputs(s), "values": values_to_si(summary, s)}


def _scale_inputs(s: Scales) -> dict:
    return {"length": {"value": s.length, "units": "m"}, "mass": {"value": s.mass, "units": "kg"},
            "g": {"value": s.g, "units": "m s-2"}, **{k: v for k, v in s.to_dict().items()
                                                       if k not in ("length", "mass", "acceleration")}}


#: the quantity of each peak variable of a fit (its peak value's kind)
_PEAK_KINDS = {"v_max": _V, "a_max": _A, "sigma_max": _F, "v": _V, "a": _A, "sigma": _F}


def fit_rows(fit: dict, scales: Scales) -> list[tuple[str, object, object, str]]:
    """:func:`si_rows` of a fit report (``RunFit.to_dict()`` of :func:`snapping.scaling.fit_run`),
    flat: the snapping time ``t_star`` (and ``t_star_err``), each peak's time and value
    (``t_peak_v_max``, ``peak_v_max``, ...), the scales ``delta_*`` (lengths), the run's and
    the whirling-rod peaks (``computed_v``, ``predicted_delta_c_sigma``, ...) and
    ``kappa_max_0``. The exponents are dimensionless; the prefactors A (whose units depend
    on the exponent) stay nondimensional. Entries missing from ``fit`` are left out."""
    flat, kinds = {}, {}

    def put(name, value, kind):
        if value is None or isinstance(value, (int, float)) and not isinstance(value, bool):
            flat[name] = None if value is None or not math.isfinite(value) else value
            kinds[name] = kind

    snap = fit.get("snap") or {}
    put("t_star", snap.get("t_star"), _T)
    put("t_star_err", snap.get("t_star_err"), _T)
    for var, p in (snap.get("peaks") or {}).items():
        if isinstance(p, dict):
            put(f"t_peak_{var}", p.get("t"), _T)
            if var in _PEAK_KINDS:
                put(f"peak_{var}", p.get("value"), _PEAK_KINDS[var])
    delta = fit.get("delta") or {}
    for k, d in (delta.get("deltas") or {}).items():
        put(k, d, _L)
    for q, v in (delta.get("computed") or {}).items():
        if q in _PEAK_KINDS:
            put(f"computed_{q}", v, _PEAK_KINDS[q])
    for k, pred in (delta.get("predicted") or {}).items():
        for q, v in (pred or {}).items():
            if q in _PEAK_KINDS:
                put(f"predicted_{k}_{q}", v, _PEAK_KINDS[q])
    put("kappa_max_0", fit.get("kappa_max_0"), _K)
    return si_rows(flat, scales, kinds)


def fit_to_si(fit: dict, scales: Scales) -> dict:
    """``{name: {"value": SI value, "units": CF string}}`` of the rows of :func:`fit_rows`."""
    return {k: {"value": si, "units": u} for k, _, si, u in fit_rows(fit, scales)}


# ------------------------------------------------------------------ a line's body in SI
#: air density at sea level and about 20 C, kg m-3 (the default of the SI drag options)
AIR_DENSITY = 1.2
#: cross-flow drag coefficient of a long circular cylinder at subcritical Reynolds numbers
#: (about 1e3 to 2e5: a fly line, a whip, a cable in a breeze), on the projected area d per length
CD_NORMAL = 1.2
#: skin-friction coefficient of the tangential (axial) drag, on the wetted area pi d per length
#: (an estimate: fly-line and mooring-line models use 0.01 or less)
CD_TANGENTIAL = 0.01

#: the body's SI inputs: (dimension as a pint unit, meaning)
BODY_SI_INPUTS = {
    "ei": ("N m**2", "bending stiffness EI"),
    "bending_damping": ("N m**2 s", "Kelvin-Voigt bending damping (moment per curvature rate)"),
    "curvature": ("1/m", "natural curvature"),
    "diameter": ("m", "diameter of the line (drag)"),
    "air_density": ("kg/m**3", "air density"),
    "cd_normal": ("", "cross-flow drag coefficient (on the projected area d per length)"),
    "cd_tangential": ("", "skin-friction coefficient (on the wetted area pi d per length)"),
    "tip_drag_area": ("m**2", "drag area C_d A of the tip body"),
    "wind": ("m/s", "uniform wind velocity (wx, wy), y downward"),
}


def _si_profile(name, v, factor, length):
    """A body profile given in SI (a number, one value per node, or a function of the
    arclength s in m from the held end) times ``factor``: the nondimensional profile
    (a function of the nondimensional s = s_SI / L)."""
    import numpy as np

    if callable(v):
        def f(s, _v=v):
            return factor * float(_v(s * length))

        f.__name__ = f"{getattr(v, '__name__', 'function')} (SI) x {factor:.6g}"
        if callable(getattr(v, "on_array", None)):  # a catalogue line's taper: every node in one call
            def on_array(s, _v=v):
                return [factor * float(x) for x in _v.on_array(np.asarray(s, dtype=float) * length)]

            f.on_array = on_array
        return f
    if np.ndim(v) == 0:
        x = V.real(name, v)
        if not (math.isfinite(x) and (x >= 0.0 or name == "curvature")):
            raise V.SnappingInputError(f"{name}={x!r} is out of range: must be finite and >= 0 "
                                       f"({BODY_SI_INPUTS[name][0] or 'dimensionless'})")
        return x * factor
    a = np.asarray(V.float_array(name, v), dtype=float)
    if a.ndim != 1 or a.size == 0 or not np.all(np.isfinite(a)) or (name != "curvature" and np.any(a < 0.0)):
        raise V.SnappingInputError(f"{name} must be one finite value >= 0 per node (a 1-D array); got shape "
                                   f"{a.shape}")
    return a * factor


def body_numbers(length, mass, g: float = G_STANDARD, *, ei=0.0, bending_damping=0.0, curvature=0.0,
                 diameter=None, air_density: float | None = None, cd_normal: float | None = None,
                 cd_tangential: float | None = None, tip_drag_area: float = 0.0, wind=None) -> dict:
    """The nondimensional numbers of a line's body (the keywords of
    :class:`snapping.simulate.Body`) from its SI description, for a chain of ``length`` L [m]
    and ``mass`` M [kg] (mean mass per length ``lambda = M/L``) under ``g`` [m s-2].

    The conversions (each checked dimensionless by pint; the force per length unit is
    ``lambda g``, the speed unit ``sqrt(g L)``):

    * bending number ``beta = EI / (lambda g L^3)`` (``ei`` in N m^2);
    * bending damping ``eta / (lambda g L^3 sqrt(L/g))`` (``bending_damping`` in N m^2 s);
    * natural curvature ``kappa0 L`` (``curvature`` in 1/m);
    * quadratic normal drag: the force per length ``0.5 rho C_n d |v_n| v_n`` (cylinder
      cross-flow, on the projected area d per length; Morison's drag term, as MoorDyn and
      OrcaFlex write it) gives ``drag_normal = 0.5 rho C_n d L / lambda``;
    * quadratic tangential drag: ``0.5 rho C_t (pi d) |v_t| v_t`` (skin friction on the wetted
      area pi d per length, MoorDyn's convention for its axial drag) gives
      ``drag_tangential = 0.5 rho C_t pi d L / lambda``;
    * the tip body: ``0.5 rho (C_d A) |v| v`` gives ``tip_drag = 0.5 rho C_d A L / M``;
    * wind ``w / sqrt(g L)``.

    ``diameter`` (m) turns on the line's drag with ``cd_normal`` (default :data:`CD_NORMAL`)
    and ``cd_tangential`` (default :data:`CD_TANGENTIAL`); ``air_density`` defaults to
    :data:`AIR_DENSITY`. ``ei``, ``bending_damping``, ``curvature`` and ``diameter`` may be
    numbers, one value per node (index 0 the free end) or functions of the arclength s in m
    from the held end (a taper).

    >>> n = body_numbers(2.0, 0.02, ei=1e-3, diameter=1e-3)   # 2 m, 10 g/m, EI 1e-3 N m^2, 1 mm
    >>> round(n["bending"], 8), round(n["drag_normal"], 6), round(n["drag_tangential"], 8)
    (0.00127421, 0.144, 0.00376991)
    """
    ureg = registry()
    s = Scales(length, mass, g)
    L, M, gg = s.length, s.mass, s.g
    lam = M / L
    Q = ureg.Quantity
    lam_q, L_q, g_q, M_q = Q(lam, "kg/m"), Q(L, "m"), Q(gg, "m/s**2"), Q(M, "kg")

    def dimensionless(q) -> float:  # pint: a wrong formula raises DimensionalityError here
        return float(q.to("dimensionless").magnitude)

    out: dict = {}
    f_bend = dimensionless(Q(1.0, "N m**2") / (lam_q * g_q * L_q ** 3))
    out["bending"] = _si_profile("ei", ei, f_bend, L)
    f_eta = dimensionless(Q(1.0, "N m**2 s") / (lam_q * g_q * L_q ** 3 * (L_q / g_q) ** 0.5))
    out["damping"] = _si_profile("bending_damping", bending_damping, f_eta, L)
    out["curvature"] = _si_profile("curvature", curvature, dimensionless(Q(1.0, "1/m") * L_q), L)
    tip_area = 0.0
    if tip_drag_area is not None:
        tip_area = V.real("tip_drag_area", tip_drag_area)
        if not (math.isfinite(tip_area) and tip_area >= 0.0):
            raise V.SnappingInputError(f"tip_drag_area={tip_area!r} is out of range: must be finite and >= 0 (m^2)")
    drag_given = diameter is not None or tip_area > 0.0
    if not drag_given and (cd_normal is not None or cd_tangential is not None):
        raise V.SnappingInputError("cd_normal/cd_tangential need diameter (m): the drag per length is "
                                   "0.5 rho C d |v| v")
    if drag_given or air_density is not None:
        rho = AIR_DENSITY if air_density is None else V.real("air_density", air_density)
        if not (math.isfinite(rho) and 0.0 <= rho <= 1e5):
            raise V.SnappingInputError(f"air_density={rho!r} is out of range: must be finite, in [0, 1e5] (kg/m^3)")
    if diameter is not None:
        cn = CD_NORMAL if cd_normal is None else V.real("cd_normal", cd_normal)
        ct = CD_TANGENTIAL if cd_tangential is None else V.real("cd_tangential", cd_tangential)
        for name, c in (("cd_normal", cn), ("cd_tangential", ct)):
            if not (math.isfinite(c) and 0.0 <= c <= 1e3):
                raise V.SnappingInputError(f"{name}={c!r} is out of range: a drag coefficient, finite, in [0, 1000]")
        rho_q = Q(rho, "kg/m**3")
        f_n = dimensionless(0.5 * rho_q * cn * Q(1.0, "m") * L_q / lam_q)
        f_t = dimensionless(0.5 * rho_q * ct * math.pi * Q(1.0, "m") * L_q / lam_q)
        out["drag_normal"] = _si_profile("diameter", diameter, f_n, L)
        out["drag_tangential"] = _si_profile("diameter", diameter, f_t, L)
    if tip_area > 0.0:
        out["tip_drag"] = dimensionless(0.5 * Q(rho, "kg/m**3") * Q(tip_area, "m**2") * L_q / M_q)
    if wind is not None:
        import numpy as np

        try:
            w = np.asarray(wind, dtype=float)
        except (TypeError, ValueError):
            w = np.zeros(0)
        if w.shape != (2,) or not np.all(np.isfinite(w)):
            raise V.SnappingInputError(f"wind={wind!r} must be two finite numbers (wx, wy) in m/s")
        f_w = dimensionless(Q(1.0, "m/s") / (g_q * L_q) ** 0.5)
        out["wind"] = (float(w[0]) * f_w, float(w[1]) * f_w)
    return out
