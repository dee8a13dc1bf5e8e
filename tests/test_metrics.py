"""Walk metrics on synthetic rollouts (pure NumPy)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.sim.metrics import SATURATED, walk_metrics
from imitwalk.sim.types import Rollout


def _rollout(torque=None, limit=None, n=100):
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    pos = np.c_[np.linspace(0, 0.5, n), np.zeros(n), np.full(n, 0.3)]
    z = np.zeros((n, 3))
    return Rollout(
        t=np.arange(n) * 0.01,
        q_cmd=np.zeros((n, 3)),
        q=np.zeros((n, 3)),
        gyro=z,
        accel=z,
        foot_force=np.zeros((n, 2, 4)),
        torso_pos=pos,
        torso_quat=quat,
        qpos=np.zeros((n, 10)),
        fell=False,
        fall_time=None,
        control_dt=0.01,
        joint_names=("hip", "knee", "ankle"),
        torque=torque,
        torque_limit=limit,
    )


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


def _stepping(period: float, scuff_at: float | None = None, seconds: float = 12.0) -> Rollout:
    """A synthetic walk: each foot down for 60 % of ``period`` (alternating), the torso
    moving at 0.2 m/s; optionally one toe touch ``scuff_at`` [s] into a swing."""
    dt = 0.01
    t = np.arange(0.0, seconds, dt) + dt
    force = np.zeros((len(t), 2, 4))
    for j, shift in enumerate((0.0, 0.5)):
        phase = ((t / period) + shift) % 1.0
        down = phase < 0.6
        if scuff_at is not None:
            swing = (phase - 0.6) * period
            down |= np.abs(swing - scuff_at) < 0.015
        force[down, j] = 20.0
    pos = np.zeros((len(t), 3))
    pos[:, 0] = 0.2 * t
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (len(t), 1))
    n = 3
    return Rollout(
        t=t,
        q_cmd=np.zeros((len(t), n)),
        q=np.zeros((len(t), n)),
        gyro=np.zeros((len(t), 3)),
        accel=np.zeros((len(t), 3)),
        foot_force=force,
        torso_pos=pos,
        torso_quat=quat,
        qpos=np.zeros((len(t), 7)),
        fell=False,
        fall_time=None,
        control_dt=dt,
    )


@given(period=st.floats(0.8, 1.6))
@settings(max_examples=15, deadline=None)
def test_gait_timing_reads_cadence_and_stride_from_the_soles(period):
    from imitwalk.sim.metrics import gait_timing

    g = gait_timing(_stepping(period), weight_n=80.0, after_s=1.0, lifted_s=0.15)
    assert g.cadence_spm == pytest.approx(120.0 / period, rel=0.03)
    assert g.cycle_s == pytest.approx(period, rel=0.03)
    assert g.stride_m == pytest.approx(0.2 * period, rel=0.05)
    assert g.scuffs == 0


def test_a_toe_touch_mid_swing_is_a_scuff_not_a_step():
    from imitwalk.sim.metrics import gait_timing

    clean = gait_timing(_stepping(1.2), weight_n=80.0, after_s=1.0, lifted_s=0.2)
    scuffed = gait_timing(_stepping(1.2, scuff_at=0.12), weight_n=80.0, after_s=1.0, lifted_s=0.2)
    assert scuffed.steps == clean.steps and scuffed.cadence_spm == pytest.approx(clean.cadence_spm)
    assert scuffed.scuffs > 0 and clean.scuffs == 0
