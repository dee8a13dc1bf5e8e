"""What the robot can know about itself from its own sensors (pure NumPy).

A real HOAP-2 has a torso gyro and accelerometer, four force sensors under each sole
and joint encoders; nothing else. :class:`StateEstimator` turns those readings into the
learner's state: torso roll and pitch from a complementary filter (gyro integrated,
pulled towards the accelerometer's gravity direction with time constant ``tau``),
heading from the integrated yaw rate, how the load is shared between the feet, and
where it sits under them (the centre of pressure, from four sensors per sole laid out
front-left, front-right, rear-left, rear-right). No simulator ground truth is used.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["GRAVITY", "STATE_NAMES", "Estimate", "StateEstimator"]

#: Standard gravity [m/s²].
GRAVITY = 9.81

#: The full state vector, in order.
STATE_NAMES = ("gyro_x", "gyro_y", "gyro_z", "roll", "pitch", "heading", "load_left", "cop_x")


@dataclass(frozen=True)
class Estimate:
    """One tick's estimate.

    Attributes:
        gyro: ``(3,)`` torso angular velocity [rad/s]; roll, pitch: torso tilt [rad];
        heading: integrated yaw since reset [rad]; load_left: share of the sole forces
        under the left foot (0.5 when nothing touches); cop_x: front minus rear sensor
        force over the total, −1 (all on the heels) … 1 (all on the toes), 0 if unknown.
    """

    gyro: np.ndarray
    roll: float
    pitch: float
    heading: float
    load_left: float
    cop_x: float = 0.0

    def vector(self) -> np.ndarray:
        """``(8,)`` in :data:`STATE_NAMES` order."""
        return np.array(
            [*self.gyro, self.roll, self.pitch, self.heading, self.load_left, self.cop_x]
        )


class StateEstimator:
    """Complementary-filter tilt, integrated heading, foot-load share.

    Args:
        dt: control period [s]; tau: time constant pulling the tilt towards the
            accelerometer [s] (long: trust the gyro; short: trust the accelerometer);
        prior: ``None``: the tilt starts from the first reading that feels gravity (see
            :meth:`update`); a time [s]: it starts level, and that belief counts as
            ``prior`` seconds of level readings, so until ``tau`` has passed the tilt is
            the running mean of the readings and that prior (the filter's time constant
            grows from ``prior`` to ``tau``). One reading cannot then set it: a robot set
            down onto the floor lands, and its accelerometer reads the landing's jolt
            (Unitree G1: 34° of pitch on its first reading, which put the centre of
            mass 0.37 m ahead of its feet).
    """

    def __init__(self, dt: float, tau: float = 0.5, prior: float | None = None):
        self.dt, self.tau, self.prior = dt, tau, prior
        self.reset()

    def reset(self) -> None:
        """Level, heading zero."""
        self.roll = self.pitch = self.heading = 0.0
        self._started = False
        self._elapsed = 0.0  # [s] of readings that felt gravity (``prior`` only)

    def update(self, gyro: np.ndarray, accel: np.ndarray, foot_force: np.ndarray) -> Estimate:
        """Fold in one tick of readings: gyro ``(3,)`` [rad/s], accel ``(3,)`` [m/s²],
        foot_force ``(2, k)`` [N].

        Without a ``prior``, the tilt starts from the first reading that feels gravity
        (|accel| above half of it): a robot set down a fraction of a millimetre above the
        floor is in free fall for its first tick, and that reading's direction says
        nothing (it read −180° of roll, which the filter took a second to forget). Until
        then the tilt is level. With one, it starts level (see the class doc).
        """
        gyro = np.asarray(gyro, dtype=float)
        ax, ay, az = np.asarray(accel, dtype=float)
        acc_roll = float(np.arctan2(ay, az))
        acc_pitch = float(np.arctan2(-ax, np.hypot(ay, az)))
        feels_gravity = np.hypot(np.hypot(ax, ay), az) > 0.5 * GRAVITY
        if self.prior is not None:  # level at first, the readings averaged in
            self.roll += gyro[0] * self.dt
            self.pitch += gyro[1] * self.dt
            if feels_gravity and np.isfinite(acc_roll):
                w = self.dt / (min(self.tau, self.prior + self._elapsed) + self.dt)
                self.roll += w * (acc_roll - self.roll)
                self.pitch += w * (acc_pitch - self.pitch)
                self._elapsed += self.dt
        elif not self._started or not np.isfinite(acc_roll):
            if feels_gravity and np.isfinite(acc_roll):
                self.roll, self.pitch, self._started = acc_roll, acc_pitch, True
        else:
            a = self.tau / (self.tau + self.dt)
            self.roll = a * (self.roll + gyro[0] * self.dt) + (1 - a) * acc_roll
            self.pitch = a * (self.pitch + gyro[1] * self.dt) + (1 - a) * acc_pitch
        self.heading += float(gyro[2]) * self.dt
        f = np.asarray(foot_force, dtype=float)
        total = f.sum()
        load = float(f[0].sum() / total) if total > 1e-6 else 0.5
        cop = 0.0
        if f.shape[1] == 4 and total > 1e-6:
            cop = float((f[:, :2].sum() - f[:, 2:].sum()) / total)
        return Estimate(gyro.copy(), self.roll, self.pitch, self.heading, load, cop)
