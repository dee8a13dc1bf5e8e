"""The stepping gait's state, from the robot's own sensors only (no simulator state).

Each tick :class:`BodyEstimator` turns an :class:`~imitwalk.sim.types.Observation`
into a :class:`BodyEstimate` in the **stance frame**: origin at the stance sole's centre,
x along that sole's heading, z up along gravity.

* **Attitude**: roll and pitch from the gyro and accelerometer (a complementary filter
  that starts level and averages the first readings in: :data:`TILT_PRIOR`),
  heading from the integrated yaw rate (:class:`~imitwalk.balance.estimator.StateEstimator`).
* **Kinematics**: the encoders posed on the robot's model with the pelvis turned by that
  attitude give the centre of mass, the swing sole and the sole force sensors relative
  to the stance sole (:class:`~imitwalk.step.kinematics.BodyModel`).
* **Centre of pressure**: the sole forces weighted by their sensors' positions.
* **Centre-of-mass velocity**: a steady-state Kalman filter per axis on the linear
  inverted pendulum, driven by the measured centre of pressure and corrected by the
  kinematic centre of mass (the model of Stephens, "State estimation for force-
  controlled humanoid balance", Humanoids 2011). Its gain comes from the Riccati
  recursion with the noise levels in :class:`ObserverNoise`.
* **DCM**: ``ξ = c + ċ / ω``.
* **The floor's slope** under the stance sole: its attitude (the IMU's tilt and the
  encoders), smoothed over :data:`SLOPE_TAU` for the swing foot's landing height and over
  :data:`SETTLED_TAU` for the soles' tilt across the walk. A sole on its edge reads as a
  slope, and tilting the sole onto that reading rolls it further: smoothed over 0.3 s, the
  tilt fell 12 more of ``hard``'s 40 training robots than none; over 1.5 s it settles on
  the floor's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.balance.estimator import StateEstimator
from imitwalk.sim.types import Observation
from imitwalk.step.kinematics import BodyModel, FootPose, rot_xyz, rot_z
from imitwalk.step.lipm import GRAVITY

__all__ = ["BodyEstimate", "BodyEstimator", "ObserverNoise", "observer_gain"]

SIDES = ("l", "r")
#: The floor's slope is smoothed with this time constant [s] for the swing foot's landing.
SLOPE_TAU = 0.3
#: ... and with this one [s] for the soles' tilt across the walk (``settled_slope``),
#: picked by trials on training robots (the module doc of :mod:`imitwalk.step.controller`).
SETTLED_TAU = 1.5
#: The attitude starts level, a belief worth this many seconds of level readings [s]
#: (:class:`~imitwalk.balance.estimator.StateEstimator`'s ``prior``): the first readings
#: are the landing's jolt when the robot is set down.
TILT_PRIOR = 0.1


@dataclass(frozen=True)
class ObserverNoise:
    """Noise levels the velocity observer's gain is computed for.

    Attributes:
        position: the kinematic centre of mass's error [m] (encoders and tilt);
        accel: the pendulum model's unmodelled acceleration [m/s²].
    """

    position: float = 0.003
    accel: float = 1.0


def observer_gain(omega: float, dt: float, noise: ObserverNoise) -> np.ndarray:
    """``(2,)`` the steady-state Kalman gain of one axis of the pendulum observer
    (state ``[c, ċ]``, measured ``c``), from the discrete Riccati recursion."""
    ch, sh = np.cosh(omega * dt), np.sinh(omega * dt)
    a = np.array([[ch, sh / omega], [omega * sh, ch]])
    g = np.array([[0.5 * dt * dt], [dt]])
    q = (g @ g.T) * noise.accel**2
    r = noise.position**2
    p = np.eye(2) * 1e-2
    k = np.zeros(2)
    for _ in range(2000):
        pp = a @ p @ a.T + q
        s = pp[0, 0] + r
        k = pp[:, 0] / s
        p_new = pp - np.outer(k, pp[0, :])
        if np.max(np.abs(p_new - p)) < 1e-14:
            break
        p = p_new
    return k


@dataclass(frozen=True)
class BodyEstimate:
    """One tick's state, in the stance frame.

    Attributes:
        com: ``(3,)`` centre of mass [m] (z: its height above the stance sole);
        com_vel: ``(2,)`` its horizontal velocity [m/s]; dcm: ``(2,)`` [m];
        swing: the other sole's pose (position ``(3,)`` [m], heading [rad]);
        cop: ``(2,)`` the centre of pressure [m] (``None``: nothing touches);
        load: ``(2,)`` the total sole force under the left and right foot [N];
        heading: the stance sole's heading in the start frame [rad];
        slope: ``(2,)`` the floor's rise per metre along x and y under the stance sole
        (its attitude from the IMU and the encoders, smoothed over :data:`SLOPE_TAU`);
        settled_slope: ``(2,)`` the same, smoothed over :data:`SETTLED_TAU`;
        roll, pitch: the torso's tilt [rad].
    """

    com: np.ndarray
    com_vel: np.ndarray
    dcm: np.ndarray
    swing: FootPose
    cop: np.ndarray | None
    load: np.ndarray
    heading: float
    slope: np.ndarray
    settled_slope: np.ndarray
    roll: float
    pitch: float


class BodyEstimator:
    """Sensors → :class:`BodyEstimate`.

    Args:
        body: the robot's kinematics; dt: control period [s]; omega: the pendulum's
            frequency [1/s]; noise: the observer's noise levels; tilt_tau: the attitude
            filter's time constant [s].
    """

    def __init__(
        self,
        body: BodyModel,
        dt: float,
        omega: float,
        noise: ObserverNoise | None = None,
        tilt_tau: float = 0.5,
    ):
        self.body, self.dt, self.omega = body, dt, omega
        self.gain = observer_gain(omega, dt, noise or ObserverNoise())
        self._tilt = StateEstimator(dt, tilt_tau, prior=TILT_PRIOR)
        ch, sh = np.cosh(omega * dt), np.sinh(omega * dt)
        self._a = np.array([[ch, sh / omega], [omega * sh, ch]])
        self._b = np.array([1.0 - ch, -omega * sh])
        self.reset("r")

    def reset(self, stance: str) -> None:
        """Start over, standing still on both feet, ``stance`` the stance foot."""
        self._tilt.reset()
        self.stance = stance
        self._x: np.ndarray | None = None  # (2, 2): per axis [c, ċ]
        self._slope = np.zeros(2)  # the floor's dz/dx, dz/dy under the stance sole
        self._settled = np.zeros(2)  # the same, smoothed more
        self._frame: tuple[np.ndarray, float] | None = None

    def _pose(self, obs: Observation) -> tuple[np.ndarray, np.ndarray, float]:
        """Pose the model on the encoders, the pelvis turned by the attitude; the
        rotation from the pelvis frame to the stance frame, the stance sole's position
        in the pelvis frame, and its heading in the start frame."""
        est = self._tilt.update(obs.gyro, obs.accel, obs.foot_force)
        self._last_tilt = est
        b = self.body
        b.set(obs.joints)
        imu = b.imu_in_root()
        world = rot_xyz(est.roll, est.pitch, est.heading) @ imu.T  # pelvis → start frame
        st = self.stance
        sole_mat = world @ b.sole_mat(st) @ b._flat[st].T
        heading = float(np.arctan2(sole_mat[1, 0], sole_mat[0, 0]))
        to_stance = rot_z(-heading) @ world
        # the floor's slope under the stance sole (its normal), in the stance frame
        normal = rot_z(-heading) @ sole_mat[:, 2]
        slope = -normal[:2] / max(float(normal[2]), 0.5)
        self._slope += min(self.dt / SLOPE_TAU, 1.0) * (slope - self._slope)
        self._settled += min(self.dt / SETTLED_TAU, 1.0) * (slope - self._settled)
        return to_stance, b.sole_pos(st), heading

    def update(self, obs: Observation, zmp_hint: np.ndarray) -> BodyEstimate:
        """Fold in one tick's readings; ``zmp_hint`` ``(2,)`` [m] drives the observer
        when no sole touches the ground."""
        rot, origin, heading = self._pose(obs)
        b = self.body
        com = rot @ (b.com() - origin)
        other = "l" if self.stance == "r" else "r"
        sw = rot @ (b.sole_pos(other) - origin)
        sw_mat = rot @ b.sole_mat(other) @ b._flat[other].T
        sw_yaw = float(np.arctan2(sw_mat[1, 0], sw_mat[0, 0]))
        f = np.asarray(obs.foot_force, dtype=float)
        load = f.sum(axis=1)
        total = float(load.sum())
        cop = None
        if total > 0.05 * b.mass * GRAVITY:
            pts = {s: (rot @ (b.pads(s) - origin).T).T for s in SIDES}
            cop = (f[0] @ pts["l"][:, :2] + f[1] @ pts["r"][:, :2]) / total
        p = cop if cop is not None else zmp_hint
        if self._x is None:
            self._x = np.stack([com[:2], np.zeros(2)], axis=1)  # (2 axes, [c, v])
        x = self._x @ self._a.T + np.outer(p, self._b)  # predict, per axis
        x = x + np.outer(com[:2] - x[:, 0], self.gain)  # correct
        self._x = x
        tilt = self._last_tilt
        return BodyEstimate(
            com=com,
            com_vel=x[:, 1].copy(),
            dcm=x[:, 0] + x[:, 1] / self.omega,
            swing=FootPose(sw, sw_yaw),
            cop=cop,
            load=load,
            heading=heading,
            slope=self._slope.copy(),
            settled_slope=self._settled.copy(),
            roll=float(tilt.roll),
            pitch=float(tilt.pitch),
        )

    def switch(self, new_stance: str, landing: FootPose) -> None:
        """The swing foot landed at ``landing`` (in the old stance frame) and becomes the
        stance foot: re-express the observer's state in its frame."""
        self.stance = new_stance
        r = rot_z(-landing.yaw)[:2, :2]
        self._slope = r @ self._slope
        self._settled = r @ self._settled
        if self._x is None:
            return
        c = (self._x[:, 0] - landing.pos[:2]) @ r.T
        v = self._x[:, 1] @ r.T
        self._x = np.stack([c, v], axis=1)
