"""Where the robot is, from its own sensors: leg odometry and the commanded walk (pure NumPy).

A walking robot knows where it is the way a person counting steps does. Every touchdown
the landing foot's pose, measured in the stance foot's frame by the encoders
(:class:`~imitwalk.step.kinematics.BodyModel`), is chained onto the stance foot's pose
in the start frame; the heading the chain turns by is the IMU's (the gyro's integrated
yaw rate, :class:`~imitwalk.balance.estimator.StateEstimator`), not the feet's, because
a sole that slips when it turns misreports its yaw and the gyro does not. The body is
then the stance foot plus the measured centre of mass. Its error grows with the
distance walked (the feet's slip, the gyro's drift); an optional position fix
(:meth:`LegOdometry.fix`, a camera or a motion-capture room) pulls it back.

The start frame: origin midway between the soles when the walk starts, x along the
robot's heading then, y to its left, z up. :class:`StepCommand` is what a navigator
asks of the stepping gait: a heading in that frame, and a stride.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.errors import ConfigError

__all__ = ["LegOdometry", "Pose2D", "StepCommand", "rot2"]


@dataclass(frozen=True)
class StepCommand:
    """What the stepping gait is asked to walk.

    Attributes:
        heading: the heading to walk at, in the start frame [rad] (the feet turn towards
            it by the learned ``heading`` gain's share of the error each step, at most
            :data:`~imitwalk.step.schedule.MAX_STEP_YAW` a step); stride: the style's
            step length times this, in [0, 1] (0: stepping on the spot); turn: the
            heading advances by this at every lift-off [rad per step] (a turning
            gait, :attr:`GaitStyle.turn <imitwalk.step.style.GaitStyle.turn>`; each
            step also turns by it ahead of the feedback).
    """

    heading: float = 0.0
    stride: float = 1.0
    turn: float = 0.0

    def __post_init__(self) -> None:
        for name in ("heading", "turn"):
            if not np.isfinite(getattr(self, name)):
                raise ConfigError(
                    f"command {name} {getattr(self, name)!r}: expected a finite angle [rad]"
                )
        if not 0.0 <= self.stride <= 1.0:
            raise ConfigError(f"command stride {self.stride!r}: expected 0 to 1 of the style's")


@dataclass(frozen=True)
class Pose2D:
    """A pose on the floor: ``x``, ``y`` [m] and ``heading`` [rad] in the start frame."""

    x: float
    y: float
    heading: float

    @property
    def xy(self) -> np.ndarray:
        """``(2,)`` the position [m]."""
        return np.array([self.x, self.y])


def rot2(a: float) -> np.ndarray:
    """``(2, 2)`` the rotation by ``a`` [rad] in the floor's plane."""
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s], [s, c]])


class LegOdometry:
    """The stance foot's pose in the start frame, chained step by step (see the module doc).

    Attributes:
        foot: ``(2,)`` the stance sole's centre in the start frame [m].
    """

    def __init__(self) -> None:
        self.foot = np.zeros(2)

    def reset(self, other_foot: np.ndarray, heading: float) -> None:
        """Start: ``other_foot`` ``(2,)`` [m] is the second sole in the stance frame, and
        the stance sole's heading is ``heading`` [rad]; the origin lies midway."""
        self.foot = -0.5 * (rot2(heading) @ np.asarray(other_foot, dtype=float)[:2])

    def touchdown(self, landing: np.ndarray, heading: float) -> None:
        """The swing foot landed at ``landing`` ``(2,)`` [m] in the frame of the stance
        foot, whose heading was ``heading`` [rad]; it becomes the stance foot."""
        self.foot = self.foot + rot2(heading) @ np.asarray(landing, dtype=float)[:2]

    def fix(self, measured: np.ndarray, body: np.ndarray, weight: float) -> None:
        """A position fix: the body is measured at ``measured`` ``(2,)`` [m] (start
        frame) where the odometry puts it at ``body`` ``(2,)`` [m]; move the chain
        ``weight`` (0 to 1) of the way to it."""
        self.foot = self.foot + weight * (np.asarray(measured, dtype=float) - body)

    def pose(self, com: np.ndarray, heading: float) -> Pose2D:
        """The body's pose: the centre of mass ``com`` ``(2,)`` [m] in the stance frame,
        the stance sole's ``heading`` [rad]."""
        xy = self.foot + rot2(heading) @ np.asarray(com, dtype=float)[:2]
        return Pose2D(float(xy[0]), float(xy[1]), float(heading))
