"""The array layouts the compiled kernels, the engines and the driver share: the rows of a state
array, the entries of the measurements, the columns of the per-step record, the entries of the
control array, the peak table and the return codes of :func:`snapping.simulate.kernels.advance`.
"""

from __future__ import annotations


# rows of a state array
RX, RY, RVX, RVY, RAX, RAY, RSIG = 0, 1, 2, 3, 4, 5, 6
NROWS = 7

# ---------------------------------------------------------------- measurements
# entries of the ``meas`` array filled by :func:`measure`
M_VMAX, M_SV, M_AMAX, M_SA, M_SIGMAX, M_KMAX, M_SK = 0, 1, 2, 3, 4, 5, 6
M_VEND, M_AEND, M_PFX, M_PFY, M_ENERGY, M_LINKERR, M_LINKERR0 = 7, 8, 9, 10, 11, 12, 13
M_LENGTH, M_FINITE = 14, 15
# the minimum link tension over the chain (negative: the rigid links carry compression, where a real
# line goes slack) and the arclength of its link's midpoint from the held end
M_SIGMIN, M_SSIGMIN = 16, 17
NMEAS = 18

# ---------------------------------------------------------------- record rows
# columns of the per-step record buffer, in the order of schema.STEP_VARS after t
(R_T, R_DT, R_VMAX, R_AMAX, R_SIGMAX, R_KMAX, R_SK, R_SA, R_SV, R_VEND, R_AEND,
 R_PFX, R_PFY, R_ENERGY, R_LINKERR, R_EPS, R_SIGMIN, R_SSIGMIN) = range(18)
NREC = 18
RECORD_NAMES = ("t", "dt", "v_max", "a_max", "sigma_max", "kappa_max", "s_kappa_max", "s_a_max",
                "s_v_max", "v_end", "a_end", "pin_force_x", "pin_force_y", "energy", "link_error",
                "error_estimate", "sigma_min", "s_sigma_min")

# ---------------------------------------------------------------- control array
(C_T, C_DT, C_CUR, C_NSTEPS, C_NREJ, C_NRHS, C_NREC, C_TOL, C_FIXED, C_THIN, C_MAXLINK,
 C_DTMIN, C_STEPS_PER_CALL, C_TEND, C_TRET, C_VUP, C_VDOWN, C_STOPFRAC, C_E0, C_L0,
 C_LAST_V, C_LAST_A, C_LAST_S, C_LAST_K, C_DRIFT_LINK, C_DRIFT_LINK0, C_DRIFT_LEN, C_DRIFT_E,
 C_T_PEAKSTATE, C_DT_MIN_ACC, C_DT_MAX_ACC, C_EPS_MAX_ACC,
 C_MAXENERGY, C_MAXREJ, C_CONSREJ, C_VFLOOR) = range(36)
NCTL = 36

#: the stop rule judges a snap only once the running peak of v_max is above the start's own speed
#: and above this fraction of sqrt(g L) (``C_VFLOOR`` here, ``rk.Q_VFLOOR`` for DOP853 and RODAS4):
#: a start that is not at rest (a chain swinging gently from the start: its v_max only falls) or a
#: release transient (a bent line's residual force on 58,422 links: v_max 4e-8 at t = 6e-11, then
#: damped) is not a snap
STOP_FLOOR = 1e-3

# peak tracking: rows v, a, sigma, kappa; columns
P_TPREV, P_QPREV, P_TM1, P_QM1, P_T0, P_Q0, P_TP1, P_QP1, P_NEED = range(9)
NPK = 9
PEAK_QUANTITIES = ("v", "a", "sigma", "kappa")
_PEAK_MEAS = (M_VMAX, M_AMAX, M_SIGMAX, M_KMAX)

# return codes of :func:`advance`
RET_CALL_LIMIT, RET_RECORD_FULL, RET_T_RETURN, RET_V_UP, RET_V_DOWN = 0, 1, 2, 3, 4
RET_STOP, RET_END = 5, 6
RET_FAIL_NAN, RET_FAIL_DT, RET_FAIL_DRIFT, RET_FAIL_ENERGY, RET_FAIL_REJECT = 10, 11, 12, 13, 14
