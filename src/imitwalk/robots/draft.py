"""``imitwalk robot import``: draft a joint map from a user's MJCF.

:func:`draft_joint_map` reads the file (never writing to it), guesses each role from
the kinematic tree (:mod:`imitwalk.robots.roles`), the soles from the feet's collision
geoms, the sensors the file already has on the torso and the feet, and the standing
posture: the file's keyframe if it has one, else a solved one (:mod:`imitwalk.robots.posture`).
It then builds the robot from the draft. Drafting simulates nothing: ``robot import``
holds the drafted posture for :data:`imitwalk.sim.standing.CHECK_SECONDS` with the stand
check of :mod:`imitwalk.sim.standing` (the one ``robot stand`` and ``learn`` use). A robot
that does not stand is still drafted: the joint map is what the user edits to make it
stand (its ``servos``, ``stand_keyframe``/``stand``, ``soles``). Each guess, and each thing
it could not guess, is one line of :attr:`Draft.lines`.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from imitwalk.errors import RobotError
from imitwalk.robots.build import FSR_LAYOUT, compile_model
from imitwalk.robots.jointmap import parse_joint_map
from imitwalk.robots.roles import guess_roles
from imitwalk.robots.servos import actuator_kind
from imitwalk.robots.spec import LEG_ROLES, ROLES, Robot
from imitwalk.robots.tree import Tree, footprint

__all__ = ["Draft", "draft_joint_map"]

_KEY_HINTS = ("stand", "home", "default", "init")


@dataclass(frozen=True)
class Draft:
    """A drafted joint map: ``jmap`` (the JSON object), ``lines`` (one per guess and per
    thing not guessed) and ``robot`` (built from it)."""

    jmap: dict
    lines: tuple[str, ...]
    robot: Robot


def _sole(tree: Tree, body: int, bodies: list[int]) -> dict | str:
    """The sole under ``bodies`` as a joint map entry: a site the file has at its centre
    (within a hundredth of the foot's length), else a site to add on ``body``."""
    fp = footprint(tree.model, tree.data, bodies)
    m, d = tree.model, tree.data
    near = [i for i in range(m.nsite) if m.site_bodyid[i] in bodies and m.site(i).name]
    near = [i for i in near if np.linalg.norm(d.site_xpos[i] - fp.centre) < 0.02 * fp.half[0]]
    if near:
        return m.site(near[0]).name
    rot = tree.data.xmat[body].reshape(3, 3)
    pos = rot.T @ (fp.centre - tree.data.xpos[body])
    quat = np.zeros(4)
    mujoco.mju_negQuat(quat, tree.data.xquat[body])  # the sole frame: level, facing +x
    out = {"body": tree.name(body), "pos": [round(float(x), 5) + 0.0 for x in pos]}
    out["size"] = [round(float(x), 5) + 0.0 for x in fp.half]
    if not np.allclose(quat, [1.0, 0.0, 0.0, 0.0], atol=1e-9):
        out["quat"] = [round(float(x), 6) + 0.0 for x in quat]
    return out


def _on(model: mujoco.MjModel, sensor: int) -> int | None:
    """The body a site sensor sits on."""
    if model.sensor_objtype[sensor] != mujoco.mjtObj.mjOBJ_SITE:
        return None
    return int(model.site_bodyid[model.sensor_objid[sensor]])


def _sensors(tree: Tree, torso: int, feet: dict, lines: list[str]) -> dict:
    """Gyro, accelerometer and foot sensors the file has on the torso and the feet."""
    m, out = tree.model, {}
    kinds = {"gyro": mujoco.mjtSensor.mjSENS_GYRO, "accel": mujoco.mjtSensor.mjSENS_ACCELEROMETER}
    on = {
        k: [i for i in range(m.nsensor) if m.sensor_type[i] == t and _on(m, i) == torso]
        for k, t in kinds.items()
    }
    tname = tree.name(torso)
    if on["gyro"]:
        gyro = on["gyro"][0]
        out["gyro"] = m.sensor(gyro).name
        lines.append(f"guessed gyro: {out['gyro']} (on the torso {tname})")
        same = [i for i in on["accel"] if m.sensor_objid[i] == m.sensor_objid[gyro]]
        if same or on["accel"]:
            out["accelerometer"] = m.sensor((same or on["accel"])[0]).name
            lines.append(f"guessed accelerometer: {out['accelerometer']}")
        else:
            lines.append("no accelerometer on the torso: one is added at the gyro when built")
    else:
        lines.append(f"no gyro on the torso {tname}: an IMU (gyro, accelerometer) is added")
    touch = mujoco.mjtSensor.mjSENS_TOUCH
    found = {}
    for side, (_, bodies) in feet.items():
        ids = [i for i in range(m.nsensor) if m.sensor_type[i] == touch and _on(m, i) in bodies]
        if len(ids) == 4:  # front-left, front-right, rear-left, rear-right
            pos = {i: tree.data.site_xpos[m.sensor_objid[i]] for i in ids}
            ids = sorted(ids, key=lambda i: (-round(pos[i][0], 4), -pos[i][1]))
        found[side] = [m.sensor(i).name for i in ids]
    if found["l"] and found["r"]:
        out["foot_force"] = found
        lines.append(f"guessed foot force sensors: {found}")
    else:
        lines.append(
            f"no foot sensors: 4 touch sensors ({', '.join(FSR_LAYOUT)}) are added per sole"
        )
    return out


def _keyframe(model: mujoco.MjModel) -> str | None:
    keys = [model.key(k).name for k in range(model.nkey) if model.key(k).name]
    for hint in _KEY_HINTS:
        for k in keys:
            if hint in k.lower():
                return k
    return keys[0] if keys else None


def draft_joint_map(mjcf: str | Path, out: str | Path) -> Draft:
    """Draft the joint map of ``mjcf``, to be written at ``out`` (its ``mjcf`` entry is
    relative to ``out``'s folder).

    Raises:
        RobotError: no floating base; no legs (the bodies seen are listed); a leg role
            that cannot be guessed.
    """
    from imitwalk.robots.posture import solve_stand

    mjcf, out = Path(mjcf), Path(out)
    model = compile_model(mjcf)
    tree = Tree(model, mjcf.name)
    sk = guess_roles(tree, mjcf.name)
    lines = [f"guessed {g.role}: {g.joint} (sign {g.sign:+.0f}; {g.note})" for g in sk.guesses]
    lines += [f"could not guess {x}" for x in sk.missed]
    if sk.unmapped:
        lines.append(f"no role (held at the standing posture): {', '.join(sk.unmapped)}")
    roles = {g.role: g for g in sk.guesses}
    if missing := [r for r in LEG_ROLES if r not in roles]:
        raise RobotError(f"{mjcf.name}: could not guess leg roles {', '.join(missing)}")
    joints = {
        r: roles[r].joint if roles[r].sign > 0 else {"joint": roles[r].joint, "sign": -1}
        for r in ROLES
        if r in roles
    }
    rel = os.path.relpath(mjcf.resolve(), out.resolve().parent)
    jmap: dict[str, object] = {"name": mjcf.stem, "mjcf": rel, "joints": joints}
    jmap["torso"] = tree.name(sk.torso)
    lines.append(f"guessed torso: {jmap['torso']}")
    jmap["soles"] = soles = {s: _sole(tree, *sk.feet[s]) for s in ("l", "r")}
    for s in ("l", "r"):
        e = soles[s]
        if isinstance(e, str):
            lines.append(f"guessed {s} sole: the site {e} (at the centre of the foot's geoms)")
            continue
        lines.append(
            f"guessed {s} sole: {e['size'][0] * 2:.3f} x {e['size'][1] * 2:.3f} m "
            f"under {e['body']} (from its collision geoms)"
        )
    jmap.update(_sensors(tree, sk.torso, sk.feet, lines))
    acts = {int(model.actuator_trnid[a, 0]): a for a in range(model.nu)}
    kinds = {g.joint: acts.get(model.joint(g.joint).id) for g in sk.guesses}
    motors = [j for j, a in kinds.items() if a is None or actuator_kind(model, a) != "position"]
    if motors:
        lines.append(f"position servos are added (gains from the mass) for: {', '.join(motors)}")
    key = _keyframe(model)
    if key is not None:
        jmap["stand_keyframe"] = key
        lines.append(f"guessed standing posture: the file's keyframe {key!r}")
    robot = Robot.from_map(parse_joint_map(jmap, str(out)), out.parent, mjcf=mjcf)
    if key is None:
        arms = {s: tree.name(b) for s, b in sk.arm_ends.items()}
        jmap["stand"] = solve_stand(robot, arms)
        robot = Robot.from_map(parse_joint_map(jmap, str(out)), out.parent, mjcf=mjcf)
        lines.append("solved standing posture: knees bent, feet flat, centre of mass over them")
    return Draft(jmap, tuple(lines), robot)
