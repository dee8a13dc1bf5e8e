"""The policy that walks a course: the stepping gait steered by its own odometry.

Every control tick the :class:`Navigator` reads where the robot is by its own sensors
(:attr:`SteppingController.pose <imitwalk.step.controller.SteppingController.pose>`: leg
odometry turned by the IMU's heading, :mod:`imitwalk.step.odometry`), and commands the
stepping gait (:class:`~imitwalk.step.odometry.StepCommand`):

* **heading**: towards the waypoint, at most ``max_turn`` beyond the heading now. The
  gait turns each step by its learned ``heading`` share of that
  (:class:`~imitwalk.step.gains.StepGains`), so the default ``max_turn`` is the error for
  which that share is :data:`STEP_TURN`;
* **stride**: the style's times the cosine of the heading error (nothing when the
  waypoint lies more than 90° off: the robot turns on the spot), so that it does not
  circle a waypoint it faces away from; it changes by at most the whole stride over
  :data:`~imitwalk.step.schedule.START_STEPS` steps, as the gait's own start does, so
  that the robot slows down as it speeds up;
* **the next waypoint** once the robot believes itself within half the course's reach
  of this one (the other half is left to the odometry's error; on 20 training robots
  the default course took 39 s on average, against 50 s when it aimed within half a
  step); after the last it steps on the spot.

A position fix (:meth:`Navigator.fix`, the paper's "visual information": a camera or a
motion-capture room) pulls the odometry ``fix_weight`` of the way to it; without one the
robot walks by dead reckoning. Nothing here reads the simulator.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.navigate.course import Course
from imitwalk.sim.types import Observation
from imitwalk.step.controller import SteppingController
from imitwalk.step.odometry import StepCommand
from imitwalk.step.schedule import START_STEPS

__all__ = ["STEP_TURN", "NavTick", "Navigator"]

#: The turn per step the navigator asks for at most [rad], picked by trials on training
#: robots (``eval`` protocol seeds 110-129, the default clip on hoap2, the default
#: course): 20 of 20 finished at 0.25 rad, 16 of 20 at 0.35 rad (the falls came in
#: turns). The gait itself allows :data:`~imitwalk.step.schedule.MAX_STEP_YAW`.
STEP_TURN = 0.25


@dataclass(frozen=True)
class NavTick:
    """One tick of a navigation, by the robot's own estimate.

    Attributes:
        t: time [s]; x, y: the centre of mass in the start frame [m]; heading: [rad];
        target: the waypoint aimed at (0-based; K after the last).
    """

    t: float
    x: float
    y: float
    heading: float
    target: int


def _wrap(a: float) -> float:
    return float((a + np.pi) % (2 * np.pi) - np.pi)


class Navigator:
    """A policy ``(tick, observation) -> joint targets`` that walks ``course`` (see the
    module doc).

    Args:
        controller: the stepping gait it steers; course: the waypoints;
        max_turn: the heading error asked of the gait at most [rad] (``None``: the
            error the gait turns its largest step for, see the module doc);
        fix_weight: how far a position fix pulls the odometry (0 to 1).

    Attributes:
        q0: the controller's starting posture; target: the waypoint aimed at;
        track: a :class:`NavTick` per tick.
    """

    def __init__(
        self,
        controller: SteppingController,
        course: Course,
        max_turn: float | None = None,
        fix_weight: float = 0.5,
    ):
        self.ctrl, self.course = controller, course
        share = max(controller.gains.heading, 1e-3)
        self.max_turn = STEP_TURN / share if max_turn is None else max_turn
        self.fix_weight = fix_weight
        self.q0 = controller.q0
        self.near = 0.5 * course.reach
        self.target, self.stride = 0, 1.0
        self._ramp = controller.dt / (START_STEPS * controller.style.step_time)
        self.track: list[NavTick] = []

    @property
    def finished(self) -> bool:
        """Whether the robot believes it has reached every waypoint."""
        return self.target >= len(self.course.waypoints)

    def fix(self, xy: np.ndarray) -> None:
        """A position fix: the body measured at ``xy`` ``(2,)`` [m] in the start frame."""
        if self.ctrl.started:
            pose = self.ctrl.pose
            self.ctrl.odometry.fix(xy, pose.xy, self.fix_weight)

    def _command(self) -> StepCommand:
        pose = self.ctrl.pose
        wp = self.course.waypoints
        while not self.finished and np.linalg.norm(wp[self.target] - pose.xy) < self.near:
            self.target += 1
        if self.finished:
            heading, want = self.ctrl.command.heading, 0.0
        else:
            d = wp[self.target] - pose.xy
            err = _wrap(float(np.arctan2(d[1], d[0])) - pose.heading)
            heading = pose.heading + min(max(err, -self.max_turn), self.max_turn)
            want = max(float(np.cos(err)), 0.0)
        self.stride += min(max(want - self.stride, -self._ramp), self._ramp)
        return StepCommand(heading=heading, stride=self.stride)

    def __call__(self, k: int, obs: Observation) -> np.ndarray:
        if k > 0 and self.ctrl.started:
            self.ctrl.steer(self._command())
        q = self.ctrl(k, obs)
        pose = self.ctrl.pose
        self.track.append(NavTick(float(obs.t), pose.x, pose.y, pose.heading, self.target))
        return q
