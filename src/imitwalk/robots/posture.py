"""A standing posture for a robot whose file has none: knees bent, feet flat (mink IK).

:func:`solve_stand` starts from the zero posture on the floor and solves, by whole-body
IK on the robot's own model, for the soles flat where they are, the centre of mass over
the midpoint of the soles, the floating base level, the knees bent :data:`KNEE_DEG` and
the hands hanging below the shoulders; hinges that play no role stay where they are.
"""

from __future__ import annotations

import mink
import mujoco
import numpy as np

from imitwalk.robots.spec import Robot

__all__ = ["KNEE_DEG", "solve_stand"]

#: Knee flexion of a solved standing posture [deg].
KNEE_DEG = 30.0
#: Hands hang this fraction of the arm's reach out from below the shoulder.
ARM_OUT = 0.15


def _limited(robot: Robot) -> mujoco.MjModel:
    """The robot's model with every role joint limited to its range (for the IK)."""
    m = robot.compile()
    for (lo, hi), name, sign in zip(robot.limits, robot.mj_joints, robot.signs, strict=True):
        j = m.joint(name).id
        m.jnt_limited[j] = 1
        m.jnt_range[j] = np.sort(np.array([lo, hi]) * sign)
    return m


def solve_stand(
    robot: Robot, arm_ends: dict[str, str] | None = None, knee_deg: float = KNEE_DEG
) -> dict[str, float]:
    """A standing posture of ``robot``: role -> angle [rad], canonical signs.

    Args:
        robot: the robot (its ``stand_qpos`` is where the solve starts: feet on the floor).
        arm_ends: side -> the last body of each arm, to hang the arms down.
        knee_deg: knee flexion [deg].
    """
    m = _limited(robot)
    cfg = mink.Configuration(m)
    cfg.update(robot.stand_qpos.copy())
    d = cfg.data
    mujoco.mj_kinematics(m, d)
    root = int(m.body_rootid[m.body(robot.torso).id])
    tasks: list[mink.Task] = []
    mid = np.zeros(3)
    for s in ("l", "r"):
        name = robot.soles[s]
        kind = "site" if mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, name) >= 0 else "body"
        task = mink.FrameTask(name, kind, 10.0, 10.0)
        pose = cfg.get_transform_frame_to_world(name, kind)
        task.set_target(pose)
        tasks.append(task)
        mid += pose.translation() / 2
    com = mink.ComTask(cost=np.array([10.0, 10.0, 0.0]))
    com.set_target(mid)
    base = mink.FrameTask(m.body(root).name, "body", 0.0, 10.0)
    base.set_target(cfg.get_transform_frame_to_world(m.body(root).name, "body"))
    tasks += [com, base]
    target = cfg.q.copy()
    cost = np.full(m.nv, 1e3)  # hinges without a role stay put
    cost[:6] = 0.0
    for role, name, sign in zip(robot.joint_names, robot.mj_joints, robot.signs, strict=True):
        j = m.joint(name).id
        knee = role.endswith("_knee")
        target[m.jnt_qposadr[j]] = np.radians(knee_deg) * sign if knee else 0.0
        cost[m.jnt_dofadr[j]] = 1.0 if knee else 1e-2
    posture = mink.PostureTask(m, cost=cost)
    posture.set_target(target)
    tasks.append(posture)
    hands = []  # (task, shoulder joint, reach [m], outward sign)
    for s, end in (arm_ends or {}).items():
        if f"{s}_shoulder_pitch" not in robot.joint_names:
            continue
        first = m.joint(robot.mj_joints[robot.index(f"{s}_shoulder_pitch")]).id
        reach = float(np.linalg.norm(d.xpos[m.body(end).id] - d.xanchor[first]))
        hands.append((mink.FrameTask(end, "body", 1.0, 0.0), first, reach, 1 if s == "l" else -1))
    tasks += [h[0] for h in hands]
    limits = [mink.ConfigurationLimit(m)]
    for _ in range(300):
        for task, first, reach, side in hands:  # below the shoulder where it is now
            below = d.xanchor[first] + np.array([0.0, side * ARM_OUT * reach, -reach])
            task.set_target(mink.SE3.from_translation(below))
        v = mink.solve_ik(cfg, tasks, 1.0, "daqp", damping=1e-6, limits=limits)
        cfg.integrate_inplace(v, 0.5)
        if np.abs(v).max() < 1e-6:
            break
    q = cfg.q[[m.jnt_qposadr[m.joint(j).id] for j in robot.mj_joints]] * robot.signs
    return {r: round(float(a), 4) + 0.0 for r, a in zip(robot.joint_names, q, strict=True)}
