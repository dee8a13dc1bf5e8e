"""The robot's kinematics for the stepping gait: forward kinematics of the measured
posture and per-leg inverse kinematics of the commanded one.

Both use the robot's own MJCF through MuJoCo's kinematics (``mj_kinematics``,
``mj_comPos``, ``mj_jacSite``) on a model of their own; neither ever steps physics
(only :mod:`imitwalk.sim` does). The model's free base is held at the origin with the
orientation it is given, so every position is relative to the pelvis (the root body).

The inverse kinematics moves each leg's joints (hip yaw, roll, pitch, knee, ankle pitch,
roll: the roles the robot has) by damped Newton steps on the sole's 6-D pose error,
warm-started from the last tick's answer, so a few iterations per tick suffice.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from imitwalk.robots import Robot

#: The least knee flexion the leg IK keeps [rad].
KNEE_FLOOR = 0.12
#: The largest change of a joint in one Newton step [rad].
MAX_STEP = 0.3

__all__ = ["KNEE_FLOOR", "LEG_JOINTS", "BodyModel", "FootPose", "rot_xyz", "rot_z"]

#: A leg's joints, from the hip down (each as ``f"{side}_{joint}"``).
LEG_JOINTS = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")


def rot_z(yaw: float) -> np.ndarray:
    """``(3, 3)`` rotation by ``yaw`` [rad] about z."""
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rot_xyz(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """``(3, 3)`` the rotation ``Rz(yaw) Ry(pitch) Rx(roll)`` (angles [rad])."""
    cr, sr, cp, sp = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch)
    ry = np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])
    rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    return rot_z(yaw) @ ry @ rx


def floor_mat(slope: np.ndarray) -> np.ndarray:
    """``(3, 3)`` the rotation that lays a level sole onto a floor rising ``slope``
    ``(2,)`` [m per m] along x and y: it turns z onto the floor's normal ``(-sx, -sy,
    1)`` and x onto the floor's line along x, ``(1, 0, sx)`` (both normalised)."""
    sx, sy = float(slope[0]), float(slope[1])
    hx, n = math.sqrt(1.0 + sx * sx), math.sqrt(1.0 + sx * sx + sy * sy)
    x0, x2 = 1.0 / hx, sx / hx  # x: the floor's line along x
    z0, z1, z2 = -sx / n, -sy / n, 1.0 / n  # z: its normal; y = z × x
    return np.array([[x0, z1 * x2, z0], [0.0, z2 * x0 - z0 * x2, z1], [x2, -z1 * x0, z2]])


def _quat(mat: np.ndarray) -> np.ndarray:
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(mat).ravel())
    return q


@dataclass(frozen=True)
class FootPose:
    """A sole's pose: ``pos`` ``(3,)`` [m] and ``yaw`` [rad], the sole flat."""

    pos: np.ndarray
    yaw: float


class BodyModel:
    """Forward and inverse kinematics of one robot.

    Attributes:
        robot: the robot; mass: its total mass [kg]; legs: per side ``"l"``/``"r"``, the
            robot's columns of that leg's joints (``(6,)``, hip to ankle).
    """

    def __init__(self, robot: Robot):
        self.robot = robot
        self.m = m = robot.compile()
        self.d = mujoco.MjData(m)
        self._root = int(m.body_rootid[m.body(robot.torso).id])
        self._qadr = np.array([m.jnt_qposadr[m.joint(j).id] for j in robot.mj_joints])
        self._dadr = np.array([m.jnt_dofadr[m.joint(j).id] for j in robot.mj_joints])
        self._sign = robot.signs.astype(float)
        self.mass = float(m.body_subtreemass[self._root])
        self.kv = self._servo_damping()
        self.legs = {
            s: robot.indices([f"{s}_{j}" for j in LEG_JOINTS if f"{s}_{j}" in robot.joint_names])
            for s in "lr"
        }
        self._sole = {s: m.site(robot.soles[s]).id for s in "lr"}
        gyro = m.sensor(robot.gyro).id
        self._imu = int(m.sensor_objid[gyro])
        self._pads = {
            s: np.array([m.sensor_objid[m.sensor(n).id] for n in robot.foot_force[s]]) for s in "lr"
        }
        # the soles' orientation relative to the pelvis when standing: "flat"
        self.set(robot.stand)
        self._flat = {s: self.sole_mat(s) for s in "lr"}
        self._jacp = np.zeros((3, m.nv))
        self._jacr = np.zeros((3, m.nv))
        # the IK's joint ranges: the knees kept bent by KNEE_FLOOR towards the way they
        # bend when standing (a straight knee is a singularity the Newton steps cannot
        # leave: the foot then flails instead of reaching)
        self.lo, self.hi = robot.limits[:, 0].copy(), robot.limits[:, 1].copy()
        for s in "lr":
            role = f"{s}_knee"
            if role in robot.joint_names:
                j = robot.index(role)
                if robot.stand[j] >= 0:
                    self.lo[j] = max(self.lo[j], KNEE_FLOOR)
                else:
                    self.hi[j] = min(self.hi[j], -KNEE_FLOOR)
        # per leg, what its Newton steps index: columns, dofs, signs, ranges, identity
        self._leg = {
            s: (c, self._dadr[c], self._sign[c], self.lo[c], self.hi[c], np.eye(len(c)))
            for s, c in self.legs.items()
        }

    def _servo_damping(self) -> np.ndarray:
        """``(n,)`` each servo's damping [Nm s/rad]: a position actuator's ``kv``
        (``-biasprm[2]``) plus its joint's own damping."""
        m = self.m
        acts = {int(m.actuator_trnid[a, 0]): a for a in range(m.nu)}
        out = []
        for name in self.robot.mj_joints:
            j = m.joint(name).id
            a = acts.get(j)
            kv = -float(m.actuator_biasprm[a, 2]) if a is not None else 0.0
            out.append(kv + float(m.dof_damping[m.jnt_dofadr[j]]))
        return np.array(out)

    # -- forward kinematics ------------------------------------------------------
    def set(self, q: np.ndarray, root_mat: np.ndarray | None = None) -> None:
        """Pose the model: ``(n,)`` joint angles [rad] (robot's signs), the pelvis at the
        origin turned by ``root_mat`` ``(3, 3)`` (default: level, heading +x)."""
        d = self.d
        d.qpos[:3] = 0.0
        d.qpos[3:7] = (1.0, 0.0, 0.0, 0.0) if root_mat is None else _quat(root_mat)
        d.qpos[self._qadr] = q * self._sign
        mujoco.mj_kinematics(self.m, d)
        mujoco.mj_comPos(self.m, d)

    def com(self) -> np.ndarray:
        """``(3,)`` the centre of mass of the posture set [m]."""
        return self.d.subtree_com[self._root].copy()

    def sole_pos(self, side: str) -> np.ndarray:
        """``(3,)`` the sole centre of ``side`` [m]."""
        return self.d.site_xpos[self._sole[side]].copy()

    def sole_mat(self, side: str) -> np.ndarray:
        """``(3, 3)`` the sole frame of ``side``."""
        return self.d.site_xmat[self._sole[side]].reshape(3, 3).copy()

    def sole_yaw(self, side: str) -> float:
        """Heading of the ``side`` sole [rad], relative to its standing heading."""
        r = self.sole_mat(side) @ self._flat[side].T
        return float(np.arctan2(r[1, 0], r[0, 0]))

    def pads(self, side: str) -> np.ndarray:
        """``(k, 3)`` the positions of ``side``'s sole force sensors [m]."""
        return self.d.site_xpos[self._pads[side]].copy()

    def imu_in_root(self) -> np.ndarray:
        """``(3, 3)`` the IMU's frame in the pelvis frame, for the posture set with a
        level pelvis."""
        return self.d.site_xmat[self._imu].reshape(3, 3).copy()

    def static_torques(self, loads: dict[str, tuple[float, np.ndarray]]) -> np.ndarray:
        """``(n,)`` the joint torques [Nm] (robot's signs) that hold the posture last set
        with the robot's weight borne by its soles: ``loads`` maps a side to its share of
        the weight and the point ``(3,)`` [m] (in the model's frame) where that share
        presses (the sole's centre of pressure). ``τ = g(q) − Σ J(q, point)ᵀ F`` with
        each ``F`` vertical: the floating base's balance, gravity from ``mj_rne`` at rest.
        With the pressure at the pendulum's ZMP this is the servos' load of the walk the
        pendulum plans, so adding ``τ / kp`` to their targets takes out their sag."""
        m, d = self.m, self.d
        bias = np.zeros(m.nv)
        mujoco.mj_rne(m, d, 0, bias)  # gravity alone: the model's velocities stay zero
        tau = bias
        for side, (share, point) in loads.items():
            if share <= 0.0:
                continue
            body = int(m.site_bodyid[self._sole[side]])
            mujoco.mj_jac(m, d, self._jacp, self._jacr, point, body)
            tau = tau - self._jacp[2] * (share * self.mass * -m.opt.gravity[2])
        return tau[self._dadr] * self._sign

    # -- inverse kinematics ------------------------------------------------------
    def solve_legs(
        self,
        q: np.ndarray,
        feet: dict[str, FootPose],
        pelvis_mat: np.ndarray,
        iterations: int = 3,
        damping: float = 1e-6,
        floor: np.ndarray | None = None,
    ) -> np.ndarray:
        """Leg joints that put each sole at its pose, the pelvis at the origin turned by
        ``pelvis_mat`` (foot poses in the same frame as the pelvis's).

        Args:
            q: ``(n,)`` the posture to start from [rad]; its other joints are kept.
            feet: per side, the sole's target :class:`FootPose`.
            pelvis_mat: ``(3, 3)`` the pelvis's orientation.
            iterations: Newton steps; damping: their Levenberg–Marquardt damping.
            floor: ``(3, 3)`` the floor's tilt (:func:`floor_mat`) both soles are laid
                onto; ``None``: level.

        Returns:
            ``(n,)`` the posture, clipped to the joint ranges.
        """
        m, d = self.m, self.d
        q = q.copy()
        turn = {s: rot_z(f.yaw) if floor is None else floor @ rot_z(f.yaw) for s, f in feet.items()}
        targets = {s: (f.pos, turn[s] @ self._flat[s]) for s, f in feet.items()}
        for _ in range(iterations):
            self.set(q, pelvis_mat)
            for s, (pos, mat) in targets.items():
                cols, dadr, sign, lo, hi, eye = self._leg[s]
                sid = self._sole[s]
                cur = d.site_xmat[sid].reshape(3, 3)
                err = np.empty(6)
                err[:3] = pos - d.site_xpos[sid]
                # orientation error: Σ cur_i × target_i = vee(T Cᵀ − C Tᵀ), halved
                r = mat @ cur.T
                err[3] = 0.5 * (r[2, 1] - r[1, 2])
                err[4] = 0.5 * (r[0, 2] - r[2, 0])
                err[5] = 0.5 * (r[1, 0] - r[0, 1])
                mujoco.mj_jacSite(m, d, self._jacp, self._jacr, sid)
                jac = np.vstack([self._jacp[:, dadr], self._jacr[:, dadr]]) * sign
                jt = jac.T
                lam = damping + 0.1 * float(err @ err)  # Levenberg–Marquardt: damp more when far
                step = np.linalg.solve(jt @ jac + lam * eye, jt @ err)
                step = np.minimum(np.maximum(step, -MAX_STEP), MAX_STEP)  # np.clip, cheaper
                q[cols] = np.minimum(np.maximum(q[cols] + step, lo), hi)
        return q
