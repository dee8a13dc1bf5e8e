"""From the planned body and feet to joint targets, every tick.

:class:`JointSolver` poses the robot's model: the pelvis where the commanded centre of
mass puts it (the model's own offset between the two, from the last tick's posture),
level and turned halfway to the swing foot's heading; both soles by the legs' inverse
kinematics (:meth:`~imitwalk.step.kinematics.BodyModel.solve_legs`); the arms and waist
from the style's phase profiles. It then adds to the targets what the position servos
need to hold them:

* the **servo feedforward**, a fraction of ``(τ + kv q̇) / kp``: the static torques of
  the planned support (the weight pressing at the pendulum's ZMP,
  :meth:`~imitwalk.step.kinematics.BodyModel.static_torques`) and the servos' damping
  along the planned joint velocity (the computed-torque feedforward of a PD servo);
* the **ankles' share of the balance**: a ZMP shift ``Δp`` asks each loaded ankle for
  ``m g Δp`` of torque, ``Δθ = m g Δp / kp`` (pitch for x, roll for y).
"""

from __future__ import annotations

import numpy as np

from imitwalk.robots import Robot
from imitwalk.step.gains import StepGains
from imitwalk.step.kinematics import BodyModel, FootPose, rot_z
from imitwalk.step.lipm import GRAVITY
from imitwalk.step.style import GaitStyle

__all__ = ["JointSolver"]


class JointSolver:
    """Joint targets for one robot (see the module doc).

    Args:
        robot: the robot; style: the walk (its arms' and waist's profiles); gains: its
        ``feedforward``; dt: the control period [s].
    """

    def __init__(self, robot: Robot, style: GaitStyle, gains: StepGains, dt: float):
        self.robot, self.style, self.gains, self.dt = robot, style, gains, dt
        self.ik = BodyModel(robot)
        self.kp = robot.kp.copy()
        self.weight = self.ik.mass * GRAVITY
        geom = style.geometry
        self.half = np.array([geom.foot_length, geom.foot_width]) / 2
        self._upper = {r: robot.index(r) for r in style.upper if r in robot.joint_names}
        self.reset(robot.stand)

    def reset(self, q: np.ndarray) -> None:
        """Start from the measured posture ``q`` ``(n,)`` [rad] (the first solve's jump
        from it to the walking posture carries no velocity feedforward: over one tick
        it read as several rad/s, a kick of the servos' damping)."""
        self.q = self.q_prev = np.asarray(q, dtype=float).copy()
        self._first = True
        self.ik.set(self.q)
        self.com_off = self.ik.com()[:2]  # the centre of mass ahead of the pelvis

    def com_above_pelvis(self) -> float:
        """The centre of mass's height over the pelvis in the posture last solved [m]."""
        return float(self.ik.com()[2])

    def walking_com_height(self, pelvis_z: float, width: float) -> float:
        """The centre of mass's height [m] with the pelvis ``pelvis_z`` [m] over the soles,
        the feet ``width`` [m] apart under the hips."""
        feet = {
            "l": FootPose(np.array([0.0, width / 2, -pelvis_z]), 0.0),
            "r": FootPose(np.array([0.0, -width / 2, -pelvis_z]), 0.0),
        }
        q = self.robot.stand.copy()
        for _ in range(5):
            q = self.ik.solve_legs(q, feet, np.eye(3), iterations=4)
        self.ik.set(q)
        return float(self.ik.com()[2] + pelvis_z)

    def rebase(self, turn: np.ndarray) -> None:
        """The stance frame turned by ``turn`` ``(2, 2)`` (a new stance foot)."""
        self.com_off = turn @ self.com_off

    def solve(
        self,
        stance: str,
        com: np.ndarray,
        height: float,
        other: FootPose,
        phase: float,
        loads: dict[str, tuple[float, np.ndarray]],
        ankle_zmp: np.ndarray,
        floor: np.ndarray | None = None,
        upper: float = 1.0,
    ) -> np.ndarray:
        """Joint targets ``(n,)`` [rad].

        Args:
            stance: the stance side; com: ``(2,)`` the commanded centre of mass [m] and
            height: the pelvis's height [m], both over the stance sole; other: the other
            sole's commanded pose; phase: the gait phase ψ for the arms and waist; loads:
            per side, its share of the weight and the point ``(3,)`` where it presses
            [m] (stance frame); ankle_zmp: ``(2,)`` the ZMP shift asked of the ankles
            [m]; floor: ``(3, 3)`` the floor's tilt both soles are laid onto
            (:func:`~imitwalk.step.kinematics.floor_mat`), ``None``: level; upper: the
            share [0, 1] of the style's arm and waist swing (ramped in at the start).
        """
        r = self.robot
        pelvis = np.array([*(com - self.com_off), height])
        turn = rot_z(0.5 * other.yaw)
        swing = "l" if stance == "r" else "r"
        feet = {stance: FootPose(-pelvis, 0.0), swing: FootPose(other.pos - pelvis, other.yaw)}
        q = self.ik.solve_legs(self.q, feet, turn, iterations=2, floor=floor)
        offsets = self.style.upper_at(phase)
        for role, j in self._upper.items():
            q[j] = r.stand[j] + upper * offsets[role]
        self.ik.set(q, turn)
        self.com_off = self.ik.com()[:2]
        self.q_prev, self.q = (q if self._first else self.q), q
        self._first = False
        out = q.copy()
        g = self.gains
        if g.feedforward:  # the servos' static sag, and their damping's lag: τ = kp e − kv q̇
            qdot = (q - self.q_prev) / self.dt
            out += g.feedforward * self.ik.kv * qdot / self.kp
            pressed = {s: (share, at - pelvis) for s, (share, at) in loads.items()}
            out += g.feedforward * self.ik.static_torques(pressed) / self.kp
        for side, (share, _) in loads.items():
            legs = self.ik.legs[side]
            if share <= 0.0 or len(legs) < 6:
                continue
            dp = np.clip(ankle_zmp, -self.half, self.half) * share * self.weight
            out[legs[4]] += dp[0] / self.kp[legs[4]]
            out[legs[5]] -= dp[1] / self.kp[legs[5]]
        return out
