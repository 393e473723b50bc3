"""The step-size control shared by RODAS4 in node and link coordinates
(``elastic_rodas.attempt_step`` / ``control_step``), against the rule of Hairer & Wanner's
``rodas.f`` written out here independently: a new step ``h min(6, max(1/5, 0.9 err^-1/4))``;
after an accepted step, Gustafsson's predictive step ``h min(6, max(1/5, 0.9 (h/h_acc)
(err_acc/err^2)^1/4))`` and the smaller of the two; no growth right after a rejection; a tenth
of the step after a non-finite error; the last step cut to reach the end exactly."""

import math

import numpy as np
import pytest

from snapping.simulate import elastic_rodas as R


def _ctl(h, hacc=0.0, erracc=0.0):
    ctl = np.zeros(R.NCTL)
    ctl[R.C_H] = h
    ctl[R.C_HACC] = hacc
    ctl[R.C_ERRACC] = erracc
    return ctl


def _standard(h, err):
    return h * min(6.0, max(0.2, 0.9 * err ** -0.25))


def _predictive(h, err, hacc, erracc):
    return h * min(6.0, max(0.2, 0.9 * (h / hacc) * (erracc / err ** 2) ** 0.25))


@pytest.mark.parametrize("err", [0.3, 0.999, 1e-3, 1e-12])
def test_first_accepted_step_takes_the_standard_rule(err):
    h = 0.0125
    ctl = _ctl(h)
    assert R.control_step(ctl, h, err, False)
    assert ctl[R.C_H] == pytest.approx(_standard(h, err), rel=1e-14)
    assert ctl[R.C_HACC] == h and ctl[R.C_ERRACC] == max(1e-2, err)
    assert ctl[R.C_NREJ] == 0.0


@pytest.mark.parametrize("err, hacc, erracc", [(0.5, 0.02, 0.1), (0.05, 0.005, 0.8), (0.9, 0.011, 0.01)])
def test_later_steps_take_the_smaller_of_standard_and_predictive(err, hacc, erracc):
    h = 0.01
    ctl = _ctl(h, hacc, erracc)
    assert R.control_step(ctl, h, err, False)
    want = min(_standard(h, err), _predictive(h, err, hacc, erracc))
    assert ctl[R.C_H] == pytest.approx(want, rel=1e-14)
    assert ctl[R.C_HACC] == h and ctl[R.C_ERRACC] == max(1e-2, err)


def test_no_growth_right_after_a_rejection():
    h = 0.01
    ctl = _ctl(h)
    assert R.control_step(ctl, h, 1e-4, True)
    assert ctl[R.C_H] == h  # the standard rule would grow it 6-fold (capped)
    assert _standard(h, 1e-4) > 5 * h


@pytest.mark.parametrize("err", [1.0001, 4.0, 1e6])
def test_rejected_step_shrinks_and_counts(err):
    h = 0.01
    ctl = _ctl(h, 0.02, 0.3)
    assert not R.control_step(ctl, h, err, False)
    assert ctl[R.C_H] == pytest.approx(_standard(h, err), rel=1e-14)
    assert ctl[R.C_NREJ] == 1.0
    assert ctl[R.C_HACC] == 0.02 and ctl[R.C_ERRACC] == 0.3  # the predictor keeps its last accepted step


@pytest.mark.parametrize("err", [math.nan, math.inf])
def test_non_finite_error_retries_a_tenth(err):
    ctl = _ctl(0.01)
    assert not R.control_step(ctl, 0.01, err, False)
    assert ctl[R.C_H] == pytest.approx(0.001, rel=1e-15) and ctl[R.C_NREJ] == 1.0


def test_attempt_reaches_the_end_exactly_and_fails_below_the_floor():
    ctl = _ctl(0.2)
    assert R.attempt_step(ctl, 0.5, 1.0) == (0.2, False, False)
    ctl = _ctl(0.499)  # within 1% of the end: stretched to it
    hs, last, failed = R.attempt_step(ctl, 0.5, 1.0)
    assert (hs, last, failed) == (0.5, True, False)
    ctl = _ctl(0.7)
    assert R.attempt_step(ctl, 0.5, 1.0) == (0.5, True, False)
    ctl = _ctl(2e-14)
    hs, last, failed = R.attempt_step(ctl, 3.0, 10.0)
    assert failed and ctl[R.C_STATUS] == R.FAILED and ctl[R.C_HFAIL] == 2e-14
    ctl = _ctl(4e-14)
    assert not R.attempt_step(ctl, 3.0, 10.0)[2]
