"""Robot description: which MJCF joints play which role, and which sensors to read.

A robot is an MJCF file plus a *joint map* (JSON) naming, for each canonical role
in :data:`ROLES`, the model's hinge joint that plays it; the gyro (required), the
accelerometer, the foot force sensors, the torso body and the two sole frames.
The built-in ``hoap2`` is loaded through exactly the same path as a user's robot.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

from imitwalk.errors import RobotError, unknown_name

__all__ = ["ARM_ROLES", "LEG_ROLES", "ROLES", "TRUNK_ROLES", "Robot", "load_joint_map"]

_SIDES = ("l", "r")
_LEG = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
_ARM = ("shoulder_pitch", "shoulder_roll", "arm_yaw", "elbow", "hand")
#: Leg roles, per side: yaw about +z, roll about +x, pitch about +y (right-hand rule,
#: x forward, y left, z up); knee flexion positive.
LEG_ROLES: tuple[str, ...] = tuple(f"{s}_{j}" for s in _SIDES for j in _LEG)
#: Arm roles, per side; zero hangs the arm straight down.
ARM_ROLES: tuple[str, ...] = tuple(f"{s}_{j}" for s in _SIDES for j in _ARM)
TRUNK_ROLES: tuple[str, ...] = ("waist_yaw", "neck_yaw", "neck_pitch")
#: Every canonical role, in the order trajectories use.
ROLES: tuple[str, ...] = LEG_ROLES + ARM_ROLES + TRUNK_ROLES

_MAP_KEYS = (
    "name",
    "mjcf",
    "joints",
    "gyro",
    "accelerometer",
    "foot_force",
    "torso",
    "soles",
    "stand_keyframe",
    "stand",
)


def load_joint_map(path: str | Path) -> dict:
    """Read a joint-map JSON file; one-line :class:`RobotError` if it is not valid JSON."""
    path = Path(path)
    if not path.is_file():
        raise RobotError(f"joint map not found: {path}")
    try:
        data = json.loads(path.read_text())
    except json.JSONDecodeError as exc:
        raise RobotError(
            f"joint map {path} is not valid JSON: {exc.msg} (line {exc.lineno})"
        ) from None
    if not isinstance(data, dict):
        raise RobotError(f"joint map {path} must be a JSON object")
    for key in data:
        if key not in _MAP_KEYS:
            raise unknown_name("joint-map key", key, _MAP_KEYS)
    return data


def _compile(mjcf: Path) -> mujoco.MjModel:
    if not mjcf.is_file():
        raise RobotError(f"robot file not found: {mjcf}")
    try:
        return mujoco.MjModel.from_xml_path(str(mjcf))
    except ValueError as exc:
        first = " ".join(str(exc).split())
        raise RobotError(f"{mjcf} is not valid MJCF: {first}") from None


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
        limits: ``(n, 2)`` joint ranges [rad], canonical signs.
        kp: ``(n,)`` servo stiffness [Nm/rad]; torque_limit: ``(n,)`` [Nm].
        total_mass: [kg]; torso_height: torso body height when standing [m];
        height: top of the model above the soles when standing [m].
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
        """A fresh :class:`mujoco.MjModel` of this robot (callers may modify it)."""
        return _compile(self.mjcf)

    def clip(self, q: np.ndarray) -> np.ndarray:
        """Clip ``(..., n)`` joint angles to the joint ranges [rad]."""
        return np.clip(q, self.limits[:, 0], self.limits[:, 1])

    @classmethod
    def from_map(cls, jmap: dict, base: Path, mjcf: Path | None = None) -> Robot:
        """Validate a joint map against its MJCF and build the record.

        Args:
            jmap: parsed joint map (see :func:`load_joint_map`).
            base: folder that relative paths in the map are resolved against.
            mjcf: the MJCF file; defaults to the map's ``"mjcf"`` entry.
        """
        if mjcf is None:
            if "mjcf" not in jmap:
                raise RobotError("joint map names no 'mjcf' file and none was given")
            mjcf = base / jmap["mjcf"]
        mjcf = Path(mjcf)
        model = _compile(mjcf)
        return _build(cls, jmap, mjcf, model)


def _build(cls: type[Robot], jmap: dict, mjcf: Path, model: mujoco.MjModel) -> Robot:
    joints_all = _names(model, mujoco.mjtObj.mjOBJ_JOINT, model.njnt)
    sensors_all = _names(model, mujoco.mjtObj.mjOBJ_SENSOR, model.nsensor)
    bodies = _names(model, mujoco.mjtObj.mjOBJ_BODY, model.nbody)
    sites = _names(model, mujoco.mjtObj.mjOBJ_SITE, model.nsite)

    jm = jmap.get("joints")
    if not isinstance(jm, dict) or not jm:
        raise RobotError("joint map has no 'joints' object (role -> MJCF joint name)")
    for role in jm:
        if role not in ROLES:
            raise unknown_name("joint role", role, ROLES)
    missing = [r for r in LEG_ROLES if r not in jm]
    if missing:
        raise RobotError(f"joint map lacks leg roles: {', '.join(missing)}")
    roles = tuple(r for r in ROLES if r in jm)
    mj_joints, signs = [], []
    for role in roles:
        entry = jm[role]
        name, sign = (
            (entry, 1.0) if isinstance(entry, str) else (entry.get("joint"), entry.get("sign", 1.0))
        )
        if name not in joints_all:
            raise unknown_name("joint", str(name), [j for j in joints_all if j])
        jid = model.joint(name).id
        if model.jnt_type[jid] != mujoco.mjtJoint.mjJNT_HINGE:
            raise RobotError(f"joint {name!r} (role {role}) is not a hinge joint")
        if sign not in (1, -1, 1.0, -1.0):
            raise RobotError(f"sign of role {role} must be 1 or -1, got {sign!r}")
        mj_joints.append(name)
        signs.append(float(sign))
    signs_a = np.array(signs)

    gyro = jmap.get("gyro")
    gyros = [
        s for i, s in enumerate(sensors_all) if model.sensor_type[i] == mujoco.mjtSensor.mjSENS_GYRO
    ]
    if not gyros:
        raise RobotError(f"{mjcf.name} has no gyro sensor; add <gyro site=.../> on the torso")
    if gyro is None:
        raise RobotError(
            f"joint map names no 'gyro'; gyro sensors in the model: {', '.join(gyros)}"
        )
    if gyro not in gyros:
        raise unknown_name("gyro sensor", str(gyro), gyros)
    accel = jmap.get("accelerometer")
    if accel is not None and accel not in sensors_all:
        raise unknown_name("sensor", str(accel), sensors_all)
    ff = {s: tuple(jmap.get("foot_force", {}).get(s, ())) for s in _SIDES}
    for name in ff["l"] + ff["r"]:
        if name not in sensors_all:
            raise unknown_name("sensor", name, sensors_all)
    torso = jmap.get("torso")
    if torso not in bodies:
        raise unknown_name("torso body", str(torso), [b for b in bodies if b])
    soles = jmap.get("soles", {})
    for s in _SIDES:
        if soles.get(s) not in sites and soles.get(s) not in bodies:
            raise unknown_name(f"{s} sole site", str(soles.get(s)), [x for x in sites if x])

    data = mujoco.MjData(model)
    key = jmap.get("stand_keyframe")
    if key is not None:
        keys = _names(model, mujoco.mjtObj.mjOBJ_KEY, model.nkey)
        if key not in keys:
            raise unknown_name("keyframe", str(key), keys)
        mujoco.mj_resetDataKeyframe(model, data, model.key(key).id)
    adr = np.array([model.jnt_qposadr[model.joint(j).id] for j in mj_joints])
    if "stand" in jmap:
        for role, val in jmap["stand"].items():
            data.qpos[adr[roles.index(role) if role in roles else _bad_role(role, roles)]] = (
                float(val) * signs_a[roles.index(role)]
            )
    mujoco.mj_forward(model, data)
    ranges = np.array([model.jnt_range[model.joint(j).id] for j in mj_joints])
    limits = np.sort(ranges * signs_a[:, None], axis=1)
    act_for = {int(model.actuator_trnid[a, 0]): a for a in range(model.nu)}
    kp, tl = [], []
    for j in mj_joints:
        a = act_for.get(model.joint(j).id)
        if a is None:
            raise RobotError(
                f"joint {j!r} has no actuator; imitwalk needs a position servo per joint"
            )
        kp.append(float(model.actuator_gainprm[a, 0]))
        lim = model.actuator_forcerange[a]
        tl.append(float(lim[1]) if model.actuator_forcelimited[a] else float("inf"))
    root = int(model.body_rootid[model.body(torso).id])
    sole_z = min(_frame_pos(model, data, soles[s])[2] for s in _SIDES)
    return cls(
        name=str(jmap.get("name", mjcf.stem)),
        mjcf=mjcf,
        joint_names=roles,
        mj_joints=tuple(mj_joints),
        signs=signs_a,
        gyro=gyro,
        accelerometer=accel,
        foot_force=ff,
        torso=torso,
        soles={s: soles[s] for s in _SIDES},
        stand=data.qpos[adr] * signs_a,
        stand_qpos=data.qpos.copy(),
        limits=limits,
        kp=np.array(kp),
        torque_limit=np.array(tl),
        total_mass=float(model.body_subtreemass[root]),
        torso_height=float(data.xpos[model.body(torso).id][2] - sole_z),
        height=_top(model, data) - sole_z,
        sensors=tuple(s for s in sensors_all if s),
    )


def _bad_role(role: str, roles: tuple[str, ...]) -> int:
    raise unknown_name("joint role in 'stand'", role, roles)


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
