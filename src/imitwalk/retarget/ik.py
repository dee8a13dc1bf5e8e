"""Whole-body IK on the robot with mink: task-space plan → joint angles.

Per control tick the free-floating pelvis and the legs are solved so that both soles
reach their planned poses (flat on the ground, turned to their planned headings), the
centre of mass its planned x, y and the pelvis its height and orientation (level, or
pitched into a slope, and turned to the walking frame's heading); the arms and waist
are set from the plan. Joint limits are constraints of the IK
(``mink.ConfigurationLimit``); any joint that ends at a limit is reported.
Warm-started from the previous tick.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import mink
import mujoco
import numpy as np

from imitwalk.errors import RetargetError
from imitwalk.retarget.plan import LegGeometry, TaskPlan
from imitwalk.robots import Robot
from imitwalk.robots.tree import Tree, footprint

__all__ = ["IKResult", "WalkIK", "leg_geometry"]


def _frame(model: mujoco.MjModel, name: str) -> tuple[str, int]:
    if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, name) >= 0:
        return "site", model.site(name).id
    return "body", model.body(name).id


def _pos(model: mujoco.MjModel, data: mujoco.MjData, name: str) -> np.ndarray:
    kind, i = _frame(model, name)
    return (data.site_xpos if kind == "site" else data.xpos)[i].copy()


def _mat(model: mujoco.MjModel, data: mujoco.MjData, name: str) -> np.ndarray:
    kind, i = _frame(model, name)
    return (data.site_xmat if kind == "site" else data.xmat)[i].reshape(3, 3).copy()


def leg_geometry(robot: Robot) -> LegGeometry:
    """Measure the left leg of ``robot`` at zero joint angles (pelvis frame), and how far
    the hips stand ahead of the centre of mass in the standing posture.

    The hip point is the hip-pitch axis's anchor moved sideways over the ankle (on a
    robot whose hip axes do not meet above the leg, e.g. G1, the pitch hinge sits inside
    the leg's line); the foot's size is the footprint of its collision geoms."""
    m = robot.compile()
    d = mujoco.MjData(m)
    d.qpos[:] = robot.stand_qpos
    mujoco.mj_kinematics(m, d)
    mujoco.mj_comPos(m, d)
    root0 = int(m.body_rootid[m.body(robot.torso).id])
    hips = [d.xanchor[m.joint(robot.mj_joints[robot.index(f"{s}_hip_pitch")]).id] for s in "lr"]
    hip_ahead = float(np.mean(hips, axis=0)[0] - d.subtree_com[root0][0])
    d.qpos[:] = m.qpos0
    mujoco.mj_kinematics(m, d)
    root = int(m.body_rootid[m.body(robot.torso).id])
    pelvis = d.xpos[root]
    anchor = lambda role: d.xanchor[m.joint(robot.mj_joints[robot.index(role)]).id]  # noqa: E731
    hip, ankle = anchor("l_hip_pitch").copy(), anchor("l_ankle_pitch")
    hip[1] = ankle[1]  # the hip point over the ankle: hip axes need not meet above the leg
    sole = _pos(m, d, robot.soles["l"])
    foot = footprint(m, d, Tree(m).subtree(m.body(_body_of(m, robot.soles["l"])).id))
    return LegGeometry(
        hip_y=float(abs(hip[1] - pelvis[1])),
        hip_z=float(pelvis[2] - hip[2]),
        leg=float(np.linalg.norm(hip - ankle)),
        ankle=float(ankle[2] - sole[2]),
        sole_x=float(sole[0] - ankle[0]),
        foot_length=float(2 * foot.half[0]),
        hip_ahead=hip_ahead,
        foot_width=float(2 * foot.half[1]),
    )


def _rz(th: float) -> np.ndarray:
    """``(3, 3)`` rotation by ``th`` [rad] about z."""
    c, s = np.cos(th), np.sin(th)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _body_of(model: mujoco.MjModel, name: str) -> str:
    kind, i = _frame(model, name)
    return mujoco.mj_id2name(
        model, mujoco.mjtObj.mjOBJ_BODY, model.site_bodyid[i] if kind == "site" else i
    )


@dataclass
class IKResult:
    """Joint angles for each tick of a plan.

    ``q`` ``(N, n)`` [rad] (canonical roles); ``qpos`` ``(N, nq)`` whole-body states;
    ``residual_mm`` ``(N,)`` worst task error per tick (soles, CoM) [mm]; ``pelvis_drop_mm``
    ``(N,)`` how far the pelvis sits below its planned height (to keep the knee bent) [mm];
    ``at_limit`` ``(N, n)`` bool, joints that ended on a limit; ``iterations`` per tick.
    """

    q: np.ndarray
    qpos: np.ndarray
    residual_mm: np.ndarray
    pelvis_drop_mm: np.ndarray
    at_limit: np.ndarray
    iterations: np.ndarray
    info: dict = field(default_factory=dict)


class WalkIK:
    """mink whole-body IK for the walkable reference of one robot."""

    def __init__(
        self, robot: Robot, tol: float = 1e-5, max_iter: int = 30, knee_floor_deg: float = 15.0
    ):
        self.robot, self.tol, self.max_iter = robot, tol, max_iter
        self.model = m = robot.compile()
        for (lo, hi), name, sign in zip(robot.limits, robot.mj_joints, robot.signs, strict=True):
            j = m.joint(name).id
            if not m.jnt_limited[j]:  # a joint without a range: its servo's (Robot.limits)
                m.jnt_limited[j] = 1
                m.jnt_range[j] = np.sort(np.array([lo, hi]) * sign)
        # the knees may not straighten past ``knee_floor_deg`` in the IK: where a foot is
        # out of reach the (softer) pelvis-height task gives way instead of the knee
        for s in ("l_knee", "r_knee"):
            if s in robot.joint_names:
                jid = m.joint(robot.mj_joints[robot.index(s)]).id
                lo, hi = m.jnt_range[jid]
                floor = np.radians(knee_floor_deg) * robot.signs[robot.index(s)]
                m.jnt_range[jid] = (max(lo, floor), hi) if floor > 0 else (lo, min(hi, floor))
        self.cfg = mink.Configuration(m)
        self.cfg.update(robot.stand_qpos.copy())
        self._root = int(m.body_rootid[m.body(robot.torso).id])
        self._root_name = m.body(self._root).name
        if m.jnt_type[m.body_jntadr[self._root]] != mujoco.mjtJoint.mjJNT_FREE:
            raise RetargetError(f"robot {robot.name}: body {self._root_name!r} needs a free joint")
        d = self.cfg.data
        # "flat" = each sole's orientation relative to the pelvis in the standing pose
        self._sole_rot = {s: _mat(m, d, robot.soles[s]) for s in "lr"}
        pel = d.xmat[self._root].reshape(3, 3)
        self._sole_rot = {s: pel.T @ r for s, r in self._sole_rot.items()}
        self.tasks = {
            s: mink.FrameTask(robot.soles[s], _frame(m, robot.soles[s])[0], 10.0, 10.0)
            for s in "lr"
        }
        self.com = mink.ComTask(cost=np.array([10.0, 10.0, 0.0]))
        self.pelvis = mink.FrameTask(self._root_name, "body", np.array([0.0, 0.0, 1.0]), 10.0)
        cost = np.full(m.nv, 1e-4)
        cost[:6] = 0.0
        self._qadr = np.array([m.jnt_qposadr[m.joint(j).id] for j in robot.mj_joints])
        self._dadr = np.array([m.jnt_dofadr[m.joint(j).id] for j in robot.mj_joints])
        legs = {i for i, r in enumerate(robot.joint_names) if r[2:5] in ("hip", "kne", "ank")}
        self._upper = [i for i in range(robot.dof) if i not in legs]
        cost[self._dadr[self._upper]] = 10.0
        self.posture = mink.PostureTask(m, cost=cost)
        self.limits = [mink.ConfigurationLimit(m)]

    def _targets(self, plan: TaskPlan, i: int, base: np.ndarray) -> None:
        """Set every task's target for tick ``i``."""
        r, cfg = self.robot, self.cfg
        target_q = cfg.q.copy()
        for role, val in plan.upper.items():
            if role in r.joint_names:
                j = r.index(role)
                target_q[self._qadr[j]] = (base[j] + val[i]) * r.signs[j]
        self.posture.set_target(target_q)
        yaw = np.zeros(2) if plan.yaw is None else plan.yaw[i]  # the soles'
        walk = 0.0 if plan.path is None else plan.path[i, 2]  # the walking frame's heading
        for k, (s, sole) in enumerate((("l", plan.l_sole), ("r", plan.r_sole))):
            pose = np.eye(4)
            pose[:3, :3] = _rz(yaw[k]) @ self._sole_rot[s]
            pose[:3, 3] = sole[i]
            self.tasks[s].set_target(mink.SE3.from_matrix(pose))
        com = plan.com[i]
        self.com.set_target(np.array([com[0], com[1], 0.0]))
        pelvis = np.eye(4)
        pitch = float(plan.pitch)
        c, sn = np.cos(pitch), np.sin(pitch)
        pelvis[:3, :3] = _rz(walk) @ np.array([[c, 0.0, sn], [0.0, 1.0, 0.0], [-sn, 0.0, c]])
        pelvis[2, 3] = plan.pelvis_z[i]
        self.pelvis.set_target(mink.SE3.from_matrix(pelvis))

    def _converge(self, max_iter: int) -> int:
        tasks = [self.tasks["l"], self.tasks["r"], self.com, self.pelvis, self.posture]
        for it in range(max_iter):
            v = mink.solve_ik(self.cfg, tasks, 1.0, "daqp", damping=1e-8, limits=self.limits)
            self.cfg.integrate_inplace(v, 1.0)
            if np.abs(v).max() < self.tol:
                return it + 1
        return max_iter

    def start(self, qpos: np.ndarray) -> None:
        """Warm-start the solver from a whole-body state ``(nq,)``."""
        self.cfg.update(np.asarray(qpos, dtype=float).copy())

    def solve(self, plan: TaskPlan, q_upper_base: np.ndarray | None = None) -> IKResult:
        """Solve every tick of ``plan``.

        Args:
            plan: the task-space plan.
            q_upper_base: ``(n,)`` posture the plan's arm/waist offsets add to
                (default: the standing posture).
        """
        r, m, cfg = self.robot, self.model, self.cfg
        base = r.stand if q_upper_base is None else q_upper_base
        cfg.update(r.stand_qpos.copy())
        n = len(plan.phase)
        out_q, out_qpos = np.zeros((n, r.dof)), np.zeros((n, m.nq))
        res, drop, iters = np.zeros(n), np.zeros(n), np.zeros(n, dtype=int)
        for i in range(n):
            self._targets(plan, i, base)
            iters[i] = self._converge(self.max_iter)
            d = cfg.data
            errs = [
                np.linalg.norm(_pos(m, d, r.soles["l"]) - plan.l_sole[i]),
                np.linalg.norm(_pos(m, d, r.soles["r"]) - plan.r_sole[i]),
                np.linalg.norm(d.subtree_com[self._root][:2] - plan.com[i]),
            ]
            res[i] = 1000.0 * max(errs)
            drop[i] = 1000.0 * (plan.pelvis_z[i] - d.xpos[self._root][2])
            out_qpos[i] = cfg.q
            out_q[i] = cfg.q[self._qadr] * r.signs
        margin = 1e-3
        at_limit = (out_q <= r.limits[:, 0] + margin) | (out_q >= r.limits[:, 1] - margin)
        return IKResult(out_q, out_qpos, res, drop, at_limit, iters)
