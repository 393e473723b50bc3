"""The run Dataset: the one place where its names are defined.

A run of :mod:`snapping.simulate` is one :class:`xarray.Dataset`, written to disk
as netCDF4. Its variable, dimension and attribute names are a public contract
between ``simulate``, ``scaling``, files on users' disks and scripts: they are
listed here, with units and CF ``long_name``, and nowhere else. Code that writes
or reads a run imports these tables instead of spelling names itself.

Everything is nondimensional (length l = 1, g = 1, rho = 1; velocity sqrt(g l),
time sqrt(l/g), force rho g l), hence ``units = "1"``.

Conventions (the paper's appendix): nodes are numbered from the free end
(node 1, index 0 here) to the pinned node N+1 (index N). The arclength
coordinate ``s`` is the paper's: s = 0 at the pin, s = 1 at the free end, so
node k sits at s = (N + 1 - k)/N. Link k joins nodes k and k+1 and carries the
tension ``sigma_k``. Gravity points along +e2 (``y`` grows downward).

Dimensions
----------
``step``      accepted time steps that were recorded (coordinate ``t``)
``snapshot``  full-profile snapshots (coordinate ``t_snapshot``)
``node``      the N+1 nodes (coordinate ``s_node``)
``link``      the N links (coordinate ``s_link``, the link midpoints)

Example
-------
>>> from snapping import schema
>>> schema.STEP_VARS["v_max"]["long_name"]
'maximum speed over the chain'
"""

from __future__ import annotations

STEP_DIM = "step"
SNAPSHOT_DIM = "snapshot"
NODE_DIM = "node"
LINK_DIM = "link"


def _v(long_name: str, units: str = "1") -> dict[str, str]:
    return {"long_name": long_name, "units": units}


#: Coordinates.
COORDS: dict[str, dict[str, str]] = {
    "t": _v("time"),
    "t_snapshot": _v("time of the profile snapshot (euler-richardson: the first accepted step at or after a "
                     "requested time, so later by less than one step; dop853: the requested time exactly, "
                     "from the dense output)"),
    "s_node": _v("arclength of the node from the pinned end"),
    "s_link": _v("arclength of the link midpoint from the pinned end"),
    "snapshot_kind": _v("why the snapshot was taken: initial, requested, speed_level, peak, after_peak or final"),
}

#: Per accepted step (dimension ``step``), in the order they are recorded.
STEP_VARS: dict[str, dict[str, str]] = {
    "dt": _v("accepted time step"),
    "v_max": _v("maximum speed over the chain"),
    "a_max": _v("maximum acceleration magnitude over the chain"),
    "sigma_max": _v("maximum link tension over the chain"),
    "kappa_max": _v("maximum absolute curvature over the chain"),
    "s_kappa_max": _v("arclength of the curvature maximum"),
    "s_a_max": _v("arclength of the acceleration maximum"),
    "s_v_max": _v("arclength of the speed maximum"),
    "v_end": _v("speed of the free end"),
    "a_end": _v("acceleration magnitude of the free end"),
    "pin_force_x": _v("horizontal (e1) component of the force of the chain on the pin"),
    "pin_force_y": _v("vertical (e2, downward) component of the force of the chain on the pin"),
    "energy": _v("total mechanical energy (kinetic + potential, zero for the chain hanging at rest)"),
    "link_error": _v("largest relative link-length error max_k |N |r_k+1 - r_k| - 1|"),
    "error_estimate": _v("stepper error estimate of the accepted step"),
    "sigma_min": _v("minimum link tension over the chain (negative: the rigid links carry compression, where a "
                    "real line would go slack)"),
    "s_sigma_min": _v("arclength of the midpoint of the link of minimum tension"),
}

#: Per snapshot profiles.
NODE_PROFILE_VARS: dict[str, dict[str, str]] = {
    "x": _v("node position, e1 component"),
    "y": _v("node position, e2 component (downward)"),
    "vx": _v("node velocity, e1 component"),
    "vy": _v("node velocity, e2 component"),
    "ax": _v("node acceleration, e1 component"),
    "ay": _v("node acceleration, e2 component"),
    "speed": _v("node speed"),
    "accel": _v("node acceleration magnitude"),
    "curvature": _v("discrete curvature N (theta_k+1 - theta_k) at the node (NaN at the two ends)"),
}
LINK_PROFILE_VARS: dict[str, dict[str, str]] = {
    "tension": _v("link tension"),
}

#: Per accepted step, runs of a general problem only (:mod:`snapping.simulate.problem`).
PIN_STEP_VARS: dict[str, dict[str, str]] = {
    "pin_x": _v("position of the held end, e1 component"),
    "pin_y": _v("position of the held end, e2 component (downward)"),
    "pin_vx": _v("velocity of the held end, e1 component"),
    "pin_vy": _v("velocity of the held end, e2 component"),
    "pin_work": _v("work done on the chain by the held end since t = 0 (energy - pin_work is conserved)"),
    "v_rel_max": _v("maximum node speed relative to the held end, max_j |v_j - v_pin| (what the stop rule judges)"),
    "kappa_max_interior": _v("maximum absolute curvature over the joints at least KAPPA_TIP_JOINTS (8) links from the "
                             "free end (kappa_max without the free end's node-index boundary layer: "
                             "snapping.simulate.general.KAPPA_TIP_JOINTS)"),
}

#: Per accepted step, runs of a problem with a body only (:class:`snapping.simulate.Body`: bending
#: stiffness, damping, drag, a clamp); their ``energy`` is kinetic + gravity + bending, and
#: ``energy - pin_work + dissipated`` is conserved.
BODY_STEP_VARS: dict[str, dict[str, str]] = {
    "bending_energy": _v("bending energy of the chain (sum over nodes of B (turning angle - natural)^2 / (2 l))"),
    "dissipated": _v("energy dissipated by drag and bending damping since t = 0 (the wind's work counts "
                     "negative; energy - pin_work + dissipated is conserved)"),
}

#: Dimension of the pin-motion table of a general run (``pin_motion = 'table'``).
PIN_TABLE_DIM = "pin_sample"

#: Variables describing the problem of a general run (the paper's runs have none: N equal
#: links of length 1/N and node masses 1/N).
PROBLEM_VARS: dict[str, dict[str, str]] = {
    "link_length": _v("length of the link"),
    "node_mass": _v("mass of the node (tip mass included; 0 at the held end)"),
    "start_x": _v("node position at t = 0, e1 component (the problem's start, as given)"),
    "start_y": _v("node position at t = 0, e2 component (downward)"),
    "start_vx": _v("node velocity at t = 0, e1 component"),
    "start_vy": _v("node velocity at t = 0, e2 component"),
    "pin_table_t": _v("times of the samples of the held end's prescribed motion"),
    "pin_table_x": _v("e1 position of the held end at the sample times (cubic spline between)"),
    "pin_table_y": _v("e2 position of the held end at the sample times (cubic spline between)"),
}

#: Global attributes of a general run, besides INPUT_ATTRS (``initial = 'problem'``).
PROBLEM_ATTRS: dict[str, str] = {
    "problem": "JSON description of the chain, the start shape, the held end's motion and gravity",
    "tip_mass": "point mass at the free end (ratio to the chain's mass), included in node_mass",
    "gravity": "gravity along +e2 (1: the nondimensional g; 0: none)",
    "pin_motion": "motion of the held end: 'fixed', 'pull', 'flick' or 'table'",
    "start": "start shape: 'catenary', 'supports', 'curve' or 'nodes'",
    "kappa_peak_approach": ("the snap's curvature peak on the approach: the largest kappa_max_interior over the steps "
                            "at which v_max is at its running maximum (up to the speed peak), located on the dense "
                            "output (the elastic line: as its v/a/sigma peaks, its kept steps sampled and integrated "
                            "again); NaN for a run resumed from a checkpoint written before it existed "
                            "(docs/guide/regimes.md, 'The curvature peak')"),
    "t_kappa_peak_approach": "time of kappa_peak_approach",
    "n_rhs_approach": ("of n_rhs, the right-hand-side evaluations that located kappa_peak_approach (n_rhs less them: "
                       "the integration's own cost, as before that peak existed; what a regime study's escalation "
                       "cap judges); NaN for a run resumed from a checkpoint written before it existed"),
    "t_pin_settled": ("time from which the held end's acceleration no longer changes (NaN: a fixed held end); "
                      "with a moving held end the stop rule and snap_reached judge v_rel_max (the speed relative "
                      "to the held end) from then on, after it has risen above its value then"),
    "start_rest": ("the shape a line with a body was released from, held at both ends at rest before: "
                   "'equilibrium' (the discrete static equilibrium, with bending the heavy elastica, to a "
                   "relative residual below 1e-12: snapping.simulate.equilibrium), 'catenary' (not in bending equilibrium), or 'as given' "
                   "(a curve or nodes); runs of a problem with a body only"),
    "body": ("JSON description of the body (bending, curvature, damping, drag, wind, tip_drag, clamp; "
             "nondimensional), runs of a problem with a body only"),
}

#: Global attributes of runs of the stiff method, or of a problem with bending run with
#: ``method='fast'`` (which then chooses between dop853 and rodas4:
#: :mod:`snapping.simulate.stiffness`); absent elsewhere.
METHOD_ATTRS: dict[str, str] = {
    "method_choice": ("why method='fast' ran this method ('method' names it): the shortest bending wave's "
                      "frequency and damping ratio, and the explicit method's estimated steps"),
    "n_jacobians": "Jacobians of the stiff method (rodas4; each ten forward-mode derivatives of the rows)",
    "n_factorizations": "banded LU factorisations of the stiff method's stage matrix (rodas4)",
}

#: Global attributes: inputs. A run file alone must be enough to rerun it.
INPUT_ATTRS: dict[str, str] = {
    "chi": "initial end-to-end separation (fraction of the length), in (0, 1)",
    "N": "number of links",
    "method": "time-stepping method",
    "tol": "stepper tolerance",
    "dt0": "initial time step",
    "t_end": "end time (0 = stop automatically after the snap)",
    "stop_fraction": "automatic stop once the maximum speed has fallen to this fraction of its peak",
    "snapshot_times": "requested snapshot times (besides the automatic ones)",
    "record_thin": "relative change below which a step is not recorded (0 = record every step)",
    "chords": "initial node placement on the catenary: 'arclength' (the paper's) or 'exact' (chords 1/N)",
    "initial": ("initial condition: 'catenary' (from chi), 'snapshot' (the snapshot of kind 'initial' holds it) "
                "or 'problem' (a general problem: PROBLEM_ATTRS, PROBLEM_VARS and the 'initial' snapshot)"),
    "t_end_max": "hard end time of an automatic (stop after the snap) run",
    "max_link_error": "relative link-length error at which the run fails",
    "max_energy_drift": "energy drift |E(t) - E(0)| at which the run fails (0 = no bound)",
    "dt_min": "time-step floor: the run fails when the adaptive step falls below it",
    "max_rejections": "consecutive rejected steps at which the run fails",
}

#: Inputs of one method, written only when not their default (a default run's file is unchanged).
OPTIONAL_INPUT_ATTRS: dict[str, str] = {
    "drag_jacobian": ("the stiff method's stage solves: 'banded' (the default, not written; drag left out of the "
                      "Jacobian) or 'correct' (each stage corrected once for it)"),
}

#: Inputs added after the first files were written, with the value that reproduces an older file.
INPUT_DEFAULTS: dict[str, float] = {"max_energy_drift": 0.0, "dt_min": 1e-14, "max_rejections": 100}

#: Global attributes: results.
RESULT_ATTRS: dict[str, str] = {
    "status": ("'completed', 'failed', 'interrupted' (stopped by a signal, resumable) or 'checkpoint' "
               "(saved while running, resumable)"),
    "stop_reason": "why the run stopped",
    "failure": ("kind of numerical failure: '' (none), 'non_finite', 'step_size', 'link_drift', "
                "'energy_drift' or 'rejections'"),
    "failure_node": "index along 'node' of the worst node at a failure (-1: none)",
    "t_snap_v": "snapping time from the peak of the maximum speed (NaN: the run did not reach the snap)",
    "t_snap_a": ("snapping time from the peak of the maximum acceleration (NaN: the run did not reach the snap, "
                 "or this peak is at the run's last step)"),
    "t_snap_sigma": ("snapping time from the peak of the maximum tension (NaN: the run did not reach the snap, "
                     "or this peak is at the run's last step)"),
    "snap_reached": ("1 if the run reached the snap: at some recorded step v_max fell below stop_fraction of its "
                     "running peak (with a moving held end: v_rel_max, from t_pin_settled on; the rule that stops an "
                     "automatic run, applied to a run with t_end too); 0 if "
                     "not: then the t_snap_* are NaN and the *_peak are maxima over the run, not snap peaks"),
    "snap_note": "'' if snap_reached, else one line saying why there is no snapping time",
    "v_peak": "peak of the maximum speed (if snap_reached is 0: its maximum over the run)",
    "a_peak": "peak of the maximum acceleration (if snap_reached is 0: its maximum over the run)",
    "sigma_peak": "peak of the maximum tension (if snap_reached is 0: its maximum over the run)",
    "kappa_peak": "peak of the maximum curvature (if snap_reached is 0: its maximum over the run)",
    "kappa_max_0": "maximum curvature at t = 0",
    "min_tension": ("smallest link tension over the recorded steps (sigma_min; negative: the rigid links carried "
                    "compression, where a real line would go slack)"),
    "t_min_tension": "time of min_tension",
    "s_min_tension": "arclength of the midpoint of the link of min_tension",
    "t_compression": ("first recorded time at which the rigid links carried compression: sigma_min < "
                      "-compression_tolerance max(1, sigma_max) (NaN: never; the history from then on "
                      "is not what a real, slack-capable line does; snapping.simulate.compression)"),
    "compression_tolerance": ("relative round-off bound of the link tensions, 8 (2N + 1)^2 eps (the condition "
                              "number bound of the tension solve times a safety factor)"),
    "energy_drift": "max |E(t) - E(0)| over the run",
    "link_drift": "max relative link-length error against 1/N over the run",
    "link_drift_initial": "max relative link-length change against the initial chords",
    "length_drift": "max relative change of the total length against the initial chords",
    "link_error_initial": "relative error of the initial chords against 1/N (sampling the catenary)",
    "t_final": "time at which the run stopped",
    "energy_initial": "total energy at t = 0",
    "dt_min_accepted": "smallest accepted time step",
    "dt_max_accepted": "largest accepted time step",
    "n_steps": "accepted steps",
    "n_rejected": "rejected steps",
    "n_rhs": "right-hand-side evaluations",
    "wall_time": "wall-clock time of the run in seconds",
    "snapping_version": "version of the snapping package that wrote the file",
}

#: Units of the numeric result attributes where they are not nondimensional ("1"), for
#: tools that turn them into variables (:func:`snapping.sweep.combine`).
RESULT_UNITS: dict[str, str] = {"wall_time": "s"}


def result_units(name: str) -> str:
    """Units of the result attribute ``name``: ``"s"`` for wall-clock times, else ``"1"``."""
    return RESULT_UNITS.get(name, "1")


#: Per accepted step, runs of the extensible line only (:mod:`snapping.simulate.elastic`); their
#: ``energy`` is kinetic + gravity + elastic, and ``energy - pin_work + dissipated`` is conserved.
ELASTIC_STEP_VARS: dict[str, dict[str, str]] = {
    "s_sigma_max": _v("arclength (at rest) of the midpoint of the link of largest tension"),
    "elastic_energy": _v("elastic energy of the links (sum over taut links of h_j times the integral of the "
                         "tension over the strain)"),
    "strain_max": _v("largest link strain l_j/h_j - 1 (negative: every link shorter than at rest)"),
    "n_slack": _v("number of slack links (tension 0)"),
}
#: Per snapshot (and per link) of the extensible line.
ELASTIC_LINK_VARS: dict[str, dict[str, str]] = {
    "strain": _v("link strain l_j/h_j - 1 (at most 0: slack)"),
    "axial_stiffness": _v("axial stiffness EA of the link (the table's initial slope for a tension-strain table)"),
}

#: Result attributes of the extensible line's runs (numbers; a combined sweep's variables over (chi, N)).
ELASTIC_RESULT_ATTRS: dict[str, str] = {
    "strain_peak": "largest link strain over the recorded steps",
    "t_first_slack": "time of the first recorded step with a slack link (NaN: none)",
    "a_peak_snap": ("peak of the maximum acceleration over the snap: from the start until v_max, after its peak, "
                    "falls to 0.9 of it (t_snap_edge); a_peak itself where it lies in that window, else the "
                    "largest of the recorded steps before the edge and the value at the edge "
                    "(snapping.simulate.snap_window, snap_edge)"),
    "sigma_peak_snap": ("peak of the maximum tension over the snap (as a_peak_snap): excludes the slack fold and "
                        "recoil after the snap, which the run's sigma_peak may hold"),
    "t_snap_end": "end of the snap's window: the first recorded step after the speed peak with v_max < 0.9 v_peak",
    "t_snap_edge": ("the snap window's exact end: the time after the speed peak at which v_max falls to 0.9 v_peak, "
                    "on the states integrated from its recorded step's start (NaN: v_max never falls that far; "
                    "snapping.simulate.snap_edge)"),
    "sigma_peak_taut": ("peak of the maximum tension over the taut snap: from the start until the line first goes "
                        "slack after the speed peak, never before t_snap_end (t_taut_end); sigma_peak itself where it "
                        "lies in that window, else the largest recorded step (snapping.simulate.snap_window)"),
    "t_taut_end": ("end of the taut snap's window: the first recorded step at or after the speed peak with a slack "
                   "link (the run's last step if none), at least t_snap_end"),
    "n_slack_steps": "number of recorded steps with a slack link",
    "dissipated_total": "energy dissipated by the axial damping over the run",
    "wave_speed": "smallest longitudinal wave speed sqrt(EA/lambda) of the links",
    "stop_speed_floor": ("running peak of v_max above which the stop rule judges the snap, 2 sqrt(2 U0 / m_min) / "
                         "(1 - stop_fraction) (U0 the elastic energy at t = 0, m_min the smallest node mass)"),
    "t_stop_armed": "time from which the stop rule judged the snap (NaN: never; then no snap is reported)",
    "peak_ringing": ("the largest tension's oscillation about its level before the snap, over windows of two "
                     "periods 8 L/c of the slowest longitudinal mode (snapping.simulate.elastic_checks; NaN: "
                     "not judged)"),
    "peaks_resolved": ("1 if the peak guard finds a_peak and sigma_peak the line's, 0 if they are the "
                       "integrator's ringing (then status 'failed'; peak_note says why)"),
    "peak_note": "the peak guard's rules broken (ringing, slack, energy; empty when resolved)",
}

ALL_VARS = {**STEP_VARS, **NODE_PROFILE_VARS, **LINK_PROFILE_VARS, **PIN_STEP_VARS, **PROBLEM_VARS,
            **BODY_STEP_VARS, **ELASTIC_STEP_VARS, **ELASTIC_LINK_VARS}

# ---------------------------------------------------------------- checkpoints
#: Status values of a run file that :func:`snapping.simulate.resume` continues.
RESUMABLE_STATUS = ("checkpoint", "interrupted")

#: Dimensions of the checkpoint variables (besides ``node`` and ``link``).
CHECKPOINT_DIMS = {
    "checkpoint_buffer": "the two state buffers of the compiled loop",
    "checkpoint_row": "rows x, y, vx, vy, ax, ay, sigma of a kernel state",
    "checkpoint_ctl": "entries of the compiled loop's control array",
    "checkpoint_peak": "the tracked peaks v, a, sigma, kappa",
    "checkpoint_peak_col": "columns of a tracked peak (previous, -1, peak, +1 samples and a flag)",
    "checkpoint_meas": "entries of the per-step measurement array",
    "checkpoint_snapshot": "snapshots taken so far",
    "checkpoint_pending": "requested snapshot times still to come (NaN padded)",
    "checkpoint_pending_after": "after-peak snapshot fractions still to come (NaN padded)",
    "checkpoint_slot": "the two step slots of the DOP853 loop (last and previous accepted step)",
    "checkpoint_stage": "the 16 Runge-Kutta stages of a DOP853 step (12, and 4 of the dense output)",
    "checkpoint_dense": "the 7 coefficient vectors of a DOP853 step's dense output",
    "checkpoint_angle": "the 2N angle-form unknowns (link angles, then angular velocities)",
    "checkpoint_rodas_stage": "f at a RODAS4 step's start, its 6 stage increments U_1 .. U_6, f at its end",
    "checkpoint_jacobian_var": "the variables theta, omega, a, T of the rows' banded derivatives",
    "checkpoint_jacobian_colour": "the 5 colours (links 5 apart) of the rows' banded derivatives",
    "checkpoint_jacobian_row": "the 2N rows (angle and tension row of each link) of the banded derivatives",
    "checkpoint_count": "the RODAS4 counters: Jacobians, factorisations, extra evaluations, singular matrices",
}

#: The complete state of an unfinished run, stored in the run file itself next to the
#: record so far (the step variables) while ``status`` is one of RESUMABLE_STATUS.
#: Removed once the run completes or fails. Together with the step variables and the
#: input attributes they continue the run to the same Dataset, bit for bit.
CHECKPOINT_VARS: dict[str, dict[str, str]] = {
    "checkpoint_S": _v("current and next chain state of the compiled loop"),
    "checkpoint_peak_state": _v("state at the running peak of v_max"),
    "checkpoint_ctl": _v("control array of the compiled loop (t, dt, counters, drifts, targets)"),
    "checkpoint_pk": _v("running peak trackers of v_max, a_max, sigma_max, kappa_max (a general chain: + kappa_max_interior on the approach)"),
    "checkpoint_meas": _v("measurements of the last accepted step"),
    "checkpoint_meas0": _v("measurements of the initial state"),
    "checkpoint_rinv0": _v("1 / (initial chord length)^2 per link"),
    "checkpoint_snapshot_state": _v("full kernel states of the snapshots so far"),
    "checkpoint_snapshot_t": _v("times of the snapshots so far"),
    "checkpoint_requested": _v("requested snapshot times still to come (NaN padded)"),
    "checkpoint_after_fractions": _v("after-peak snapshot fractions still to come (NaN padded)"),
}
#: The complete state of an unfinished angle-form run (``method = 'dop853'``): the same
#: role as CHECKPOINT_VARS, with the step slots of the DOP853 loop instead of
#: ``checkpoint_S`` (the other names are shared and mean the same, in the DOP853 layout).
CHECKPOINT_VARS_DOP853: dict[str, dict[str, str]] = {
    "checkpoint_Y0": _v("start states (angles, angular velocities) of the two stored steps"),
    "checkpoint_Y1": _v("end states (angles, angular velocities) of the two stored steps"),
    "checkpoint_stages": _v("Runge-Kutta stages of the two stored steps (stage 12: derivative at the end, FSAL)"),
    "checkpoint_dense": _v("dense-output coefficients of the two stored steps"),
    "checkpoint_step_t": _v("start times of the two stored steps"),
    "checkpoint_step_h": _v("sizes of the two stored steps"),
    "checkpoint_dense_ok": _v("1 where the dense output of a stored step has been built (2: built while locating "
                              "kappa_peak_approach, simulate.dense_peaks), else 0"),
    "checkpoint_Z": _v("positions, velocities, accelerations and tensions of the current state"),
    "checkpoint_peak_t": _v("time of the located peak of v_max (NaN: none yet)"),
    **{k: CHECKPOINT_VARS[k] for k in ("checkpoint_peak_state", "checkpoint_ctl", "checkpoint_pk", "checkpoint_meas",
                                       "checkpoint_meas0", "checkpoint_rinv0", "checkpoint_snapshot_state",
                                       "checkpoint_snapshot_t", "checkpoint_requested",
                                       "checkpoint_after_fractions")},
}
#: The complete state of an unfinished run of the stiff method (``method = 'rodas4'``): the
#: step slots of the RODAS4 loop and the Jacobian at the current state (the shared names
#: mean the same as in CHECKPOINT_VARS_DOP853).
CHECKPOINT_VARS_RODAS4: dict[str, dict[str, str]] = {
    "checkpoint_Y0": CHECKPOINT_VARS_DOP853["checkpoint_Y0"],
    "checkpoint_Y1": CHECKPOINT_VARS_DOP853["checkpoint_Y1"],
    "checkpoint_stages": _v("f at the start, the stage increments U_1 .. U_6 and f at the end of the two stored "
                            "RODAS4 steps (they give the continuous extension)"),
    "checkpoint_step_t": CHECKPOINT_VARS_DOP853["checkpoint_step_t"],
    "checkpoint_step_h": CHECKPOINT_VARS_DOP853["checkpoint_step_h"],
    "checkpoint_jacobian": _v("coloured banded derivatives of the rows at the current state (the next step's "
                              "Jacobian)"),
    "checkpoint_counts": _v("Jacobians, banded factorisations, extra evaluations and singular stage matrices so far"),
    "checkpoint_Z": CHECKPOINT_VARS_DOP853["checkpoint_Z"],
    "checkpoint_peak_t": CHECKPOINT_VARS_DOP853["checkpoint_peak_t"],
    **{k: CHECKPOINT_VARS[k] for k in ("checkpoint_peak_state", "checkpoint_ctl", "checkpoint_pk", "checkpoint_meas",
                                       "checkpoint_meas0", "checkpoint_rinv0", "checkpoint_snapshot_state",
                                       "checkpoint_snapshot_t", "checkpoint_requested",
                                       "checkpoint_after_fractions")},
}
#: The state of an unfinished extensible-line run (``snapping.simulate.elastic.solve``,
#: methods ``rodas4`` and ``rodas4-links``; :mod:`snapping.simulate.elastic_checkpoint`):
#: the arrays of ``RodasRun.state()`` (``ckpt_`` + their names; dimensions ``ckpt_<name>_<axis>``)
#: and the snapshots so far, next to the record so far. Continued by
#: ``solve(..., resume=path)`` to the same numbers, bit for bit.
ELASTIC_CHECKPOINT_VARS: dict[str, dict[str, str]] = {
    "ckpt_stepper_y": _v("node state of the RODAS4 stepper (positions, velocities, held end's work, dissipation)"),
    "ckpt_stepper_zl": _v("link state of the rodas4-links stepper (lengths, angles, their rates, W, D)"),
    "ckpt_stepper_yn": _v("node state of the rodas4-links stepper"),
    "ckpt_stepper_ctl": _v("the stepper's controls and counts (t, step size, last error, evaluations)"),
    "ckpt_stepper_St0": _v("f at the current state (the next step's first stage)"),
    "ckpt_stepper_B": _v("banded Jacobian at the current state"),
    "ckpt_stepper_gW": _v("gradient of the held end's work rate at the current state"),
    "ckpt_stepper_gD": _v("gradient of the dissipation rate at the current state"),
    "ckpt_stepper_dsp": _v("the Jacobian's dependence on the held end at the current state"),
    "ckpt_PY0": _v("start states of the step slots"),
    "ckpt_PY1": _v("end states of the step slots"),
    "ckpt_PC": _v("continuous-extension coefficients of the step slots"),
    "ckpt_PT": _v("start and end times of the step slots"),
    "ckpt_PN0": _v("node start states of the step slots (rodas4-links)"),
    "ckpt_ref": _v("users of each step slot"),
    "ckpt_keep": _v("step slots kept around each peak (v, a, sigma)"),
    "ckpt_nkeep": _v("number of kept step slots per peak"),
    "ckpt_after": _v("1 where a peak keeps the next step"),
    "ckpt_best": _v("running peaks of v_max, a_max, sigma_max and their times"),
    "ckpt_sctl": _v("the run's controls (stop rule, energy error, first slack, running peak)"),
    "ckpt_peak_z": _v("state at the running peak of v_max"),
    "ckpt_snap_t": _v("times of the snapshots so far"),
    "ckpt_snap_z": _v("states of the snapshots so far"),
    "ckpt_snap_kind": _v("kinds of the snapshots so far"),
}
#: Global attributes of an extensible-line checkpoint (besides the run's inputs).
ELASTIC_CHECKPOINT_ATTRS: dict[str, str] = {
    "checkpoint_version": "layout version of the ckpt_ variables",
    "checkpoint_wall_time": "wall-clock seconds spent on the run before this checkpoint",
    "checkpoint_n_restep": "right-hand-side evaluations of the snapshots' integrations so far",
    "checkpoint_inputs": "JSON of every input of solve that the run's numbers depend on (resume checks them)",
}
#: String variable (no units) holding the kinds of the snapshots so far.
CHECKPOINT_KIND_VAR = "checkpoint_snapshot_kind"

#: Global attributes of a checkpoint.
CHECKPOINT_ATTRS: dict[str, str] = {
    "checkpoint_version": "layout version of the checkpoint variables",
    "checkpoint_wall_time": "wall-clock seconds spent on the run before this checkpoint",
    "checkpoint_link_error_initial": "relative error of the initial chords (exact, for the failure bound)",
    "checkpoint_time": "ISO time at which the checkpoint was written",
}

#: Global attribute of every run file the simulator writes: the SHA-256 digest of its
#: content (every attribute but itself, every variable's name, dimensions, dtype and
#: values; :func:`snapping.simulate.dataset.content_digest`). A checkpoint whose digest
#: does not match (an edited ``chi``, a damaged state) is not resumed.
DIGEST_ATTR = "integrity_sha256"

# ---------------------------------------------------------------- 3D runs
#: Names that only a 3D run (:mod:`snapping.spatial`, :mod:`snapping.spatial.dataset3d`) has.
#: A 3D run Dataset uses the planar names above where they mean the same (``x``, ``y``,
#: ``vx``, ``v_max``, ``t_snap_v``, ...; ``y`` along gravity's default direction, downward)
#: and these for the third coordinate and what only space has. A planar run has none of them.
#: ``energy`` of a 3D run has the planar zero: the chain hanging straight down at rest from a
#: held end at the origin.
SPATIAL_STEP_VARS: dict[str, dict[str, str]] = {
    "z_amp": _v("out-of-plane amplitude: largest distance of a node from the reference plane through the held end"),
    "vz_amp": _v("largest out-of-plane node speed (velocity component along the reference plane's normal)"),
    "angular_momentum_g": _v("angular momentum about the held end along gravity's direction"),
}
SPATIAL_NODE_PROFILE_VARS: dict[str, dict[str, str]] = {
    "z": _v("node position, e3 component (out of the e1-e2 plane)"),
    "vz": _v("node velocity, e3 component"),
    "az": _v("node acceleration, e3 component"),
}
SPATIAL_PROBLEM_VARS: dict[str, dict[str, str]] = {
    "start_z": _v("node position at t = 0, e3 component"),
    "start_vz": _v("node velocity at t = 0, e3 component"),
    "pin_table_z": _v("e3 position of the held end at the sample times (cubic spline between; a 3D table)"),
}
#: Global attributes of a 3D run, besides the planar ones that mean the same.
SPATIAL_ATTRS: dict[str, str] = {
    "dims": "number of space dimensions of the run (3: snapping.spatial; planar runs have no such attribute)",
    "g_dir": "unit direction of gravity (x, y, z)",
    "normal": "unit normal of the reference plane whose out-of-plane amplitude z_amp measures",
    "perturbation": "JSON description of the out-of-plane perturbation of the start ('' if none)",
    "whirl": "rotation rate of a whirling start about the vertical through the held end (NaN: not whirling)",
    "z_amp_snap": "out-of-plane amplitude at the speed peak (t_snap_v)",
    "vz_amp_snap": "largest out-of-plane node speed at the speed peak",
    "z_amp_max": "largest out-of-plane amplitude over the run",
    "angular_momentum_drift": "max |angular_momentum_g(t) - angular_momentum_g(0)| (conserved: fixed end, gravity only)",
    "link_error_max": "largest | |e_j| - 1 | at the end of an accepted step before its projection",
}
SPATIAL_VARS = {**SPATIAL_STEP_VARS, **SPATIAL_NODE_PROFILE_VARS, **SPATIAL_PROBLEM_VARS}
