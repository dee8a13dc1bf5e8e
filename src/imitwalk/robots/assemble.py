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
    for role, (name, _) in jm.joints.items():
        if name not in joints_all:
            raise unknown_name("joint", name, [j for j in joints_all if j])
        if model.jnt_type[model.joint(name).id] != mujoco.mjtJoint.mjJNT_HINGE:
            raise RobotError(f"joint {name!r} (role {role}) is not a hinge joint")
    joints = tuple(jm.joints[r][0] for r in roles)
    signs = tuple(jm.joints[r][1] for r in roles)
    torso = jm.torso or tree.name(tree.root)
    if torso not in bodies:
        raise unknown_name("torso body", torso, [b for b in bodies if b])
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
    gyros = [
        s for i, s in enumerate(sensors) if model.sensor_type[i] == mujoco.mjtSensor.mjSENS_GYRO
    ]
    imu = gyro_add = None
    if jm.gyro is not None:
        if not gyros:
            raise RobotError(
                f"{mjcf.name} has no gyro sensor {jm.gyro!r}; leave 'gyro' out of the "
                "joint map to have an IMU added on the torso"
            )
        if jm.gyro not in gyros:
            raise unknown_name("gyro sensor", jm.gyro, gyros)
        imu_site = sites[int(model.sensor_objid[model.sensor(jm.gyro).id])]
        gyro = jm.gyro
    else:
        d = tree.data
        tb = model.body(torso).id
        quat = np.zeros(4)
        mujoco.mju_negQuat(quat, d.xquat[tb])  # level with the world at the zero posture
        imu_site = free_name(taken, "imu")
        taken.add(imu_site)
        imu = (torso, imu_site, tuple(model.body_ipos[tb]), tuple(quat))
        gyro = free_name(set(sensors), "imu_gyro")
        gyro_add = (gyro, imu_site)
    accel = accel_add = None
    if jm.accelerometer is not None:
        if jm.accelerometer not in sensors:
            raise unknown_name("sensor", jm.accelerometer, [s for s in sensors if s])
        accel = jm.accelerometer
    elif jm.add_accelerometer:
        accel = free_name(set(sensors) | {gyro}, "imu_accel")
        accel_add = (accel, imu_site)
    pads = []
    if jm.foot_force is not None:
        foot_force = jm.foot_force
        for name in foot_force["l"] + foot_force["r"]:
            if name not in sensors:
                raise unknown_name("sensor", name, [s for s in sensors if s])
    else:
        used = set(sensors) | {gyro, accel} | taken
        foot_force = {}
        for side in ("l", "r"):
            names = tuple(free_name(used, f"{side}_fsr_{q}") for q in FSR_LAYOUT)
            used |= set(names)
            foot_force[side] = names
            # one name per entry of FSR_LAYOUT (4), which mypy cannot see through tuple()
            pads.append(_sole_pads(model, tree.data, tree, side, jm.soles[side], names))  # type: ignore[arg-type]
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
        imu=imu,
        gyro=gyro_add,
        accelerometer=accel_add,
        servos=_servos(jm, model, roles, joints, tree),
    )
    res = Resolved(roles, joints, signs, gyro, accel, foot_force, torso, soles)
    return add, res
