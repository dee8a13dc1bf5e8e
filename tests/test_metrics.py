"""Walk metrics on synthetic rollouts (pure NumPy)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.sim.metrics import SATURATED, walk_metrics
from imitwalk.sim.types import Rollout


def _rollout(torque=None, limit=None, n=100):
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    pos = np.c_[np.linspace(0, 0.5, n), np.zeros(n), np.full(n, 0.3)]
    z = np.zeros((n, 3))
    return Rollout(
        t=np.arange(n) * 0.01, q_cmd=np.zeros((n, 3)), q=np.zeros((n, 3)), gyro=z, accel=z,
        foot_force=np.zeros((n, 2, 4)), torso_pos=pos, torso_quat=quat, qpos=np.zeros((n, 10)),
        fell=False, fall_time=None, control_dt=0.01, joint_names=("hip", "knee", "ankle"),
        torque=torque, torque_limit=limit,
    )  # fmt: skip


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 100), st.integers(0, 100))
def test_saturation_is_the_most_saturated_joints_share_of_ticks(k_knee, k_ankle):
    tau = np.full((100, 3), 1.0)
    tau[:k_knee, 1] = -4.0  # at the limit, either sign
    tau[:k_ankle, 2] = SATURATED * 4.0
    m = walk_metrics(_rollout(tau, np.array([4.0, 4.0, 4.0])), 0.5)
    assert m.torque_saturation == max(k_knee, k_ankle) / 100
    if max(k_knee, k_ankle) > 0:
        assert m.saturated_joint == ("knee" if k_knee >= k_ankle else "ankle")
    else:
        assert m.saturated_joint is None  # nothing saturated: no joint to name


def test_no_torque_recorded_means_no_saturation_figure():
    m = walk_metrics(_rollout(), 0.5)
    assert m.torque_saturation is None and m.saturated_joint is None
    assert m.forward_distance_m == 0.5 and m.to_dict()["torque_saturation"] is None
