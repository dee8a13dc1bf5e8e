"""Progress ratios that mean something (issue 60): ``evaluate`` measures a robot's forward
distance against the distance commanded over the whole judged time, so a robot that
falls at once scores about 0, not its fall over the millimetres commanded before it."""

from __future__ import annotations

import pytest

from imitwalk.sim.types import SimOptions

SECONDS = 30.0


@pytest.mark.parametrize(
    "kick", [(0.0, 3.0, 0.0), (0.0, 0.0, 3.0), (1.5, -3.0, 0.0), (1.5, 3.0, 0.0), (1.5, 1.5, -1.5)]
)
def test_a_robot_that_falls_at_once_scores_about_zero(tick_run, robot, kick):
    """Kicked over at the start (``t`` [s], Δv [m/s]). Over the 0.5 mm commanded before a fall
    at 1.6 s, the 0.39 m the torso fell backwards read as a progress of -754."""
    from imitwalk.judge.verdict import RunController, load_run

    options = SimOptions(pushes=(kick,))
    m = RunController(str(tick_run), "fixed").walk(robot, options, SECONDS, "mujoco")
    assert m.fell and m.fall_time_s < 2.5
    lr = load_run(str(tick_run))
    whole = lr.ref.expected_distance(lr.scale, SECONDS)  # [m]
    # the stated range: at most the robot's standing height over the whole walk's distance
    assert abs(m.progress_ratio) <= robot.height / whole
    assert abs(m.progress_ratio) < 0.5
    assert m.progress_ratio == pytest.approx(m.forward_distance_m / whole)


def test_a_walk_that_does_not_fall_is_judged_as_before(tick_run, robot):
    from imitwalk.judge.verdict import RunController, load_run

    m = RunController(str(tick_run), "fixed").walk(robot, SimOptions(), 4.0, "mujoco")
    lr = load_run(str(tick_run))
    assert not m.fell
    expected = lr.ref.expected_distance(lr.scale, m.seconds)
    assert m.progress_ratio == pytest.approx(m.forward_distance_m / expected)
