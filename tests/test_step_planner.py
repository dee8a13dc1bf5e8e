"""Step location, timing and ZMP adaptation (pure NumPy)."""

from __future__ import annotations

import numpy as np

from imitwalk.step.lipm import NominalGait, dcm_after, dcm_before
from imitwalk.step.planner import StepLimits, StepWeights, plan_step

GAIT = NominalGait(
    step=0.15, width=0.078, ss=0.5, ds=0.13, heel=0.014, toe=0.014, inward=0.0, omega=6.14
)
LIMITS = StepLimits(
    forward=0.19, backward=0.09, inner=0.07, outer=0.16, ss_min=0.25, ss_max=0.75, swing_speed=1.4
)
WEIGHTS = StepWeights(step=10.0, offset=1.0, time=1.0, zmp=0.01)
BOX = (np.array([-0.02, -0.02]), np.array([0.02, 0.02]))


def _nominal_dcm(elapsed: float) -> np.ndarray:
    """The periodic gait's DCM ``elapsed`` into the single support of a right stance."""
    _, heel, toe = GAIT.zmp_points(-1.0)
    target = np.array([GAIT.step, GAIT.width]) + GAIT.offset(1.0)
    now = heel + (toe - heel) * elapsed / GAIT.ss
    return dcm_before(target, now, toe, GAIT.ss - elapsed, GAIT.omega), now


def _plan(xi, now, elapsed, **kw):
    args = dict(
        elapsed=elapsed,
        zmp_now=now,
        swing_at=np.array([-0.1, 0.078]),
        nominal_step=np.array([GAIT.step, GAIT.width]),
        offset=GAIT.offset(1.0),
        zmp_box=BOX,
    )
    args.update(kw)
    return plan_step(xi, -1.0, GAIT, LIMITS, WEIGHTS, **args)


def test_the_nominal_dcm_gets_the_nominal_step():
    xi, now = _nominal_dcm(0.1)
    c = _plan(xi, now, 0.1)
    assert np.allclose(c.landing, [GAIT.step, GAIT.width], atol=2e-3)
    assert abs(c.ss - GAIT.ss) < 0.02
    assert np.allclose(c.zmp_shift, 0.0, atol=1e-3)


def test_a_small_push_is_taken_by_the_ankles():
    xi, now = _nominal_dcm(0.1)
    c = _plan(xi + np.array([0.005, 0.005]), now, 0.1)
    assert np.all(c.zmp_shift > 0.0)  # the ZMP moves towards the push ...
    assert np.allclose(c.landing, [GAIT.step, GAIT.width], atol=2e-3)  # ... the step stays


def test_a_dcm_pushed_forward_steps_further_or_sooner():
    xi, now = _nominal_dcm(0.1)
    c = _plan(xi + np.array([0.05, 0.0]), now, 0.1)
    assert c.zmp_shift[0] == BOX[1][0]  # the ankles at their limit ...
    assert c.landing[0] > GAIT.step + 0.01 or c.ss < GAIT.ss - 0.05  # ... and the step


def test_a_dcm_pushed_out_to_the_swing_side_steps_wider():
    xi, now = _nominal_dcm(0.1)
    c = _plan(xi + np.array([0.0, 0.05]), now, 0.1)
    assert c.zmp_shift[1] == BOX[1][1]
    assert c.landing[1] > GAIT.width + 0.005


def test_the_landing_stays_in_its_box():
    xi, now = _nominal_dcm(0.1)
    for push in ([0.3, 0.0], [-0.3, 0.0], [0.0, 0.3], [0.0, -0.3]):
        c = _plan(xi + np.array(push), now, 0.1)
        assert -LIMITS.backward - 1e-9 <= c.landing[0] <= LIMITS.forward + 1e-9
        assert LIMITS.inner - 1e-9 <= c.landing[1] <= LIMITS.outer + 1e-9  # never crosses
        assert LIMITS.ss_min - 1e-9 <= c.ss <= LIMITS.ss_max + 1e-9
        assert np.all(c.zmp_shift >= BOX[0] - 1e-12) and np.all(c.zmp_shift <= BOX[1] + 1e-12)


def test_the_prediction_is_the_closed_form_dcm():
    xi, now = _nominal_dcm(0.2)
    c = _plan(xi, now, 0.2)
    _, _, toe = GAIT.zmp_points(-1.0)
    expect = dcm_after(xi, now + c.zmp_shift, toe + c.zmp_shift, c.remaining, GAIT.omega)
    assert np.allclose(c.xi_end, expect, atol=1e-9)
