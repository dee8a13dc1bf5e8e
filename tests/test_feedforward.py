"""The servo feedforward (:mod:`imitwalk.retarget.feedforward`): what it computes, and that
the nominal robot follows its reference more closely with it."""

from __future__ import annotations

import numpy as np
import pytest

from imitwalk.balance.feedback import TickPolicy
from imitwalk.errors import ConfigError
from imitwalk.retarget.feedforward import CLIP, reference_offsets, servo_offsets
from imitwalk.sim.mujoco import MujocoPlant

LEGS = ("hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")


def test_offsets_are_bounded_and_follow_the_reference(tiny_reference, robot):
    ref, _ = tiny_reference
    off = reference_offsets(ref, robot, 0.3, 3.0)
    assert off.shape == ref.trajectory(0.3, 3.0).shape
    assert np.all(np.isfinite(off)) and np.abs(off).max() <= CLIP
    assert np.abs(off).max() > 1e-3  # a robot under gravity needs some
    assert reference_offsets(ref, robot, 0.3, 3.0) is off  # computed once
    # the stance knee carries the body: held where the reference has it, the servo sags
    # into a deeper bend, so its target is set less bent
    down, share = ref.planned_load(0.3, len(off))
    assert np.all((share >= 0) & (share <= 1)) and down.any(axis=1).all()
    single = down[:, 0] & ~down[:, 1]
    knee = robot.joint_names.index("l_knee")
    sign = np.sign(np.median(ref.trajectory(0.3, 3.0)[single, knee]))
    assert np.median(sign * off[single, knee]) < 0


def test_a_long_walk_repeats_the_steady_loop_as_a_whole_computation_gives_it(tiny_reference, robot):
    ref, _ = tiny_reference
    q = ref.trajectory(0.3, 8.0)  # several loops past the start-up
    down, share = ref.planned_load(0.3, len(q))
    whole = servo_offsets(robot, q, down, share, ref.dt)
    off = reference_offsets(ref, robot, 0.3, 8.0)
    # equal but for the whole computation's last ticks (its finite differences' edge)
    np.testing.assert_allclose(off[:-10], whole[:-10], atol=1e-9)
    short = reference_offsets(ref, robot, 0.3, 3.0)
    np.testing.assert_array_equal(off[: len(short)], short)  # a walk's length changes nothing


def _leg_error(ref, robot, offsets, ticks: int) -> float:
    """RMS error [rad] of the leg joints behind the reference, the nominal robot played
    the reference with ``offsets`` open loop."""
    policy = TickPolicy(ref, 0.3, (), robot.joint_names, ticks * ref.dt, offsets=offsets)
    plant = MujocoPlant(robot, ref.sim_options())
    legs = [i for i, j in enumerate(robot.joint_names) if j[2:] in LEGS]
    obs, err = plant.reset(policy.q0), []
    for t in range(ticks - 1):
        plant.command(policy(t, obs))
        obs = plant.step()
        err.append(obs.joints[legs] - policy.q_ref[t + 1, legs])
    return float(np.sqrt(np.mean(np.square(err))))


def test_the_nominal_robot_follows_its_reference_closer(tiny_reference, robot):
    ref, _ = tiny_reference
    ticks = ref.starts.shape[1]
    off = reference_offsets(ref, robot, 0.3, ticks * ref.dt)
    assert _leg_error(ref, robot, off, ticks) < 0.7 * _leg_error(ref, robot, None, ticks)


def test_a_reference_without_a_plan_says_so(tiny_reference, robot):
    ref, _ = tiny_reference
    ref_without = type(ref).__new__(type(ref))
    ref_without.__dict__.update({**ref.__dict__, "plan": {}})
    with pytest.raises(ConfigError, match=r"trials\.feedforward=0"):
        reference_offsets(ref_without, robot, 0.3, 1.0)


def _obs(left: float, right: float):
    from imitwalk.sim.types import Observation

    return Observation(
        0.0, np.zeros(3), np.array([0.0, 0.0, 9.81]), np.array([[left], [right]]), np.zeros(0)
    )


def test_the_clock_waits_while_the_lifting_sole_is_loaded(tiny_reference, robot):
    ref, _ = tiny_reference
    policy = TickPolicy(ref, 0.3, (), robot.joint_names, 4.0, wait=0.3)
    assert len(policy.q_cmd) == 2 * len(policy.q_ref)  # it may reach twice as far
    down = ref.planned_load(0.3, len(policy.q_cmd))[0]
    lift = int(np.flatnonzero(down[:-1] & ~down[1:])[0] // 2)  # the first lift-off
    side = int(np.flatnonzero(down[lift] & ~down[lift + 1])[0])  # 0: left
    loaded = _obs(*((40.0, 10.0) if side == 0 else (10.0, 40.0)))
    for k in range(lift + 1):  # up to the lift-off, with the lifting sole loaded
        np.testing.assert_array_equal(policy(k, loaded), policy.q_cmd[k])
    for k in range(lift + 1, lift + 1 + policy.clock.max_wait):  # it waits, at most MAX_WAIT_S
        np.testing.assert_array_equal(policy(k, loaded), policy.q_cmd[lift])
    k = lift + 1 + policy.clock.max_wait
    np.testing.assert_array_equal(policy(k, loaded), policy.q_cmd[lift + 1])
    unloaded = _obs(*((0.0, 50.0) if side == 0 else (50.0, 0.0)))
    np.testing.assert_array_equal(policy(k + 1, unloaded), policy.q_cmd[lift + 2])
    # without the wait, the clock is the control tick
    plain = TickPolicy(ref, 0.3, (), robot.joint_names, 4.0)
    np.testing.assert_array_equal(plain(lift + 5, loaded), plain.q_cmd[lift + 5])
