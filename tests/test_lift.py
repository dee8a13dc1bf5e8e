"""The ``lift`` step channel: its settings, its task offsets, the IK, and old runs."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from imitwalk.balance import STEP_CHANNELS, STEP_STATE, StepConfig, StepController
from imitwalk.errors import ConfigError
from imitwalk.models import stack_episodes, unstack_episodes

L = STEP_CHANNELS.index("lift")
N, DS = 100, 0.1  # ticks per cycle, double support per transition


def test_lift_is_off_by_default_and_its_box_is_zero_then():
    ctrl = StepController(StepConfig(), N, DS)
    assert "lift" not in ctrl.config.channels and ctrl.box[L] == 0.0


def test_a_run_written_before_the_lift_channel_loads_with_lift_off():
    old = (0.015, 0.012, 0.04, 0.008, 0.01, 0.15)  # six channels: time, no lift
    cfg = StepConfig(c_max=old, offset=(0.002, 0, 0, 0, 0, 0), channels=("dx",))
    assert cfg.c_max == (*old, 0.0) and cfg.offset == (0.002, 0, 0, 0, 0, 0, 0.0)
    A_old = np.c_[np.ones((4, 6)), np.full(4, 0.7)]  # six channels and the scale
    data = unstack_episodes(stack_episodes({"step": [(np.zeros((4, 8)), A_old)]}))
    A = data["step"][0][1]
    assert A.shape == (4, len(STEP_CHANNELS) + 1)
    assert np.all(A[:, L] == 0.0) and np.all(A[:, -1] == 0.7) and np.all(A[:, :6] == 1.0)


def test_lift_box_out_of_range_is_an_error():
    c_max = list(StepConfig().c_max)
    c_max[L] = 0.05
    with pytest.raises(ConfigError, match=r"step\.c_max for lift=0\.05: expected 0 <= c <= 0\.02"):
        StepConfig(channels=("dx", "lift"), c_max=tuple(c_max))


@given(st.floats(-0.005, 0.005), st.integers(0, 5), st.floats(0.0, 0.999))
def test_lift_raises_only_the_swing_foot_only_in_its_swing(lift, k, u):
    ctrl = StepController(StepConfig(channels=("lift",)), N, DS)
    for j in range(k + 1):
        ctrl.decide(np.zeros(len(STEP_STATE)), j)
        ctrl.actions[-1][L] = lift
    i = (k + u) * N / 2
    out = ctrl.offsets(i)
    swing = 1 if k % 2 == 0 else 0  # even steps: left stance, right swing
    sigma = np.clip((u - 2 * DS) / (1 - 2 * DS), 0.0, 1.0)
    assert out[8 + (1 - swing)] == 0.0  # the stance foot stays on the ground
    assert out[8 + swing] == pytest.approx(lift * np.sin(np.pi * sigma), abs=1e-12)
    assert abs(out[8 + swing]) <= abs(lift) + 1e-12
    if u <= 2 * DS:  # double support: both feet down
        assert out[8 + swing] == 0.0
    np.testing.assert_array_equal(out[:8], 0.0)  # the other channels are off


def test_online_ik_raises_the_swing_sole_by_the_lift(robot, tiny_reference):
    from imitwalk.retarget.ik import CHANNELS, _pos
    from imitwalk.retarget.online import OnlineIK

    ref, _ = tiny_reference
    k = ref.starts.shape[1] + 5  # a loop tick
    zs = {}
    for dz in (0.0, 0.004):
        ik = OnlineIK(robot, ref, 0.4)
        off = np.zeros(len(CHANNELS))
        off[CHANNELS.index("r_z")] = dz
        for _ in range(5):  # converge from the standing warm start
            ik(k, off)
        d = ik.ik.cfg.data
        zs[dz] = {s: _pos(ik.ik.model, d, robot.soles[s])[2] for s in "lr"}
    assert zs[0.004]["r"] - zs[0.0]["r"] == pytest.approx(0.004, abs=2e-4)
    assert zs[0.004]["l"] == pytest.approx(zs[0.0]["l"], abs=2e-4)
    # the step controller writes one offset per IK channel
    ctrl = StepController(StepConfig(channels=("lift",)), N, DS)
    ctrl.decide(np.zeros(len(STEP_STATE)), 0)
    assert ctrl.offsets(0).shape == (len(CHANNELS),)


def test_lift_offsets_can_be_tried_like_any_channel_offset():
    from imitwalk.learnconfig import preset

    step = StepConfig(channels=("dx", "dy", "yaw", "sway", "lean", "lift"))
    cfg = preset("extended", step=step, offsets=(0.004,), offset_channel="lift")
    assert cfg.with_offset(0.004).step.offset_vector[L] == 0.004
    with pytest.raises(
        ConfigError, match=r"step\.offset for lift=0\.008: outside -0\.005\.\.0\.005"
    ):
        preset("extended", step=step, offsets=(0.008,), offset_channel="lift")
    with pytest.raises(ConfigError, match="unknown offset_channel 'lift'; valid: dx, dy"):
        preset("extended", offsets=(0.004,), offset_channel="lift")
