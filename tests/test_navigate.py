"""Navigation (``imitwalk navigate``): the leg odometry, the commanded stepping gait, the
course and its checks, the position fix, and the command's output and bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.errors import ConfigError

finite = st.floats(-0.3, 0.3, allow_nan=False)


def _cli(argv, capsys):
    from imitwalk.cli import main

    code = main(argv)
    out = capsys.readouterr()
    return code, out.out, out.err


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(finite, finite, st.floats(-0.4, 0.4)), min_size=1, max_size=8))
def test_the_odometry_chains_steps_as_poses_compose(steps):
    """Each touchdown's landing, seen from the stance foot, moves the chain by exactly the
    stance foot's rotation of it: the foot's position is the composed poses' position."""
    from imitwalk.step.odometry import LegOdometry

    odo = LegOdometry()
    odo.reset(np.array([0.0, 0.1]), 0.0)
    assert np.allclose(odo.foot, [0.0, -0.05])  # the origin midway between the soles
    pos, heading = odo.foot.copy(), 0.0
    for dx, dy, dyaw in steps:
        c, s = np.cos(heading), np.sin(heading)
        pos = pos + np.array([c * dx - s * dy, s * dx + c * dy])
        odo.touchdown(np.array([dx, dy]), heading)
        heading += dyaw
    assert np.allclose(odo.foot, pos)
    pose = odo.pose(np.zeros(2), heading)
    assert np.allclose(pose.xy, pos) and pose.heading == heading


def test_a_fix_pulls_the_odometry_its_weight_of_the_way():
    from imitwalk.step.odometry import LegOdometry

    odo = LegOdometry()
    body = odo.pose(np.array([0.02, 0.0]), 0.0).xy
    odo.fix(body + np.array([0.2, -0.1]), body, 0.5)
    assert np.allclose(odo.pose(np.array([0.02, 0.0]), 0.0).xy - body, [0.1, -0.05])


def test_commands_and_courses_refuse_bad_values_in_one_line():
    from imitwalk.navigate import Course, parse_waypoints
    from imitwalk.sim.fix import PositionFix
    from imitwalk.step.odometry import StepCommand

    for kw, word in [({"stride": 1.5}, "stride"), ({"heading": float("nan")}, "heading")]:
        with pytest.raises(ConfigError, match=word):
            StepCommand(**kw)
    with pytest.raises(ConfigError, match=r"waypoint 2 'nan,1'"):
        parse_waypoints(["1,0", "nan,1"])
    with pytest.raises(ConfigError, match=r"waypoint 1 '1;2'"):
        parse_waypoints(["1;2"])
    with pytest.raises(ConfigError, match="no waypoints"):
        parse_waypoints([])
    with pytest.raises(ConfigError, match=r"waypoint 1 '1e300,0'.*within ±1000 m"):
        parse_waypoints(["1e300,0"])
    with pytest.raises(ConfigError, match=r"waypoint 1 is \[inf, 0.0\]"):
        Course(np.array([[np.inf, 0.0]]))
    with pytest.raises(ConfigError, match="reach"):
        Course(np.array([[1.0, 0.0]]), reach=0.0)
    with pytest.raises(ConfigError, match="rate"):
        PositionFix(rate_hz=0.0)


def test_the_default_course_turns_up_to_90_degrees_on_legs_at_least_half_a_metre():
    from imitwalk.navigate import Course
    from imitwalk.navigate.course import DEFAULT_COURSE

    course = Course(np.array(DEFAULT_COURSE))
    assert len(course.waypoints) == 5 and np.all(course.legs >= 0.5)
    assert np.allclose(course.turns_deg, [0, 90, -90, -90, 90])


@pytest.mark.parametrize("stride", [1.0, 0.0])
def test_the_stepping_gait_walks_the_heading_and_stride_commanded(robot, stride):
    """Commanded 0.6 rad to the left after its start, the nominal robot turns there by its
    own gyro and encoders; at stride 0 it steps on the spot. Its odometry agrees with the
    truth to a few centimetres."""
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.navigate.trial import truth_path
    from imitwalk.sim.metrics import yaw_rad
    from imitwalk.sim.mujoco import make_plant, run
    from imitwalk.sim.types import SimOptions
    from imitwalk.step.controller import SteppingController
    from imitwalk.step.gains import StepGains
    from imitwalk.step.odometry import StepCommand
    from imitwalk.step.pipeline import gait_from_motion

    style = gait_from_motion(load_motion(default_clip()), robot).style
    ctrl = SteppingController(robot, style, StepGains(), 0.01)
    ctrl.steer(StepCommand(heading=0.6, stride=stride))
    poses = []

    def policy(k, obs):
        q = ctrl(k, obs)
        poses.append(ctrl.pose)
        return q

    policy.q0 = ctrl.q0
    ro = run(make_plant(robot, SimOptions()), policy, 800)
    assert not ro.fell
    yaw = yaw_rad(ro.torso_quat)[-1]
    assert 0.4 < yaw < 0.8 and abs(poses[-1].heading - 0.6) < 0.15
    path = truth_path(ro)
    travel = float(np.linalg.norm(path[-1]))
    assert (travel > 0.6) if stride == 1.0 else (travel < 0.1)
    assert np.linalg.norm(poses[-1].xy - path[-1]) < 0.06


def test_navigate_writes_its_verdict_plot_and_video(step_run, tmp_path, capsys):
    out = tmp_path / "nav"
    argv = [
        "navigate",
        str(step_run),
        "--waypoints",
        "0.2,0",
        "--seeds",
        "2",
        "--seconds",
        "6",
        "--out",
        str(out),
        "--json",
        "--fix-rate",
        "2",
    ]
    code, stdout, _ = _cli(argv, capsys)
    assert code == 0
    got = json.loads(stdout)
    assert got["robots"] == 2 and got["fix"] == {"rate_hz": 2.0, "sigma_m": 0.05}
    assert json.loads((out / "navigate.json").read_text()) == got
    assert sorted(p.name for p in out.iterdir()) == ["navigate.json", "path.png", "video.mp4"]
    for r in got["results"]:
        assert r["finished"] == (r["reached_s"][0] is not None and not r["fell"])


def test_bad_navigate_commands_exit_2_with_one_line(step_run, tick_run, tmp_path, capsys):
    import shutil
    from dataclasses import replace

    from imitwalk.step.gait import StepGait
    from imitwalk.step.style import reversed_in_time

    back = tmp_path / "back"  # a backward run (learn --backward)
    shutil.copytree(step_run, back)
    gait = StepGait.load(back / "style.json")
    replace(gait, style=reversed_in_time(gait.style)).save(back / "style.json")
    base = ["navigate", str(step_run), "--no-video", "--out", str(tmp_path / "n")]
    cases = [
        ([*base, "--waypoints", "1,nan"], "waypoint 1 '1,nan'"),
        ([*base, "--waypoints"], "no waypoints"),
        ([*base, "--waypoints", "1,0", "2"], "waypoint 2 '2'"),
        ([*base, "--fix-noise", "0.1"], "--fix-rate"),
        ([*base, "--fix-rate", "-1"], "rate"),
        ([*base, "--seeds", "0"], "--seeds 0"),
        ([*base, "--waypoints", "1e300,0"], "within ±1000 m"),
        ([*base, "--seconds", "inf"], "--seconds inf: expected a finite number"),
        ([*base, "--seconds", "0.002"], "--seconds 0.002"),
        ([*base, "--workers", "0"], "--workers 0"),
        ([*base, "--joint-map", "x.json"], "--joint-map x.json needs --robot"),
        (
            ["navigate", str(step_run), "--no-video", "--out", str(tmp_path / "no" / "n")],
            "does not exist",
        ),
        (["navigate", str(tick_run), "--no-video"], "learner: step"),
        (["navigate", str(back), "--no-video"], "walks backward"),
        (["navigate", str(tmp_path / "none")], "not found"),
    ]
    for argv, word in cases:
        code, _, err = _cli(argv, capsys)
        lines = err.strip().splitlines()
        assert code == 2 and word in lines[-1] and lines[-1].startswith("error: "), (argv, err)
    assert not (tmp_path / "n").exists()


def test_navigate_refuses_a_robot_the_run_did_not_learn_on(step_run, tmp_path, capsys, monkeypatch):
    import imitwalk.cli.navigate_commands as nav
    from imitwalk.robots import load_robot

    real = load_robot("hoap2")

    class Other:
        name = "op3"

    monkeypatch.setattr(nav, "robot_from", lambda a: Other() if a.robot == "op3.json" else real)
    argv = ["navigate", str(step_run), "--robot", "op3.json", "--out", str(tmp_path / "n")]
    code, _, err = _cli(argv, capsys)
    assert code == 2 and "learned on 'hoap2', not 'op3'" in err.strip().splitlines()[-1]
    assert not (tmp_path / "n").exists()
