"""The grid probe of the graded nylon answer (``benchmarks/probe_nylon_grid.py``, ``design10``):
its unchanged variant is the answer's own graded level, and its factors refine what they say."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from snapping import caps_runs as CR

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("probe_nylon_grid", ROOT / "benchmarks" / "probe_nylon_grid.py")
probe = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(probe)

LB = 1.0029732075734887e-3  # the nylon line's bending length (L), sqrt(EI / (lambda g L)) / L


@pytest.mark.parametrize("chi,level", [(0.1, 0), (0.1, 1), (0.25, 0), (0.4, 1)])
def test_unchanged_variant_is_the_graded_level(chi, level):
    # the probe re-derives the spacing of grading.fold_following: it must give graded_h's links exactly
    h = probe.links(chi, LB, level)
    ref = CR.graded_h(chi, LB, level)
    assert h.size == ref.size
    np.testing.assert_allclose(h, ref, rtol=1e-12, atol=0.0)


def test_factors_refine_their_part_only():
    h0 = probe.links(0.1, LB, 0)
    tip = probe.links(0.1, LB, 0, tip=0.5)
    held = probe.links(0.1, LB, 0, held=0.5)
    # the free end's link is TIP_LINK l_b, halved by tip=0.5; the held arm's HELD_LINK l_b, halved by held=0.5
    assert h0[0] == pytest.approx(0.4 * LB, rel=1e-2) and tip[0] == pytest.approx(0.2 * LB, rel=1e-2)
    assert h0.max() == pytest.approx(20.0 * LB, rel=1e-2) and held.max() == pytest.approx(10.0 * LB, rel=1e-2)
    assert held[0] == pytest.approx(h0[0], rel=1e-2) and tip.max() == pytest.approx(h0.max(), rel=1e-2)
    # every part and the slope scaled: the spacing function halves, so the links double (+-1, the rounding)
    both = probe.links(0.1, LB, 1, gscale=True)
    assert abs(both.size - 2 * h0.size) <= 1
    assert both[0] == pytest.approx(0.5 * h0[0], rel=1e-2) and both.max() == pytest.approx(0.5 * h0.max(), rel=1e-2)


def test_below_refines_only_near_the_free_end():
    h0 = probe.links(0.1, LB, 0)
    hb = probe.links(0.1, LB, 0, below=0.05, by=0.5, w=0.005)
    x0, xb = np.cumsum(h0) - h0 / 2, np.cumsum(hb) - hb / 2
    at = lambda x, xs, h: float(np.interp(x, xs, h))  # noqa: E731
    assert at(0.02, xb, hb) == pytest.approx(0.5 * at(0.02, x0, h0), rel=0.02)  # halved well below 0.05
    assert at(0.3, xb, hb) == pytest.approx(at(0.3, x0, h0), rel=0.02)  # untouched well above
