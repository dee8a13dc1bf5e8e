"""The servo state of the step model (``step.servo_state``): ankle-pitch tracking errors."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from imitwalk.balance import StepController, mirror_state
from imitwalk.errors import ConfigError
from imitwalk.learnconfig import preset
from imitwalk.stepconfig import LAG_JOINTS, SERVO_STATE, STEP_STATE, StepConfig

finite = st.floats(-1.0, 1.0, allow_nan=False)
D = len(STEP_STATE) + len(SERVO_STATE)


@given(st.lists(finite, min_size=D, max_size=D))
def test_mirroring_swaps_the_legs_lags_and_twice_is_identity(values):
    s = np.array(values)
    s[6] = abs(s[6])
    m = mirror_state(s, -1.0)
    assert m[-2] == s[-1] and m[-1] == s[-2]  # the stance leg's first
    np.testing.assert_allclose(m[: len(STEP_STATE)], mirror_state(s[: len(STEP_STATE)], -1.0))
    np.testing.assert_allclose(mirror_state(m, -1.0), s, atol=1e-12)
    np.testing.assert_array_equal(mirror_state(s, 1.0), s)


def test_servo_state_is_named_and_outside_the_objective():
    cfg = StepConfig(servo_state=True)
    assert cfg.state_names == STEP_STATE + SERVO_STATE
    np.testing.assert_array_equal(cfg.state_weights, [*cfg.weights, 0.0, 0.0])
    assert StepConfig().state_names == STEP_STATE
    states, _ = StepController(cfg, 100, 0.1).episode()
    assert states.shape == (0, D)
    with pytest.raises(ConfigError, match=r"step\.weights has 3 values"):
        StepConfig(weights=(1.0, 1.0, 1.0))


def _policy(tiny_reference, **step):
    from imitwalk.gait import GaitModel
    from imitwalk.policy import WalkPolicy

    ref, _ = tiny_reference
    gait = GaitModel(ref, (0.3, 0.4), preset("extended").gait)
    steps = StepController(StepConfig(**step), gait.n_ticks, 0.1)
    n = ref.loops.shape[-1]
    return WalkPolicy(gait, 0.4, steps=steps, channel_ik=lambda k, off: np.zeros(n)), ref


def test_the_step_state_carries_each_ankles_measured_lag_stance_leg_first(tiny_reference):
    policy, ref = _policy(tiny_reference, servo_state=True)
    idx = [list(ref.joint_names).index(j) for j in LAG_JOINTS]
    lag = np.zeros(len(ref.joint_names))
    lag[idx] = [0.01, 0.03]  # the left ankle lags 0.01 rad, the right 0.03
    obs = SimpleNamespace(
        gyro=np.zeros(3), accel=np.array([0, 0, 9.81]), foot_force=np.ones((2, 4)), joints=None
    )
    q = policy.q0
    for k in range(policy._clock0 + 3 * policy.n):
        obs.joints = q - lag  # the robot ends each tick short of its targets by ``lag``
        q = policy(k, obs)
    states = np.array(policy.steps.states)
    assert states.shape[1] == D
    # past the first two steps (whose window starts at the first step)
    np.testing.assert_allclose(states[2::2, -2:], [[0.01, 0.03]] * len(states[2::2]))
    np.testing.assert_allclose(states[3::2, -2:], [[0.03, 0.01]] * len(states[3::2]))


def test_servo_state_needs_the_ankle_joints(tiny_reference, monkeypatch):
    import imitwalk.policy

    monkeypatch.setattr(imitwalk.policy, "LAG_JOINTS", ("l_ankle_pitch", "l_talus"))
    with pytest.raises(ConfigError, match=r"unknown joint .*l_talus.*l_ankle_pitch"):
        _policy(tiny_reference, servo_state=True)
    _policy(tiny_reference)  # off: not needed
