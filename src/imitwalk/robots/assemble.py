"""What a robot's model lacks, from its joint map: the :class:`~imitwalk.robots.build.Additions`.

:func:`plan_additions` checks every name of a :class:`~imitwalk.robots.jointmap.JointMap`
against the user's own model and decides what to add when the model is built: a floor
if the file has none (and, for rendering, a light from above and a sky), the joint map's
sole sites, four touch sensors under each sole if the map names no foot sensors, an IMU
on the torso if it names no gyro (an accelerometer at the gyro if it names none), and
position servos where a joint has a motor actuator or none (:mod:`imitwalk.robots.servos`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from imitwalk.errors import RobotError, unknown_name
from imitwalk.robots.build import FSR_LAYOUT, Additions, ServoGains, TouchPads, free_name
from imitwalk.robots.jointmap import JointMap, SoleSpec
from imitwalk.robots.servos import KV_PER_KP, actuator_kind, default_gains, torque_limit
from imitwalk.robots.tree import Tree, footprint

__all__ = ["Resolved", "plan_additions"]


@dataclass(frozen=True)
class Resolved:
    """The joint map's names as they will be in the built model.

    ``roles`` in canonical order with their MJCF ``joints`` and ``signs``; ``gyro``,
    ``accelerometer`` (or ``None``), ``foot_force`` per side, ``torso`` and ``soles``
    (site or body names) per side.
    """

    roles: tuple[str, ...]
    joints: tuple[str, ...]
    signs: tuple[float, ...]
    gyro: str
    accelerometer: str | None
    foot_force: dict[str, tuple[str, ...]]
    torso: str
    soles: dict[str, str]


def _names(model: mujoco.MjModel, objtype: mujoco.mjtObj, count: int) -> list[str]:
    try:
        return [mujoco.mj_id2name(model, objtype, i) or "" for i in range(count)]
    except UnicodeDecodeError:
        raise RobotError("the model has a name that is not UTF-8 text") from None


def _actuators(model: mujoco.MjModel) -> dict[int, int]:
    """Joint id -> the (last) actuator that drives it."""
    return {
        int(model.actuator_trnid[a, 0]): a
        for a in range(model.nu)
        if model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT
    }


def _ctrlrange(model: mujoco.MjModel, j: int) -> tuple[float, float]:
    if model.jnt_limited[j]:
        lo, hi = model.jnt_range[j]
        return float(lo), float(hi)
    return -math.pi, math.pi


def _servos(
    jm: JointMap,
    model: mujoco.MjModel,
    roles: tuple[str, ...],
    joints: tuple[str, ...],
    tree: Tree,
) -> tuple[ServoGains, ...]:
    """Servos for role joints with a motor or no actuator, or named in ``servos``; and for
    other hinges with a motor (held at the standing posture)."""
    acts = _actuators(model)
    mass = float(model.body_subtreemass[tree.root])
    j = {r: model.joint(n).id for r, n in zip(roles, joints, strict=True)}
    leg = float(np.linalg.norm(tree.anchor(j["l_hip_pitch"]) - tree.anchor(j["l_ankle_pitch"])))
    g = float(np.linalg.norm(model.opt.gravity)) or 9.81
    out = []
    role_of = {model.joint(n).id: r for r, n in zip(roles, joints, strict=True)}
    for jid in tree.hinges(tree.subtree(tree.root)):
        role = role_of.get(jid)
        a = acts.get(jid)
        kind = "none" if a is None else actuator_kind(model, a)
        is_leg = role is not None and role[2:5] in ("hip", "kne", "ank")
        own = {} if role is None else jm.servos.get(role, {})
        given = {**jm.servos.get("legs" if is_leg else "upper", {}), **own}
        if role is None and kind != "motor":
            continue
        if kind == "other":
            name = model.joint(jid).name
            raise RobotError(
                f"joint {name!r} (role {role}) has an actuator that is neither a position "
                "servo nor a motor; give it a <position> actuator"
            )
        if kind == "position" and not given:
            continue
        kp, _, limit = default_gains(is_leg, mass, leg, g)
        mine = torque_limit(model, a, jid)
        limit = mine if math.isfinite(mine) else limit
        kp = given.get("kp", kp)
        kv = given.get("kv", KV_PER_KP * kp)
        limit = given.get("torque_limit", limit)
        name = model.joint(jid).name
        out.append(ServoGains(name, float(kp), float(kv), float(limit), _ctrlrange(model, jid)))
    return tuple(out)


def _sole_pads(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    tree: Tree,
    side: str,
    sole: str | SoleSpec,
    names: tuple[str, str, str, str],
) -> TouchPads:
    """Touch pads under the sole ``sole`` (a SoleSpec, a site or a body name)."""
    if isinstance(sole, SoleSpec):
        return TouchPads(sole.body, sole.pos, sole.quat, sole.size, names)
    sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, sole)
    body = int(model.site_bodyid[sid]) if sid >= 0 else model.body(sole).id
    pos = tuple(model.site_pos[sid]) if sid >= 0 else (0.0, 0.0, 0.0)
    quat = tuple(model.site_quat[sid]) if sid >= 0 else (1.0, 0.0, 0.0, 0.0)
    hx, hy = footprint(model, data, tree.subtree(body)).half  # (2,) [m]
    return TouchPads(model.body(body).name, pos, quat, (float(hx), float(hy)), names)


@dataclass(frozen=True)
class _Imu:
    """The gyro the robot reads and its site; ``added_site`` ``(body, site, pos, quat)`` and
    ``added_gyro`` ``(sensor, site)`` when they are to be added (``None``: the file's own)."""

    gyro: str
    site: str
    added_site: tuple[str, str, tuple, tuple] | None
    added_gyro: tuple[str, str] | None


def _check_joints(jm: JointMap, model: mujoco.MjModel, joints_all: list[str]) -> None:
    """Every role's joint is a hinge of ``model``; else RobotError."""
    for role, (name, _) in jm.joints.items():
        if name not in joints_all:
            raise unknown_name("joint", name, [j for j in joints_all if j])
        if model.jnt_type[model.joint(name).id] != mujoco.mjtJoint.mjJNT_HINGE:
            raise RobotError(f"joint {name!r} (role {role}) is not a hinge joint")


def _soles(
    jm: JointMap, bodies: list[str], sites: list[str]
) -> tuple[dict[str, str], list[tuple[str, SoleSpec]], set[str]]:
    """Each side's sole site (or body) name, the sole sites to add, and the site names
    taken once they are added."""
    taken = set(sites)
    soles, added_soles = {}, []
    for side, sole in jm.soles.items():
        if isinstance(sole, SoleSpec):
            if sole.body not in bodies:
                raise unknown_name(f"{side} sole body", sole.body, [b for b in bodies if b])
            soles[side] = free_name(taken, f"{side}_sole")
            taken.add(soles[side])
            added_soles.append((soles[side], sole))
        elif sole in sites or sole in bodies:
            soles[side] = sole
        else:
            raise unknown_name(f"{side} sole site", sole, [x for x in sites if x])
    return soles, added_soles, taken


def _imu(
    jm: JointMap,
    model: mujoco.MjModel,
    tree: Tree,
    mjcf: Path,
    torso: str,
    sensors: list[str],
    sites: list[str],
    taken: set[str],
) -> _Imu:
    """The joint map's gyro (checked), or an IMU to add on the ``torso``, level with the
    world at the zero posture, its site named apart from ``taken``."""
    gyros = [
        s for i, s in enumerate(sensors) if model.sensor_type[i] == mujoco.mjtSensor.mjSENS_GYRO
    ]
    if jm.gyro is not None:
        if not gyros:
            raise RobotError(
                f"{mjcf.name} has no gyro sensor {jm.gyro!r}; leave 'gyro' out of the "
                "joint map to have an IMU added on the torso"
            )
        if jm.gyro not in gyros:
            raise unknown_name("gyro sensor", jm.gyro, gyros)
        imu_site = sites[int(model.sensor_objid[model.sensor(jm.gyro).id])]
        return _Imu(jm.gyro, imu_site, None, None)
    d = tree.data
    tb = model.body(torso).id
    quat = np.zeros(4)
    mujoco.mju_negQuat(quat, d.xquat[tb])  # level with the world at the zero posture
    imu_site = free_name(taken, "imu")
    imu = (torso, imu_site, tuple(model.body_ipos[tb]), tuple(quat))
    gyro = free_name(set(sensors), "imu_gyro")
    return _Imu(gyro, imu_site, imu, (gyro, imu_site))


def _accelerometer(
    jm: JointMap, sensors: list[str], gyro: str, imu_site: str
) -> tuple[str | None, tuple[str, str] | None]:
    """The accelerometer the robot reads (``None``: none), and ``(sensor, site)`` if it is
    to be added at the IMU's site."""
    accel = accel_add = None
    if jm.accelerometer is not None:
        if jm.accelerometer not in sensors:
            raise unknown_name("sensor", jm.accelerometer, [s for s in sensors if s])
        accel = jm.accelerometer
    elif jm.add_accelerometer:
        accel = free_name(set(sensors) | {gyro}, "imu_accel")
        accel_add = (accel, imu_site)
    return accel, accel_add


def _foot_force(
    jm: JointMap,
    model: mujoco.MjModel,
    tree: Tree,
    sensors: list[str],
    taken: set[str | None],
) -> tuple[dict[str, tuple[str, ...]], list[TouchPads]]:
    """The foot sensors per side: the joint map's (checked), or touch pads to add under
    each sole, named apart from ``taken``."""
    pads = []
    if jm.foot_force is not None:
        foot_force = jm.foot_force
        for name in foot_force["l"] + foot_force["r"]:
            if name not in sensors:
                raise unknown_name("sensor", name, [s for s in sensors if s])
    else:
        used = set(taken)
        foot_force = {}
        for side in ("l", "r"):
            names = tuple(free_name(used, f"{side}_fsr_{q}") for q in FSR_LAYOUT)
            used |= set(names)
            foot_force[side] = names
            # one name per entry of FSR_LAYOUT (4), which mypy cannot see through tuple()
            pads.append(_sole_pads(model, tree.data, tree, side, jm.soles[side], names))  # type: ignore[arg-type]
    return foot_force, pads


def plan_additions(jm: JointMap, model: mujoco.MjModel, mjcf: Path) -> tuple[Additions, Resolved]:
    """Check ``jm``'s names against ``model`` (the user's file compiled as it is) and
    list what building the robot adds.

    Raises:
        RobotError: an unknown joint, sensor, body or site (the message lists the valid
            ones), a role joint that is not a hinge, no floating base.
    """
    tree = Tree(model, mjcf.name)
    joints_all = _names(model, mujoco.mjtObj.mjOBJ_JOINT, model.njnt)
    sensors = _names(model, mujoco.mjtObj.mjOBJ_SENSOR, model.nsensor)
    bodies = _names(model, mujoco.mjtObj.mjOBJ_BODY, model.nbody)
    sites = _names(model, mujoco.mjtObj.mjOBJ_SITE, model.nsite)
    roles = tuple(jm.joints)
    _check_joints(jm, model, joints_all)
    joints = tuple(jm.joints[r][0] for r in roles)
    signs = tuple(jm.joints[r][1] for r in roles)
    torso = jm.torso or tree.name(tree.root)
    if torso not in bodies:
        raise unknown_name("torso body", torso, [b for b in bodies if b])
    soles, added_soles, taken = _soles(jm, bodies, sites)
    imu = _imu(jm, model, tree, mjcf, torso, sensors, sites, taken)
    taken.add(imu.site)  # already there if it is the file's own
    gyro = imu.gyro
    accel, accel_add = _accelerometer(jm, sensors, gyro, imu.site)
    foot_force, pads = _foot_force(jm, model, tree, sensors, set(sensors) | {gyro, accel} | taken)
    floor = not any(
        model.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE and model.geom_bodyid[g] == 0
        for g in range(model.ngeom)
    )
    add = Additions(
        floor=floor,
        light=not (model.light_type == mujoco.mjtLightType.mjLIGHT_DIRECTIONAL).any(),
        sky=not (model.tex_type == mujoco.mjtTexture.mjTEXTURE_SKYBOX).any(),
        soles=tuple(added_soles),
        pads=tuple(pads),
        imu=imu.added_site,
        gyro=imu.added_gyro,
        accelerometer=accel_add,
        servos=_servos(jm, model, roles, joints, tree),
    )
    res = Resolved(roles, joints, signs, gyro, accel, foot_force, torso, soles)
    return add, res
