"""The joint map: a JSON file that says which MJCF parts play which role (pure Python).

:func:`load_joint_map` reads the file; :func:`parse_joint_map` checks every field's type
and value and returns a typed :class:`JointMap`. Names are checked against the model
later (:mod:`imitwalk.robots.spec`); here only the JSON itself is judged. Every refusal is
one :class:`~imitwalk.errors.RobotError` line naming the file, the field and what was
expected.

Fields (only ``joints`` and ``soles`` are required):

* ``name``: the robot's name (default: the MJCF file's stem); ``mjcf``: the MJCF file,
  relative to the joint map's folder.
* ``joints``: role (:data:`imitwalk.robots.spec.ROLES`) → MJCF hinge joint name, or
  ``{"joint": name, "sign": -1}`` where positive canonical angles are negative MJCF ones.
* ``gyro``, ``accelerometer``: sensor names. Left out, imitwalk adds an IMU site with a
  gyro and an accelerometer on the torso when it builds the model; ``null`` for the
  accelerometer: none.
* ``foot_force``: ``{"l": [names], "r": [names]}`` touch or force sensors under each
  sole. Left out, imitwalk adds four touch sensors under each sole, laid out front-left,
  front-right, rear-left, rear-right.
* ``torso``: the body whose height and tilt define a fall (default: the floating base).
* ``soles``: per side ``"l"``/``"r"``, a site or body at the centre of the sole, or
  ``{"body": name, "pos": [x, y, z], "size": [half length, half width]}`` (and an optional
  ``"quat"``): a sole site imitwalk adds to that body, in its frame [m].
* ``stand_keyframe``: the MJCF keyframe of the standing posture; ``stand``: role → angle
  [rad] (canonical signs) set on top of it.
* ``servos``: role, ``"legs"`` or ``"upper"`` → ``{"kp": Nm/rad, "kv": Nm s/rad,
  "torque_limit": Nm}``: the position servo imitwalk gives those joints (motor actuators,
  joints without one, or any joint named here).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Final, NoReturn, Required, TypedDict

from imitwalk.errors import RobotError, unknown_name
from imitwalk.robots.rolenames import LEG_ROLES, ROLES

__all__ = ["MAP_KEYS", "SERVO_GROUPS", "JointMap", "SoleSpec", "load_joint_map", "parse_joint_map"]

MAP_KEYS = (
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
    "servos",
)
#: Keys of ``servos`` besides role names: every leg role, every other role.
SERVO_GROUPS = ("legs", "upper")
_SERVO_KEYS = ("kp", "kv", "torque_limit")
_SIDES = ("l", "r")
_KINDS: dict[type, str] = {list: "a list", dict: "an object"}
_NAME_KEYS: Final = ("name", "mjcf", "gyro", "torso", "stand_keyframe")  # str-valued fields


@dataclass(frozen=True)
class SoleSpec:
    """A sole site to add: ``body`` it sits on, ``pos`` ``(3,)`` in the body frame [m],
    ``size`` ``(2,)`` half length and half width [m], ``quat`` ``(4,)`` (w, x, y, z) of the
    sole frame in the body frame (x forward, z up out of the sole)."""

    body: str
    pos: tuple[float, float, float]
    size: tuple[float, float]
    quat: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)


@dataclass(frozen=True)
class JointMap:
    """A checked joint map (see the module's docstring for each field)."""

    source: str
    joints: dict[str, tuple[str, float]]
    soles: dict[str, str | SoleSpec]
    name: str | None = None
    mjcf: str | None = None
    gyro: str | None = None
    accelerometer: str | None = None
    add_accelerometer: bool = True
    foot_force: dict[str, tuple[str, ...]] | None = None
    torso: str | None = None
    stand_keyframe: str | None = None
    stand: dict[str, float] = field(default_factory=dict)
    servos: dict[str, dict[str, float]] = field(default_factory=dict)


class _Fields(TypedDict, total=False):  # the JointMap fields a map sets (others: defaults)
    soles: Required[dict[str, str | SoleSpec]]
    name: str
    mjcf: str
    gyro: str
    accelerometer: str | None
    add_accelerometer: bool
    foot_force: dict[str, tuple[str, ...]]
    torso: str
    stand_keyframe: str
    stand: dict[str, float]
    servos: dict[str, dict[str, float]]


def load_joint_map(path: str | Path) -> dict:
    """Read a joint-map JSON file (an object with known keys); one-line :class:`RobotError`
    if it is missing, not UTF-8, not JSON, or holds NaN or infinity."""
    path = Path(path)
    if not path.is_file():
        raise RobotError(f"joint map not found: {path}")
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise RobotError(f"joint map {path} is not UTF-8 text (byte {exc.start})") from None
    except OSError as exc:
        raise RobotError(f"joint map {path} cannot be read: {exc.strerror}") from None
    try:
        data = json.loads(text, parse_constant=_no_constant)
    except json.JSONDecodeError as exc:
        raise RobotError(
            f"joint map {path} is not valid JSON: {exc.msg} (line {exc.lineno})"
        ) from None
    except (RecursionError, ValueError) as exc:  # deep nesting; a 5000-digit integer
        first = str(exc).split("\n")[0][:80]
        raise RobotError(f"joint map {path} is not valid JSON: {first}") from None
    if not isinstance(data, dict):
        raise RobotError(f"joint map {path} must be a JSON object")
    for key in data:
        if key not in MAP_KEYS:
            raise unknown_name("joint-map key", key, MAP_KEYS)
    return data


def _no_constant(name: str) -> NoReturn:
    raise ValueError(f"{name} is not a number JSON allows")


def _where(source: str, key: str) -> str:
    return f"joint map {source}: {key!r}"


def _string(value: object, source: str, key: str) -> str:
    if not isinstance(value, str) or not value:
        raise RobotError(f"{_where(source, key)} must be a non-empty string, got {_kind(value)}")
    return value


def _number(value: object, source: str, key: str, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise RobotError(f"{_where(source, key)} must be a number, got {_kind(value)}")
    try:
        x = float(value)
    except OverflowError:
        raise RobotError(f"{_where(source, key)} must be a finite number, got a huge one") from None
    if not math.isfinite(x) or (positive and x <= 0):
        want = "a finite number > 0" if positive else "a finite number"
        raise RobotError(f"{_where(source, key)} must be {want}, got {x!r}")
    return x


def _object(value: object, source: str, key: str, what: str) -> dict:
    if not isinstance(value, dict):
        raise RobotError(f"{_where(source, key)} must be an object of {what}, got {_kind(value)}")
    return value


def _kind(value: object) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, str):
        return f"the string {value[:40]!r}"
    if isinstance(value, int | float):
        return f"the number {value!r}"[:60]
    return _KINDS.get(type(value), type(value).__name__)


def _joint(role: str, entry: object, source: str) -> tuple[str, float]:
    key = f"joints.{role}"
    if isinstance(entry, str):
        return _string(entry, source, key), 1.0
    entry = _object(entry, source, key, '{"joint": name, "sign": 1 or -1}')
    for k in entry:
        if k not in ("joint", "sign"):
            raise unknown_name(f"key of {key}", k, ("joint", "sign"))
    name = _string(entry.get("joint"), source, f"{key}.joint")
    sign = entry.get("sign", 1)
    if isinstance(sign, bool) or sign not in (1, -1):
        raise RobotError(f"{_where(source, key + '.sign')} must be 1 or -1, got {_kind(sign)}")
    return name, float(sign)


def _sole(side: str, entry: object, source: str) -> str | SoleSpec:
    key = f"soles.{side}"
    if isinstance(entry, str):
        return _string(entry, source, key)
    entry = _object(entry, source, key, '{"body", "pos", "size"}')
    for k in entry:
        if k not in ("body", "pos", "size", "quat"):
            raise unknown_name(f"key of {key}", k, ("body", "pos", "quat", "size"))
    body = _string(entry.get("body"), source, f"{key}.body")
    vec: dict[str, tuple[float, ...]] = {}
    for k, n, positive in (("pos", 3, False), ("size", 2, True), ("quat", 4, False)):
        if k == "quat" and k not in entry:
            continue
        v = entry.get(k)
        if not isinstance(v, list) or len(v) != n:
            raise RobotError(f"{_where(source, f'{key}.{k}')} must be a list of {n} numbers")
        vec[k] = tuple(_number(x, source, f"{key}.{k}", positive) for x in v)
    quat = vec.get("quat", (1.0, 0.0, 0.0, 0.0))
    norm = math.sqrt(sum(x * x for x in quat))
    if not 1e-6 < norm < 1e6:
        raise RobotError(f"{_where(source, f'{key}.quat')} must be a non-zero quaternion")
    (px, py, pz), (hx, hy), (qw, qx, qy, qz) = vec["pos"], vec["size"], (q / norm for q in quat)
    return SoleSpec(body, (px, py, pz), (hx, hy), (qw, qx, qy, qz))


def parse_joint_map(data: dict, source: str = "") -> JointMap:
    """Check a joint map read by :func:`load_joint_map` and make it a :class:`JointMap`.

    Args:
        data: the parsed JSON object; source: the file, for messages.

    Raises:
        RobotError: a field of the wrong type, a non-finite number, an unknown role.
    """
    src = source or "(in memory)"
    data = _object(data, src, "(top level)", "fields")
    for key in data:
        if key not in MAP_KEYS:
            raise unknown_name("joint-map key", str(key), MAP_KEYS)
    joints = _parse_joints(data.get("joints"), src)
    out: _Fields = {"soles": _parse_soles(data.get("soles"), src)}
    for name_key in _NAME_KEYS:
        if name_key in data:
            out[name_key] = _string(data[name_key], src, name_key)
    if "accelerometer" in data:
        acc = data["accelerometer"]
        out["accelerometer"] = None if acc is None else _string(acc, src, "accelerometer")
        out["add_accelerometer"] = False
    if "foot_force" in data:
        out["foot_force"] = _parse_foot_force(data["foot_force"], src)
    if "stand" in data:
        out["stand"] = _parse_stand(data["stand"], joints, src)
    if "servos" in data:
        out["servos"] = _parse_servos(data["servos"], joints, src)
    return JointMap(source=src, joints=joints, **out)


def _parse_joints(jm: object, src: str) -> dict[str, tuple[str, float]]:
    """``joints``: role -> (MJCF joint name, sign ±1), in :data:`ROLES` order, every leg
    role present."""
    if not isinstance(jm, dict) or not jm:
        raise RobotError(f"joint map {src} has no 'joints' object (role -> MJCF joint name)")
    for role in jm:
        if role not in ROLES:
            raise unknown_name("joint role", role, ROLES)
    missing = [r for r in LEG_ROLES if r not in jm]
    if missing:
        raise RobotError(f"joint map {src} lacks leg roles: {', '.join(missing)}")
    return {r: _joint(r, jm[r], src) for r in ROLES if r in jm}


def _parse_soles(value: object, src: str) -> dict[str, str | SoleSpec]:
    """``soles``: side ``"l"``/``"r"`` -> a site or body name, or a sole site to add."""
    soles = _object(value, src, "soles", 'sides "l" and "r"')
    for side in soles:
        if side not in _SIDES:
            raise unknown_name("side in 'soles'", str(side), _SIDES)
    for side in _SIDES:
        if side not in soles:
            raise RobotError(f"{_where(src, 'soles')} has no {side!r} sole")
    return {s: _sole(s, soles[s], src) for s in _SIDES}


def _parse_foot_force(value: object, src: str) -> dict[str, tuple[str, ...]]:
    """``foot_force``: side -> the names of the force or touch sensors under that sole."""
    ff = _object(value, src, "foot_force", 'sides "l" and "r" -> sensor names')
    for side in ff:
        if side not in _SIDES:
            raise unknown_name("side in 'foot_force'", str(side), _SIDES)
    foot_force = {}
    for side in _SIDES:
        names = ff.get(side, [])
        if not isinstance(names, list):
            raise RobotError(f"{_where(src, 'foot_force.' + side)} must be a list of names")
        key = f"foot_force.{side}"
        foot_force[side] = tuple(_string(n, src, key) for n in names)
    return foot_force


def _parse_stand(value: object, joints: dict[str, tuple[str, float]], src: str) -> dict[str, float]:
    """``stand``: role (one of ``joints``) -> standing angle [rad], canonical signs."""
    stand = _object(value, src, "stand", "role -> angle [rad]")
    for role in stand:
        if role not in joints:
            raise unknown_name("joint role in 'stand'", str(role), tuple(joints))
    return {r: _number(v, src, f"stand.{r}") for r, v in stand.items()}


def _parse_servos(
    value: object, joints: dict[str, tuple[str, float]], src: str
) -> dict[str, dict[str, float]]:
    """``servos``: role or group -> gains (``kp`` [Nm/rad], ``kv`` [Nm s/rad],
    ``torque_limit`` [Nm])."""
    servos = _object(value, src, "servos", "role or group -> gains")
    valid = (*SERVO_GROUPS, *joints)
    out: dict[str, dict[str, float]] = {}
    for key, gains in servos.items():
        if key not in valid:
            raise unknown_name("role or group in 'servos'", str(key), valid)
        gains = _object(gains, src, f"servos.{key}", "kp, kv, torque_limit")
        for g in gains:
            if g not in _SERVO_KEYS:
                raise unknown_name(f"gain in servos.{key}", str(g), _SERVO_KEYS)
        out[key] = {
            g: _number(v, src, f"servos.{key}.{g}", positive=g != "kv") for g, v in gains.items()
        }
        if out[key].get("kv", 0.0) < 0:
            raise RobotError(f"{_where(src, f'servos.{key}.kv')} must be >= 0")
    return out
