"""Robot description: which MJCF joints play which role, and which sensors to read.

A robot is an MJCF file plus a *joint map* (JSON, :mod:`imitwalk.robots.jointmap`) naming,
for each canonical role in :data:`ROLES`, the model's hinge joint that plays it; the
gyro, the accelerometer, the foot force sensors, the torso body and the two soles. What
the file lacks (a floor, sole sites and sensors, an IMU, position servos) is added when
the model is built (:mod:`imitwalk.robots.build`); the file itself is never changed. The
built-in ``hoap2`` is loaded through exactly the same path as a user's robot.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

from imitwalk.errors import RobotError, unknown_name
from imitwalk.robots.assemble import Resolved, plan_additions
from imitwalk.robots.build import Additions, compile_model
from imitwalk.robots.jointmap import JointMap, load_joint_map, parse_joint_map
from imitwalk.robots.plausible import check_masses, check_standing
from imitwalk.robots.rolenames import ARM_ROLES, LEG_ROLES, ROLES, SIDES, TRUNK_ROLES
from imitwalk.robots.servos import actuator_kind, torque_limit

__all__ = ["ARM_ROLES", "LEG_ROLES", "ROLES", "TRUNK_ROLES", "Robot", "load_joint_map"]

#: A standing posture that is not the file's own keyframe is lowered onto the floor: its
#: lowest sole this far above it [m] (as :meth:`imitwalk.sim.mujoco.MujocoPlant.reset` does).
SOLE_CLEARANCE = 1e-4


def _names(model: mujoco.MjModel, objtype: mujoco.mjtObj, count: int) -> list[str]:
    return [mujoco.mj_id2name(model, objtype, i) or "" for i in range(count)]


@dataclass(frozen=True)
class Robot:
    """A validated robot: model file, role → joint names, sensors and nominal posture.

    Attributes:
        name: robot name (``hoap2`` or the joint map's ``name``).
        mjcf: path of the MJCF file.
        joint_names: canonical roles this robot has, in :data:`ROLES` order (``n`` of them).
        mj_joints: the MJCF joint playing each role, ``(n,)``.
        signs: ``(n,)`` ±1; canonical angle = sign × MJCF angle.
        gyro, accelerometer: sensor names (accelerometer may be ``None``).
        foot_force: ``{"l": names, "r": names}`` force/touch sensors under each sole.
        torso: body whose height and tilt define a fall; carries the gyro.
        soles: ``{"l": name, "r": name}`` site (or body) at the centre of each sole.
        stand: ``(n,)`` standing posture [rad], canonical signs.
        stand_qpos: full ``qpos`` of the standing keyframe (free base included).
        limits: ``(n, 2)`` joint ranges [rad], canonical signs (a joint without a range:
            its servo's control range, else ±π).
        kp: ``(n,)`` servo stiffness [Nm/rad]; torque_limit: ``(n,)`` [Nm] (``inf``: none).
        total_mass: [kg]; torso_height: torso body height when standing [m];
        height: top of the model above the soles when standing [m].
        additions: what building the model adds to the file (:mod:`imitwalk.robots.build`).
        stand_ctrl: ``(nu,)`` every actuator's control in the standing posture (position
            servos hold their joint's angle), ``None``: zeros.
    """

    name: str
    mjcf: Path
    joint_names: tuple[str, ...]
    mj_joints: tuple[str, ...]
    signs: np.ndarray
    gyro: str
    accelerometer: str | None
    foot_force: dict[str, tuple[str, ...]]
    torso: str
    soles: dict[str, str]
    stand: np.ndarray
    stand_qpos: np.ndarray
    limits: np.ndarray
    kp: np.ndarray
    torque_limit: np.ndarray
    total_mass: float
    torso_height: float
    height: float
    sensors: tuple[str, ...] = field(default=())
    additions: Additions = field(default_factory=Additions)
    stand_ctrl: np.ndarray | None = None

    @property
    def dof(self) -> int:
        """Number of actuated joints ``n``."""
        return len(self.joint_names)

    def index(self, role: str) -> int:
        """Column of ``role`` in a ``(T, n)`` trajectory; unknown names list the valid ones."""
        try:
            return self.joint_names.index(role)
        except ValueError:
            raise unknown_name("joint", role, self.joint_names) from None

    def indices(self, roles: tuple[str, ...] | list[str]) -> np.ndarray:
        """Columns of several roles, ``(len(roles),)`` int."""
        return np.array([self.index(r) for r in roles], dtype=int)

    def compile(self) -> mujoco.MjModel:
        """A fresh :class:`mujoco.MjModel` of this robot (callers may modify it): the
        MJCF with :attr:`additions`."""
        return compile_model(self.mjcf, self.additions)

    def clip(self, q: np.ndarray) -> np.ndarray:
        """Clip ``(..., n)`` joint angles to the joint ranges [rad]."""
        return np.clip(q, self.limits[:, 0], self.limits[:, 1])

    @classmethod
    def from_map(cls, jmap: dict | JointMap, base: Path, mjcf: Path | None = None) -> Robot:
        """Validate a joint map against its MJCF and build the record.

        Args:
            jmap: parsed joint map (see :func:`load_joint_map`), or a checked one.
            base: folder that relative paths in the map are resolved against.
            mjcf: the MJCF file; defaults to the map's ``"mjcf"`` entry.
        """
        jm = jmap if isinstance(jmap, JointMap) else parse_joint_map(jmap)
        if mjcf is None:
            if jm.mjcf is None:
                raise RobotError("joint map names no 'mjcf' file and none was given")
            mjcf = Path(os.path.normpath(Path(base) / jm.mjcf))
        mjcf = Path(mjcf)
        add, res = plan_additions(jm, compile_model(mjcf), mjcf)
        model = compile_model(mjcf, add)
        return _build(cls, jm, res, mjcf, model, add)


def _build(
    cls: type[Robot], jm: JointMap, res: Resolved, mjcf: Path, model: mujoco.MjModel, add: Additions
) -> Robot:
    roles, mj_joints, signs = res.roles, res.joints, np.array(res.signs)
    root = int(model.body_rootid[model.body(res.torso).id])
    check_masses(model, mjcf, float(model.body_subtreemass[root]))
    data = _keyframe_data(model, jm.stand_keyframe)
    jid = np.array([model.joint(j).id for j in mj_joints])
    adr = model.jnt_qposadr[jid]
    _stand(model, data, jm, res, adr, signs, mjcf)
    acts = {
        int(model.actuator_trnid[a, 0]): a
        for a in range(model.nu)
        if model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT
    }
    kp, tl, limits = _servo_table(model, mj_joints, jid, acts, signs)
    ctrl = _stand_ctrl(model, data, acts)
    sole_z = min(_frame_pos(model, data, res.soles[s])[2] for s in SIDES)
    mass, height = float(model.body_subtreemass[root]), _top(model, data) - sole_z
    torso_z = float(data.xpos[model.body(res.torso).id][2] - sole_z)
    check_standing(
        mjcf, height=height, torso_height=torso_z, roles=roles, limits=limits, kp=np.array(kp)
    )
    return cls(
        name=jm.name or mjcf.stem,
        mjcf=mjcf,
        joint_names=roles,
        mj_joints=tuple(mj_joints),
        signs=signs,
        gyro=res.gyro,
        accelerometer=res.accelerometer,
        foot_force=res.foot_force,
        torso=res.torso,
        soles=res.soles,
        stand=data.qpos[adr] * signs,
        stand_qpos=data.qpos.copy(),
        limits=limits,
        kp=np.array(kp),
        torque_limit=np.array(tl),
        total_mass=mass,
        torso_height=torso_z,
        height=height,
        sensors=tuple(s for s in _names(model, mujoco.mjtObj.mjOBJ_SENSOR, model.nsensor) if s),
        additions=add,
        stand_ctrl=ctrl,
    )


def _keyframe_data(model: mujoco.MjModel, key: str | None) -> mujoco.MjData:
    """Fresh data of ``model``, at the keyframe ``key`` if one is named."""
    data = mujoco.MjData(model)
    if key is not None:
        keys = _names(model, mujoco.mjtObj.mjOBJ_KEY, model.nkey)
        if key not in keys:
            raise unknown_name("keyframe", key, keys)
        mujoco.mj_resetDataKeyframe(model, data, model.key(key).id)
    return data


def _stand(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    jm: JointMap,
    res: Resolved,
    adr: np.ndarray,
    signs: np.ndarray,
    mjcf: Path,
) -> None:
    """Put ``data`` in the standing posture: the map's angles [rad] at qpos ``adr`` ``(n,)``,
    lowered onto the floor unless it is the file's own keyframe; RobotError if not finite."""
    key = jm.stand_keyframe
    roles = res.roles
    for role, val in jm.stand.items():
        data.qpos[adr[roles.index(role)]] = val * signs[roles.index(role)]
    mujoco.mj_kinematics(model, data)
    if key is None or jm.stand:  # not the file's own posture: put it on the floor
        low = min(_frame_pos(model, data, res.soles[s])[2] for s in SIDES)
        data.qpos[2] -= low - SOLE_CLEARANCE
    mujoco.mj_forward(model, data)
    if not np.isfinite(data.qpos).all() or not np.isfinite(data.xpos).all():
        raise RobotError(f"{mjcf.name}: the standing posture is not finite")


def _servo_table(
    model: mujoco.MjModel,
    mj_joints: tuple[str, ...],
    jid: np.ndarray,
    acts: dict[int, int],
    signs: np.ndarray,
) -> tuple[list[float], list[float], np.ndarray]:
    """Each role joint's servo stiffness [Nm/rad], torque limit [Nm] and ``(n, 2)`` range
    [rad], canonical signs; RobotError if a joint has no position servo."""
    kp, tl, ranges = [], [], []
    for name, j in zip(mj_joints, jid, strict=True):
        a = acts.get(int(j))
        if a is None or actuator_kind(model, a) != "position":
            raise RobotError(f"joint {name!r} has no position servo; imitwalk needs one per joint")
        kp.append(float(model.actuator_gainprm[a, 0]))
        tl.append(torque_limit(model, a, int(j)))
        if model.jnt_limited[j]:
            ranges.append(model.jnt_range[j])
        elif model.actuator_ctrllimited[a]:
            ranges.append(model.actuator_ctrlrange[a])
        else:
            ranges.append((-np.pi, np.pi))
    limits = np.sort(np.array(ranges, dtype=float) * signs[:, None], axis=1)
    return kp, tl, limits


def _stand_ctrl(model: mujoco.MjModel, data: mujoco.MjData, acts: dict[int, int]) -> np.ndarray:
    """``(nu,)`` every actuator's control in the posture of ``data``: each position servo
    holds its joint's angle (within its control range), others 0."""
    ctrl = np.zeros(model.nu)
    for j, a in acts.items():
        if actuator_kind(model, a) == "position":
            lo, hi = (
                model.actuator_ctrlrange[a] if model.actuator_ctrllimited[a] else (-np.inf, np.inf)
            )
            ctrl[a] = np.clip(data.qpos[model.jnt_qposadr[j]], lo, hi)
    return ctrl


def _frame_pos(model: mujoco.MjModel, data: mujoco.MjData, name: str) -> np.ndarray:
    if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, name) >= 0:
        return data.site_xpos[model.site(name).id]
    return data.xpos[model.body(name).id]


def _top(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    """Highest point of any non-world geometry [m] (geom bounding boxes)."""
    top = -np.inf
    for g in range(model.ngeom):
        if model.geom_bodyid[g] == 0:
            continue
        half = model.geom_aabb[g, 3:]
        centre = data.geom_xpos[g] + data.geom_xmat[g].reshape(3, 3) @ model.geom_aabb[g, :3]
        reach = np.abs(data.geom_xmat[g].reshape(3, 3)) @ half
        top = max(top, float(centre[2] + reach[2]))
    return top
