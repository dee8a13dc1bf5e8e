"""Turning gaits learned from turning clips: the turn read from the clip and held within
the gait's limit, the turning step's geometry, the schedule's heading, and a turning walk
on the nominal robot that turns as the clip does, past a whole turn."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.conftest import TINY_STEP, sets


def _walker(name: str) -> Path:
    """One of pybullet's walker clips (the installed wheel ships them)."""
    import pybullet_data

    return Path(pybullet_data.getDataPath()) / "data" / "motions" / "walker" / f"{name}.txt"


@pytest.fixture(scope="module")
def left(robot):
    from imitwalk.mocap import load_motion
    from imitwalk.step.pipeline import gait_from_motion

    return gait_from_motion(load_motion(_walker("turn_left0")), robot)


def test_a_turning_clip_becomes_a_turning_gait_held_within_the_limit(robot, left):
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.step.pipeline import gait_from_motion
    from imitwalk.step.style import MAX_TURN

    assert np.degrees(left.style.turn) == pytest.approx(29.83, abs=0.05)
    assert left.style.human["turn_deg"] == pytest.approx(29.83, abs=0.05)
    sharp = gait_from_motion(load_motion(_walker("turn_right0")), robot).style
    assert sharp.turn == -MAX_TURN and sharp.human["turn_deg"] == pytest.approx(-99.28, abs=0.05)
    straight = gait_from_motion(load_motion(default_clip()), robot).style
    assert straight.turn == 0.0 and straight.human["turn_deg"] == 0.0


def test_a_style_written_before_turns_reads_as_straight(left):
    from imitwalk.step.style import GaitStyle

    d = left.style.to_dict()
    assert GaitStyle.from_dict(d).turn == left.style.turn
    del d["turn"]
    assert GaitStyle.from_dict(d).turn == 0.0


@settings(max_examples=50, deadline=None)
@given(st.floats(-0.45, 0.45), st.sampled_from([1.0, -1.0]), st.floats(0.0, 0.2))
def test_the_turning_step_follows_the_walking_frame_and_is_straight_at_no_turn(turn, side, step):
    from imitwalk.step.nominal import turning_step

    width, off = 0.08, np.array([0.01, -side * 0.02])
    land, offset = turning_step(step, width, side, turn, off)
    # the walking frame: from between the feet, a chord of the arc, then turned
    frame = np.array([step * np.cos(turn / 2), step * np.sin(turn / 2)])
    beside = np.array([np.sin(turn), -np.cos(turn)]) * (width / 2) * side
    assert np.allclose(land, np.array([0.0, -side * width / 2]) + frame + beside)
    assert np.isclose(np.linalg.norm(offset), np.linalg.norm(off))
    straight, same = turning_step(step, width, side, 0.0, off)
    assert np.array_equal(straight, np.array([step, -side * width])) and np.array_equal(same, off)


def test_the_schedule_turns_a_step_per_step_time_from_the_first_lift_off():
    from imitwalk.step.schedule import nominal_distance, nominal_track, start_seconds

    tr = nominal_track(0.14, 0.6, 0.2, 0.01, 6.0)
    t = np.arange(1, 601) * 0.01
    start = start_seconds(0.6)
    assert np.all(tr[t <= start, 2] == 0.0)
    assert np.allclose(tr[:, 2], 0.2 * np.maximum(t - start, 0.0) / 0.6)
    assert tr[-1, 0] == nominal_distance(0.14, 0.6, 6.0)
    assert np.all(nominal_track(0.14, 0.6, 0.0, 0.01, 6.0)[:, 2] == 0.0)


def test_a_turning_gait_turns_as_its_clip_does_past_a_whole_turn(robot, left):
    """20 s on the nominal robot: more than 360° turned by the gyro's wrapped heading,
    at the clip's rate per cycle of the steps taken."""
    from imitwalk.sim.metrics import yaw_rad
    from imitwalk.sim.mujoco import make_plant, run
    from imitwalk.sim.types import SimOptions
    from imitwalk.step.controller import SteppingController
    from imitwalk.step.gains import StepGains

    ctrl = SteppingController(robot, left.style, StepGains(), 0.01)
    ro = run(make_plant(robot, SimOptions()), ctrl, 2000)
    assert not ro.fell
    yaw = np.degrees(np.unwrap(yaw_rad(ro.torso_quat)))
    assert yaw[-1] - yaw[0] > 360.0
    per_cycle = (yaw[-1] - yaw[0]) / (ctrl.steps / 2)
    assert per_cycle == pytest.approx(29.83, rel=0.1)


def test_learn_says_how_a_turning_clip_turns(tmp_path, capsys):
    from imitwalk.cli import main

    out = tmp_path / "run"
    assert main(["learn", str(_walker("turn_right0")), "--out", str(out), *sets(TINY_STEP)]) == 0
    err = capsys.readouterr().err
    assert "turning -45.0 deg per cycle (the clip's -99.3 deg, beyond the gait's limit)" in err


def test_a_turning_clip_played_backward_is_said_to_turn_the_other_way(left):
    from imitwalk.step.pipeline import _turning
    from imitwalk.step.style import reversed_in_time

    said = _turning(reversed_in_time(left.style))
    assert said == ", turning -29.8 deg per cycle (the clip's +29.8 deg played backward)"
    assert _turning(left.style) == ", turning +29.8 deg per cycle"
