"""Named balance channels and features (pure NumPy)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.balance.channels import CHANNELS, FEATURES, PHASED, channel_matrix, check_names
from imitwalk.errors import ConfigError


@settings(max_examples=40, deadline=None)
@given(
    st.lists(
        st.sampled_from(sorted(set(CHANNELS) - set(PHASED))), min_size=1, max_size=6, unique=True
    )
)
def test_a_channel_moves_its_joints_by_its_value_and_nothing_else(robot, channels):
    names = robot.joint_names
    full = channel_matrix(names, tuple(channels))  # (1, n, m): no phased channel
    assert full.shape == (1, len(names), len(channels))
    E = full[0]
    for c, channel in enumerate(channels):
        moved = {names[i] for i in np.flatnonzero(E[:, c])}
        assert moved == set(CHANNELS[channel])
        assert np.all(E[:, c][E[:, c] != 0] == 1.0)
    # one radian on every channel: each joint moves by the channels that name it
    a = np.ones(len(channels))
    for i, joint in enumerate(names):
        assert (E @ a)[i] == sum(joint in CHANNELS[c] for c in channels)


def test_both_legs_channels_are_the_sum_of_one_legs():
    for both in ("ankle_pitch", "ankle_roll", "hip_roll", "hip_pitch"):
        assert set(CHANNELS[both]) == set(CHANNELS[f"l_{both}"]) | set(CHANNELS[f"r_{both}"])


def test_names_are_checked_with_the_valid_ones_listed():
    assert check_names("feature", ["gyro_y", "roll"], FEATURES) == ("gyro_y", "roll")
    with pytest.raises(ConfigError, match=r"unknown feature 'gyro_w'; valid: gyro_x, gyro_y"):
        check_names("feature", ("gyro_w",), FEATURES)
    with pytest.raises(ConfigError, match="a name is given twice"):
        check_names("feature", ("roll", "roll"), FEATURES)
    with pytest.raises(ConfigError, match="no features given; valid: gyro_x"):
        check_names("feature", (), FEATURES)
    with pytest.raises(ConfigError, match=r"unknown channel 'knee'; valid: ankle_pitch"):
        channel_matrix(("l_knee",), ("knee",))


def test_a_robot_without_a_channels_joint_is_refused_naming_its_joints():
    joints = ("l_ankle_pitch", "l_knee")
    with pytest.raises(ConfigError) as err:
        channel_matrix(joints, ("ankle_pitch",))
    msg = str(err.value)
    assert "'r_ankle_pitch'" in msg and "valid: l_ankle_pitch, l_knee" in msg
    assert len(msg.splitlines()) == 1
    np.testing.assert_array_equal(channel_matrix(joints, ("l_ankle_pitch",)), [[[1.0], [0.0]]])


def test_a_phased_channel_needs_the_stance_schedule_and_follows_it(robot):
    names = robot.joint_names
    with pytest.raises(ConfigError, match="needs the stance schedule"):
        channel_matrix(names, ("turn",))
    stance = np.zeros((40, 2), dtype=bool)
    stance[:20, 0] = stance[20:, 1] = True  # left foot down, then the right
    E = channel_matrix(names, ("turn", "ankle_pitch"), stance)
    assert E.shape == (40, len(names), 2)
    moved = {names[i] for i in np.flatnonzero(np.any(E[:, :, 0] != 0, axis=0))}
    assert moved == set(CHANNELS["turn"])
    assert np.all(E[:, :, 1] == E[0, :, 1])  # an unphased channel is the same every tick
