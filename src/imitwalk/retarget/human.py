"""The paper's mapping (§2), kept for comparison: IK on a human-sized robot skeleton.

The robot's kinematic tree is rescaled to the human's segment lengths (hip and
shoulder width, thigh, shank, trunk, upper arm, forearm); the mocap keypoints are
put on it as position constraints (knees, ankles, elbows, wrists, head) with the
pelvis and the feet oriented like the human's, and mink solves the IK frame by
frame. The joint angles are then given to the real robot unchanged. Scaling is the
paper's too: the joint pattern is shrunk about its mean.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mink
import mujoco
import numpy as np

from imitwalk.mocap.cycles import foot_contacts
from imitwalk.mocap.motion import Motion
from imitwalk.retarget.ik import leg_geometry
from imitwalk.retarget.plan import START_CYCLES, _smoothstep
from imitwalk.retarget.reference import Reference
from imitwalk.retarget.template import GaitTemplate
from imitwalk.robots import Robot

__all__ = ["build_paper", "human_ik"]


def _len(k: dict, a: str, b: str) -> float:
    return float(np.median(np.linalg.norm(k[a] - k[b], axis=1)))


def _body(model: mujoco.MjModel, robot: Robot, role: str) -> int:
    return int(model.jnt_bodyid[model.joint(robot.mj_joints[robot.index(role)]).id])


def _human_sized(robot: Robot, k: dict) -> mujoco.MjModel:
    """The robot's model with its segments stretched to the human's lengths."""
    m = robot.compile()
    for s in "lr":
        hip, knee, ankle = (_body(m, robot, f"{s}_{j}") for j in ("hip_yaw", "knee", "ankle_pitch"))
        half_hip = _len(k, "l_hip", "r_hip") / 2
        m.body_pos[hip, 1] = np.sign(m.body_pos[hip, 1]) * half_hip
        for body, (a, b) in ((knee, ("hip", "knee")), (ankle, ("knee", "ankle"))):
            robot_len = float(np.linalg.norm(m.body_pos[body]))
            m.body_pos[body] *= _len(k, f"{s}_{a}", f"{s}_{b}") / max(robot_len, 1e-6)
        if f"{s}_elbow" in robot.joint_names and f"{s}_elbow" in k:
            sh, el = _body(m, robot, f"{s}_shoulder_pitch"), _body(m, robot, f"{s}_elbow")
            m.body_pos[sh, 1] = np.sign(m.body_pos[sh, 1]) * _len(k, "l_shoulder", "r_shoulder") / 2
            m.body_pos[el] *= _len(k, f"{s}_shoulder", f"{s}_elbow") / max(
                float(np.linalg.norm(m.body_pos[el])), 1e-6
            )
    return m


def _walk_frame(k: dict) -> dict:
    """Keypoints rotated so the walk heads along +x, pelvis starting over the origin."""
    d = k["pelvis"][-1] - k["pelvis"][0]
    if np.hypot(d[0], d[1]) < 0.1:  # treadmill: face the way the hips face
        left = np.mean(k["l_hip"] - k["r_hip"], axis=0)
        d = np.cross(left, [0.0, 0.0, 1.0])
    yaw = np.arctan2(d[1], d[0])
    c, s = np.cos(-yaw), np.sin(-yaw)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    o = k["pelvis"][0] * np.array([1.0, 1.0, 0.0])
    return {n: (p - o) @ rot.T for n, p in k.items()}


#: Keypoint -> the robot role whose body the IK puts on it.
_POINTS = {
    "l_knee": "l_knee",
    "r_knee": "r_knee",
    "l_ankle": "l_ankle_pitch",
    "r_ankle": "r_ankle_pitch",
    "l_elbow": "l_elbow",
    "r_elbow": "r_elbow",
    "l_wrist": "l_hand",
    "r_wrist": "r_hand",
}


@dataclass(frozen=True)
class _Tasks:
    """The IK's tasks on the human-sized model: the pelvis pose, the keypoints' positions
    (keypoint -> task), the feet's orientations (side -> task) and the standing posture."""

    pelvis: mink.FrameTask
    points: dict[str, mink.FrameTask]
    feet: dict[str, mink.FrameTask]
    posture: mink.PostureTask

    def all(self) -> list[mink.Task]:
        """Every task, in the order the IK is given them."""
        return [self.pelvis, *self.points.values(), *self.feet.values(), self.posture]


def _tasks(m: mujoco.MjModel, robot: Robot, k: dict) -> _Tasks:
    """The tasks on the human-sized model ``m`` for the keypoints ``k`` the clip has."""
    root = m.body(int(m.body_rootid[m.body(robot.torso).id])).name
    pelvis = mink.FrameTask(root, "body", 5.0, 5.0)
    tasks = {
        kp: mink.FrameTask(m.body(_body(m, robot, role)).name, "body", 10.0, 0.0)
        for kp, role in _POINTS.items()
        if kp in k and role in robot.joint_names
    }
    feet = {
        s: mink.FrameTask(m.body(_body(m, robot, f"{s}_ankle_roll")).name, "body", 0.0, 1.0)
        for s in "lr"
    }
    posture = mink.PostureTask(m, cost=1e-3)
    posture.set_target(robot.stand_qpos)
    return _Tasks(pelvis, tasks, feet, posture)


def _set_targets(tasks: _Tasks, k: dict, f: int, hip_mid: np.ndarray, off: np.ndarray) -> None:
    """Aim the tasks at source frame ``f``: the pelvis ``off`` ``(3,)`` [m] below the hips'
    mid-point ``hip_mid`` ``(T, 3)`` facing as they do, the keypoints, the feet."""
    x = k["l_hip"][f] - k["r_hip"][f]
    x = np.cross(x, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    yaw = np.arctan2(x[1], x[0])
    pose = mink.SE3.from_rotation_and_translation(
        mink.SO3.from_rpy_radians(0, 0, yaw), hip_mid[f] - off
    )
    tasks.pelvis.set_target(pose)
    for kp, t in tasks.points.items():
        t.set_target(mink.SE3.from_translation(k[kp][f]))
    for s in "lr":
        v = k[f"{s}_toe"][f] - k[f"{s}_ankle"][f]
        fyaw, fpitch = np.arctan2(v[1], v[0]), -np.arctan2(v[2], np.hypot(v[0], v[1]))
        tasks.feet[s].set_target(mink.SE3.from_rotation(mink.SO3.from_rpy_radians(0, fpitch, fyaw)))


def _solve_frame(
    cfg: mink.Configuration, tasks: _Tasks, limits: list[mink.ConfigurationLimit]
) -> None:
    """Move ``cfg`` onto the tasks' targets (at most 20 IK steps)."""
    for _ in range(20):
        vel = mink.solve_ik(
            cfg,
            tasks.all(),
            1.0,
            "daqp",
            damping=1e-6,
            limits=limits,
        )
        cfg.integrate_inplace(vel, 1.0)
        if np.abs(vel).max() < 1e-5:
            break


def human_ik(motion: Motion, robot: Robot, frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Joint angles ``(F, n)`` [rad] of the given source frames, and which hit a limit."""
    k = _walk_frame(motion.keypoints)
    m = _human_sized(robot, k)
    cfg = mink.Configuration(m)
    cfg.update(robot.stand_qpos.copy())
    tasks = _tasks(m, robot, k)
    limits = [mink.ConfigurationLimit(m)]
    qadr = np.array([m.jnt_qposadr[m.joint(j).id] for j in robot.mj_joints])
    hip_mid = (k["l_hip"] + k["r_hip"]) / 2
    off = np.array([0.0, 0.0, float(np.mean(m.body_pos[_body(m, robot, "l_hip_yaw")][2]))])
    out = np.zeros((len(frames), robot.dof))
    for i, f in enumerate(frames):
        _set_targets(tasks, k, f, hip_mid, off)
        _solve_frame(cfg, tasks, limits)
        out[i] = cfg.q[qadr] * robot.signs
    at_limit = (out <= robot.limits[:, 0] + 1e-3) | (out >= robot.limits[:, 1] - 1e-3)
    return robot.clip(out), at_limit


def build_paper(
    motion: Motion,
    template: GaitTemplate,
    robot: Robot,
    scales: Sequence[float] | np.ndarray,
    dt: float,
) -> Reference:
    """The paper's reference: one human cycle retargeted, shrunk about its mean per scale."""
    a, b = template.cycles[0]
    n = max(2, round(template.period / dt))
    src = a + (np.arange(n) / n) * (b - a)
    frames = np.unique(np.concatenate([np.floor(src), np.ceil(src)]).astype(int)) % motion.n_frames
    q_f, lim_f = human_ik(motion, robot, frames)
    loop = np.stack(
        [
            np.interp(src % motion.n_frames, frames, q_f[:, j], period=None)
            for j in range(robot.dof)
        ],
        axis=1,
    )
    contacts = foot_contacts(motion)
    stance = np.stack([contacts[s][np.round(src).astype(int) % motion.n_frames] for s in "lr"], 1)
    mean = loop.mean(axis=0)
    k = np.arange(START_CYCLES * n)
    e_pose = _smoothstep(k / n)
    e_amp = _smoothstep((k - n) / ((START_CYCLES - 1) * n))
    psi = (k % n) / n
    stride = template.stride * leg_geometry(robot).leg / template.leg_length
    scales = np.asarray(sorted(scales), dtype=float)
    loops, starts, travel = [], [], []
    for s in scales:
        ls = mean + s * (loop - mean)
        cyc = ls[np.round(psi * n).astype(int) % n]
        st = (1 - e_pose[:, None]) * robot.stand + e_pose[:, None] * (
            mean + e_amp[:, None] * (cyc - mean)
        )
        loops.append(ls)
        starts.append(st)
        travel.append(np.cumsum(e_amp) * s * stride / n)
    clipped = [
        {
            "scale": 1.0,
            "joint": robot.joint_names[j],
            "ticks": int(lim_f[:, j].sum()),
            "of": len(frames),
        }
        for j in np.flatnonzero(lim_f.any(axis=0))
    ]
    return Reference(
        robot=robot.name,
        joint_names=robot.joint_names,
        mapping="paper",
        dt=dt,
        period=n * dt,
        scales=scales,
        loops=np.stack(loops),
        starts=np.stack(starts),
        strides=scales * stride,
        start_travel=np.stack(travel),
        phase=np.arange(n) / n,
        stance=stance,
        residual_mm=np.zeros((len(scales), (START_CYCLES + 1) * n)),
        clipped=clipped,
    )
