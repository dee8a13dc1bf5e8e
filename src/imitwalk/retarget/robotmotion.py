"""A robot's whole-body motion, the record imitwalk exchanges with the field's tools.

GMR's robot-motion files and LocoMuJoCo's trajectories (:mod:`imitwalk.retarget.motionfiles`)
both hold, per frame, the floating base's pose and the joint angles of one robot model.
:class:`RobotMotion` is that content in imitwalk's terms (joint roles, the robot's
signs). Two conversions connect it to the rest of imitwalk:

- :func:`motion_of_reference`: a retargeted :class:`~imitwalk.retarget.reference.Reference`
  played from standing, its floating base placed by kinematic anchoring: the foot the
  plan has down stays where it landed, flat, and the base is where the joint angles put
  it relative to that foot (the way a motion is replayed without a simulator);
- :func:`clip_of_motion`: a robot motion as a clip (:class:`~imitwalk.mocap.Motion`):
  the joint centres the robot's forward kinematics give (pelvis, hips, knees, ankles,
  balls of the feet), so that ``imitwalk learn`` reads another project's retarget as it
  reads a human clip, and the stepping gait takes its style from it.

Both use the robot's MuJoCo model for kinematics only (``mj_kinematics``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from imitwalk.errors import MocapError
from imitwalk.mocap.motion import LOWER_BODY, Motion
from imitwalk.robots import Robot

if TYPE_CHECKING:
    from imitwalk.retarget.reference import Reference

__all__ = [
    "BALL",
    "MotionModel",
    "RobotMotion",
    "check_reference_robot",
    "clip_of_motion",
    "motion_of_reference",
]

#: The ball of the foot (a clip's ``toe``) lies this share of the sole's length ahead of
#: the sole's centre.
BALL = 0.25


@dataclass(frozen=True)
class RobotMotion:
    """One robot's motion, ``T`` frames.

    Attributes:
        robot: the robot's name; fps: frames per second [Hz];
        root_pos: ``(T, 3)`` the floating base's position [m] (world, z up);
        root_quat: ``(T, 4)`` its orientation, ``(w, x, y, z)``;
        joints: ``(T, n)`` joint angles [rad], in ``joint_names`` order and the robot's
        signs (``sign × the MJCF angle``); joint_names: the ``n`` roles;
        source: the file or run it came from.
    """

    robot: str
    fps: float
    root_pos: np.ndarray
    root_quat: np.ndarray
    joints: np.ndarray
    joint_names: tuple[str, ...]
    source: str = ""

    def __post_init__(self) -> None:
        t = len(self.joints)
        shapes = {
            "root_pos": (self.root_pos, (t, 3)),
            "root_quat": (self.root_quat, (t, 4)),
            "joints": (self.joints, (t, len(self.joint_names))),
        }
        for name, (a, shape) in shapes.items():
            if np.shape(a) != shape:
                raise MocapError(f"{self.source}: {name} is {np.shape(a)}, expected {shape}")
            if not np.all(np.isfinite(a)):
                raise MocapError(f"{self.source}: {name} holds values that are not finite")
        if t < 2 or not (np.isfinite(self.fps) and self.fps > 0):
            raise MocapError(f"{self.source}: {t} frames at {self.fps} Hz: need >= 2 at > 0 Hz")
        norms = np.linalg.norm(self.root_quat, axis=1)
        if np.any(np.abs(norms - 1.0) > 1e-3):
            raise MocapError(f"{self.source}: the root quaternions are not of unit length")

    @property
    def n_frames(self) -> int:
        """``T``."""
        return len(self.joints)


class MotionModel:
    """The robot's MuJoCo model as a motion sees it: the floating base first in ``qpos``,
    each role's ``qpos`` column and sign, every joint's name; posed frame by frame for
    kinematics only (``mj_kinematics``). The motion files
    (:mod:`imitwalk.retarget.motionfiles`) read and write its ``qpos``.

    Raises:
        MocapError: the robot has no floating base first in ``qpos``.
    """

    def __init__(self, robot: Robot):
        self.robot = robot
        self.m = m = robot.compile()
        self.d = mujoco.MjData(m)
        free = [j for j in range(m.njnt) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE]
        if len(free) != 1 or m.jnt_qposadr[free[0]] != 0:
            raise MocapError(f"robot {robot.name}: a motion needs one floating base, first")
        self.root = int(m.jnt_bodyid[free[0]])
        joint = mujoco.mjtObj.mjOBJ_JOINT
        self.names = [mujoco.mj_id2name(m, joint, j) or "" for j in range(m.njnt)]
        self.names[free[0]] = self.names[free[0]] or "root"
        self.qadr = np.array([m.jnt_qposadr[m.joint(j).id] for j in robot.mj_joints])
        self.sign = robot.signs.astype(float)
        self.soles = {s: m.site(robot.soles[s]).id for s in "lr"}

    def qpos(self, root_pos: np.ndarray, root_quat: np.ndarray, joints: np.ndarray) -> np.ndarray:
        """``(..., nq)`` the model's ``qpos``: the base at ``root_pos`` ``(..., 3)`` and
        ``root_quat`` ``(..., 4)``, the roles at ``joints`` ``(..., n)`` (the robot's
        signs), the other joints as when standing."""
        joints = np.asarray(joints, dtype=float)
        q = np.broadcast_to(self.robot.stand_qpos, (*joints.shape[:-1], self.m.nq)).copy()
        q[..., 0:3], q[..., 3:7] = root_pos, root_quat
        q[..., self.qadr] = joints * self.sign
        return q

    def motion(self, qpos: np.ndarray, fps: float, source: str) -> RobotMotion:
        """The motion of ``qpos`` ``(T, nq)`` (the inverse of :meth:`qpos`)."""
        quat = qpos[:, 3:7] / np.linalg.norm(qpos[:, 3:7], axis=1, keepdims=True)
        joints = qpos[:, self.qadr] * self.sign
        r = self.robot
        return RobotMotion(r.name, fps, qpos[:, 0:3].copy(), quat, joints, r.joint_names, source)

    def pose(self, root_pos: np.ndarray, root_quat: np.ndarray, joints: np.ndarray) -> None:
        """Pose the model at one frame (:meth:`qpos`)."""
        self.d.qpos[:] = self.qpos(root_pos, root_quat, joints)
        mujoco.mj_kinematics(self.m, self.d)

    def stand(self) -> None:
        """Pose the model standing (its standing keyframe)."""
        self.d.qpos[:] = self.robot.stand_qpos
        mujoco.mj_kinematics(self.m, self.d)

    def sole(self, side: str) -> tuple[np.ndarray, np.ndarray]:
        """The ``side`` sole's position ``(3,)`` and frame ``(3, 3)`` as posed."""
        i = self.soles[side]
        return self.d.site_xpos[i].copy(), self.d.site_xmat[i].reshape(3, 3).copy()


def _quat(mat: np.ndarray) -> np.ndarray:
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(mat).ravel())
    return q


def _rz(yaw: float) -> np.ndarray:
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def check_reference_robot(ref: Reference, robot: Robot) -> None:
    """Refuse, in one line (:class:`MocapError`), a reference retargeted to another robot
    than ``robot`` (another name or other joints)."""
    if ref.robot != robot.name or tuple(ref.joint_names) != robot.joint_names:
        raise MocapError(
            f"the reference is of robot {ref.robot!r}, not {robot.name!r}; retarget the clip to it"
        )


def motion_of_reference(
    ref: Reference, robot: Robot, scale: float | None = None, cycles: int = 4
) -> RobotMotion:
    """The reference's walk from standing at ``scale`` (default: its largest): the
    start-up then ``cycles`` loops, each frame a control tick (``1 / ref.dt`` Hz), the
    floating base placed by kinematic anchoring (see the module doc).

    Args:
        ref: a :class:`~imitwalk.retarget.reference.Reference` of ``robot``.
    """
    check_reference_robot(ref, robot)
    scale = float(ref.scales[-1]) if scale is None else scale
    start, loop, _ = ref.at_scale(scale)
    q = np.concatenate([start, *([loop] * cycles)])
    t = len(q)
    if ref.plan:
        down = ref.planned_load(scale, t)[0]
    else:  # the paper's mapping: both feet down in the start-up, the loop's stance after
        down = np.concatenate([np.ones((len(start), 2), bool), *([ref.stance] * cycles)])
    kin = MotionModel(robot)
    kin.stand()  # each sole's world frame and height standing: flat on the floor
    flat = {s: kin.sole(s)[1] for s in "lr"}
    height = {s: float(kin.sole(s)[0][2]) for s in "lr"}
    side = "r" if down[0, 1] and not down[0, 0] else "l"
    anchor_pos, anchor_yaw = kin.sole(side)[0], 0.0
    root_pos, root_quat = np.zeros((t, 3)), np.zeros((t, 4))
    for k in range(t):
        # the sole's frame in the base's frame, for these joint angles
        kin.pose(np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]), q[k])
        s_pos, s_mat = kin.sole(side)
        rot = _rz(anchor_yaw) @ flat[side] @ s_mat.T  # the base: the anchored sole flat
        root_pos[k] = anchor_pos - rot @ s_pos
        root_quat[k] = _quat(rot)
        other = "r" if side == "l" else "l"
        if k + 1 < t and not down[k + 1, "lr".index(side)] and down[k + 1, "lr".index(other)]:
            kin.pose(root_pos[k], root_quat[k], q[k])  # the other foot takes the weight
            o_pos, o_mat = kin.sole(other)
            rel = o_mat @ flat[other].T
            anchor_yaw = float(np.arctan2(rel[1, 0], rel[0, 0]))
            anchor_pos = np.array([o_pos[0], o_pos[1], height[other]])
            side = other
    return RobotMotion(
        robot.name, 1.0 / ref.dt, root_pos, root_quat, q, robot.joint_names, str(ref.source)
    )


def clip_of_motion(motion: RobotMotion, robot: Robot) -> Motion:
    """``motion`` as a clip: per frame, the joint centres of the robot's lower body
    (forward kinematics): ``pelvis`` (the floating base), ``l_hip``/``r_hip`` (the hip
    pitch axes), knees, ankles (the ankle pitch axes), and ``l_toe``/``r_toe`` (the ball of
    the foot, :data:`BALL` of the sole's length ahead of its centre).

    Raises:
        MocapError: a motion of another robot, or a robot without the roles named.
    """
    if motion.robot != robot.name or motion.joint_names != robot.joint_names:
        raise MocapError(f"{motion.source}: a motion of robot {motion.robot!r}, not {robot.name!r}")
    from imitwalk.retarget.ik import leg_geometry

    kin = MotionModel(robot)
    m, d = kin.m, kin.d
    need = [f"{s}_{r}" for s in "lr" for r in ("hip_pitch", "knee", "ankle_pitch")]
    absent = [r for r in need if r not in robot.joint_names]
    if absent:
        raise MocapError(f"robot {robot.name} has no {', '.join(absent)}: its motion is no clip")
    jid = {r: m.joint(robot.mj_joints[robot.index(r)]).id for r in need}
    ball = BALL * leg_geometry(robot).foot_length
    t = motion.n_frames
    keys = {k: np.zeros((t, 3)) for k in LOWER_BODY}
    for k in range(t):
        kin.pose(motion.root_pos[k], motion.root_quat[k], motion.joints[k])
        keys["pelvis"][k] = d.xpos[kin.root]
        for s in "lr":
            keys[f"{s}_hip"][k] = d.xanchor[jid[f"{s}_hip_pitch"]]
            keys[f"{s}_knee"][k] = d.xanchor[jid[f"{s}_knee"]]
            keys[f"{s}_ankle"][k] = d.xanchor[jid[f"{s}_ankle_pitch"]]
            pos, mat = kin.sole(s)
            keys[f"{s}_toe"][k] = pos + ball * mat[:, 0]
    return Motion(
        fps=motion.fps,
        channels=motion.joint_names,
        data=motion.joints.copy(),
        keypoints=keys,
        source=motion.source,
        format="robot",
        meta={"robot": robot.name},
    )
