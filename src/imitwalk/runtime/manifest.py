"""An export's ``manifest.json``: written from a bundle, and read back checked field by
field.

The manifest is the one file of an export its SHA-256 list cannot cover, and the one a
robot is wired from (joint order, signs, ranges; the sensor vector; the control rate).
:func:`read_manifest` therefore checks every field the runtime or a robot loop uses,
each refused in one line (:class:`~imitwalk.errors.RunError`): the control period
``dt_s`` finite and within :data:`DT_RANGE` [s], and ``rate_hz`` its inverse; each joint
an object with a name, an MJCF joint, a sign of +1 or -1, ``rad``, and a finite range
``lo < hi`` [rad]; the sensor vector's blocks in order, with their sizes and units; the
robot's name a string. :func:`check_robot` then holds them to ``robot.json`` (which the
SHA-256 list covers). :func:`is_export` says whether a folder is an earlier export that
``imitwalk export`` may replace.
"""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from imitwalk import readback
from imitwalk.errors import RunError
from imitwalk.robots.saved import MUJOCO_VERSION, ROBOT_FILES
from imitwalk.runtime.sensors import BLOCKS, SensorLayout

if TYPE_CHECKING:
    from imitwalk.robots import Robot

__all__ = [
    "BUNDLE_FORMAT",
    "DT_RANGE",
    "KIND",
    "KINDS",
    "MANIFEST",
    "PARTS",
    "build_manifest",
    "check_robot",
    "is_export",
    "not_export",
    "read_manifest",
    "sha256",
]

#: The format version of an export written here (and the newest read). 2: the stepping
#: gait's style carries its ``stride_share`` (a format-1 style walks its whole stride).
BUNDLE_FORMAT = 2
#: The manifest's file name, and the value of its ``"kind"`` key.
MANIFEST, KIND = "manifest.json", "imitwalk controller"
#: The controllers an export holds: the stepping gait, or a PPO policy (on the stepping
#: gait, or joint targets from scratch).
KINDS = ("stepping", "rl-residual", "rl-joints")
#: The files of each kind of controller, beside the robot's.
PARTS = {
    "stepping": ("style.json", "gains.json"),
    "rl-residual": ("style.json", "gains.json", "actor.json", "policy.npz"),
    "rl-joints": ("actor.json", "policy.npz"),
}
#: The control periods a manifest may state [s]: above 0.5 ms (2 kHz), at most 0.1 s
#: (10 Hz). imitwalk's controllers run at 100 Hz.
DT_RANGE = (0.0005, 0.1)

#: The sensor blocks' frames and meanings, as the manifest states them.
_FRAMES = {
    "gyro": "the IMU site's frame (the robot's gyro sensor)",
    "accel": "the IMU site's frame; specific force, +9.81 up when still",
    "foot_force": "normal force of each sole sensor, left sole first, in the order listed",
    "joints": "encoder angle x the joint's sign, in the joint order",
}
_WHAT = "an exported controller's manifest (from 'imitwalk export')"


def sha256(path: Path) -> str:
    """The SHA-256 of the file at ``path``, in hex."""
    h = hashlib.sha256()
    with path.open("rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def build_manifest(
    r: Robot,
    lay: SensorLayout,
    controller: str,
    source: dict[str, Any],
    dt: float,
    files: dict[str, str],
) -> dict[str, Any]:
    """The manifest of a bundle: its robot ``r``, sensor layout ``lay``, controller kind,
    ``source`` (the run it came from), control period ``dt`` [s] and the SHA-256 of its
    other ``files``."""
    blocks = []
    for name, unit in BLOCKS:
        block: dict[str, Any] = {"name": name, "size": lay.sizes[name], "unit": unit}
        block["frame"] = _FRAMES[name]
        if name == "gyro":
            block["mjcf_sensor"] = r.gyro
        elif name == "accel":
            block["mjcf_sensor"] = r.accelerometer
        elif name == "foot_force":
            block["mjcf_sensors"] = [*r.foot_force["l"], *r.foot_force["r"]]
        blocks.append(block)
    joints = [
        {
            "name": n,
            "mjcf_joint": mj,
            "sign": int(s),
            "unit": "rad",
            "stand": float(q0),
            "range": [float(lo), float(hi)],
        }
        for n, mj, s, q0, (lo, hi) in zip(
            r.joint_names, r.mj_joints, r.signs, r.stand, r.limits, strict=True
        )
    ]
    from imitwalk import __version__

    return {
        readback.FORMAT_KEY: BUNDLE_FORMAT,
        "kind": KIND,
        "controller": controller,
        "versions": {"imitwalk": __version__, "mujoco": MUJOCO_VERSION},
        "source": source,
        "robot": r.name,
        "control": {"rate_hz": 1.0 / dt, "dt_s": dt},
        "joints": joints,
        "sensors": {"size": lay.size, "blocks": blocks},
        "output": {
            "name": "joint targets",
            "size": r.dof,
            "unit": "rad",
            "order": "the joints, with their signs",
            "to": "position servos",
        },
        "files": files,
    }


def not_export(folder: Path) -> str | None:
    """Why the existing folder ``folder`` is not an earlier export that may be replaced
    (``None`` if it is one): its manifest must be a JSON object of kind :data:`KIND`
    with an integer format and a ``files`` object, and the folder must hold exactly the
    manifest and the files it lists, each a plain file."""
    path = folder / MANIFEST
    if not path.is_file() or path.is_symlink():
        return f"it holds no {MANIFEST}"
    try:
        m = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        return f"its {MANIFEST} is not JSON"
    fmt = m.get(readback.FORMAT_KEY) if isinstance(m, dict) else None
    if not isinstance(m, dict) or m.get("kind") != KIND or type(fmt) is not int:
        return f"its {MANIFEST} is not an imitwalk export's (kind {KIND!r} and a format)"
    files = m.get("files")
    if not isinstance(files, dict):
        return f"its {MANIFEST} lists no files"
    entries = {p.name: p for p in folder.iterdir()}
    extra = sorted(set(entries) - {*files, MANIFEST})
    if extra:
        return f"it holds files its {MANIFEST} does not list: {', '.join(extra[:4])}"
    odd = sorted(n for n, p in entries.items() if p.is_symlink() or not p.is_file())
    if odd:
        return f"{', '.join(odd[:4])} in it is not a plain file"
    return None


def is_export(folder: str | Path) -> bool:
    """True if ``folder`` is an earlier export (:func:`not_export`), safe to replace."""
    folder = Path(folder)
    return folder.is_dir() and not_export(folder) is None


def read_manifest(folder: str | Path) -> dict[str, Any]:
    """An export's manifest, checked: its kind, format, every field the runtime uses (see
    the module doc), and the files it lists (each present, with the SHA-256 recorded).

    Raises:
        RunError: one line naming what is wrong (not an export, another format, a field
            missing or out of range, a file missing, changed or truncated).
    """
    folder = Path(folder)
    path = folder / MANIFEST
    if not folder.is_dir():
        raise RunError(f"{folder} is not a folder: give the folder 'imitwalk export' wrote")
    req = ("kind", "controller", "robot", "control", "joints", "sensors", "files")
    m = readback.read_json(path, _WHAT, RunError, required=req)
    if m["kind"] != KIND:
        raise RunError(f"{path} is not {_WHAT}: its kind is {m['kind']!r}")
    if readback.FORMAT_KEY not in m:
        raise RunError(f"{path} has no {readback.FORMAT_KEY!r}: not {_WHAT}")
    readback.check_format(m, BUNDLE_FORMAT, str(path), RunError)
    kind = m["controller"]
    if not isinstance(kind, str) or kind not in KINDS:
        raise RunError(f"{path}: controller {kind!r} is not one of {', '.join(KINDS)}")
    _check_fields(m, path)
    files = m["files"]
    need = (*ROBOT_FILES, *PARTS[kind])
    if not isinstance(files, dict) or sorted(files) != sorted(need):
        raise RunError(f"{path}: a {kind!r} export lists the files {', '.join(need)}")
    for name in need:
        p = folder / name
        if not p.is_file():
            raise RunError(f"{folder}: {name} is missing; export the run again")
        if sha256(p) != files[name]:
            raise RunError(
                f"{p} differs from what the manifest recorded (changed or truncated); "
                "export the run again"
            )
    return m


def _real(x: object) -> bool:
    """True for a finite JSON number (not ``true``/``false``)."""
    return isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)


def _check_fields(m: dict[str, Any], path: Path) -> None:
    """Refuse, in one line, a field of manifest ``m`` of the wrong type or value."""
    if not isinstance(m["robot"], str) or not m["robot"]:
        raise RunError(f"{path}: robot must be the robot's name (a string); got {m['robot']!r}")
    if not isinstance(m.get("source", {}), dict):
        raise RunError(f"{path}: source must be an object (run, learner, controller, scale)")
    _check_control(m["control"], path)
    joints = m["joints"]
    if not isinstance(joints, list) or not joints:
        raise RunError(f"{path}: joints must be a list of objects, one per joint")
    for i, j in enumerate(joints):
        _check_joint(i, j, path)
    _check_sensors(m["sensors"], path)


def _check_control(c: object, path: Path) -> None:
    lo, hi = DT_RANGE
    if not isinstance(c, dict) or "dt_s" not in c:
        raise RunError(f"{path}: control must be an object with dt_s, the control period [s]")
    dt = c["dt_s"]
    if not _real(dt) or not lo < dt <= hi:
        raise RunError(
            f"{path}: control.dt_s must be a finite period [s] with {lo:g} < dt_s <= {hi:g}; "
            f"got {dt!r}"
        )
    rate = c.get("rate_hz", 1.0 / dt)
    if not _real(rate) or abs(rate * dt - 1.0) > 1e-6:
        raise RunError(
            f"{path}: control.rate_hz ({rate!r}) is not 1 / dt_s ({dt!r}); export the run again"
        )


def _check_joint(i: int, j: object, path: Path) -> None:
    at = f"{path}: joints[{i}]"
    if not isinstance(j, dict):
        raise RunError(f"{at} must be an object (name, mjcf_joint, sign, unit, stand, range)")
    for key in ("name", "mjcf_joint"):
        if not isinstance(j.get(key), str) or not j[key]:
            raise RunError(f"{at}.{key} must be a name (a string); got {j.get(key)!r}")
    if type(j.get("sign")) is not int or j["sign"] not in (1, -1):
        raise RunError(f"{at}.sign must be 1 or -1; got {j.get('sign')!r}")
    if j.get("unit", "rad") != "rad":
        raise RunError(f"{at}.unit must be 'rad'; got {j['unit']!r}")
    if "stand" in j and not _real(j["stand"]):
        raise RunError(f"{at}.stand must be a finite angle [rad]; got {j['stand']!r}")
    r = j.get("range")
    if not (isinstance(r, list) and len(r) == 2 and all(map(_real, r)) and r[0] < r[1]):
        raise RunError(f"{at}.range must be [lo, hi], finite, lo < hi [rad]; got {r!r}")


def _check_sensors(s: object, path: Path) -> None:
    names = [name for name, _ in BLOCKS]
    if not isinstance(s, dict) or type(s.get("size")) is not int or s["size"] < 1:
        raise RunError(f"{path}: sensors must be an object with size (an integer) and blocks")
    blocks = s.get("blocks")
    if not isinstance(blocks, list) or not all(isinstance(b, dict) for b in blocks):
        raise RunError(f"{path}: sensors.blocks must be a list of objects ({', '.join(names)})")
    got = [(b.get("name"), b.get("unit")) for b in blocks]
    if got != list(BLOCKS):
        want = ", ".join(f"{n} [{u}]" for n, u in BLOCKS)
        raise RunError(f"{path}: sensors.blocks must be {want}, in this order")
    sizes = [b.get("size") for b in blocks]
    if not all(type(n) is int and n >= 0 for n in sizes) or sum(sizes) != s["size"]:
        raise RunError(f"{path}: sensors.blocks' sizes {sizes} do not add up to {s['size']!r}")


def check_robot(m: dict[str, Any], robot: Robot, path: Path) -> None:
    """Refuse, in one line, a checked manifest ``m`` that disagrees with the export's
    ``robot.json`` (``robot``): the robot's name, each joint's name, MJCF joint, sign,
    standing angle and range, and the sensor blocks' sizes and MJCF sensors."""
    again = "export the run again"
    if m["robot"] != robot.name:
        raise RunError(f"{path}: robot {m['robot']!r} is not robot.json's {robot.name!r}; {again}")
    names = [j["name"] for j in m["joints"]]
    if names != list(robot.joint_names):
        raise RunError(f"{path}: its joints disagree with robot.json; {again}")
    rows = zip(m["joints"], robot.mj_joints, robot.signs, robot.stand, robot.limits, strict=True)
    for j, mj, sign, stand, (lo, hi) in rows:
        want: dict[str, Any] = {"mjcf_joint": mj, "sign": int(sign), "stand": float(stand)}
        want["range"] = [float(lo), float(hi)]
        for key, val in want.items():
            got = j.get(key, val)
            if not (got == val if key in ("mjcf_joint", "sign") else _close(got, val)):
                raise RunError(
                    f"{path}: joint {j['name']!r} {key} {got!r} disagrees with robot.json "
                    f"({val!r}); {again}"
                )

    lay = SensorLayout(len(robot.foot_force["l"]), robot.dof)
    blocks = {b["name"]: b for b in m["sensors"]["blocks"]}
    mjcf = {
        "gyro": ("mjcf_sensor", robot.gyro),
        "accel": ("mjcf_sensor", robot.accelerometer),
        "foot_force": ("mjcf_sensors", [*robot.foot_force["l"], *robot.foot_force["r"]]),
    }
    for name, n in lay.sizes.items():
        key, sensor = mjcf.get(name, ("", None))
        if blocks[name]["size"] != n or (key and blocks[name].get(key, sensor) != sensor):
            raise RunError(f"{path}: its sensors block {name!r} disagrees with robot.json; {again}")


def _close(a: object, b: float | list[float]) -> bool:
    """``a`` equals ``b`` (a number or a list of them) within 1e-9."""
    if isinstance(b, list):
        return isinstance(a, list) and len(a) == len(b) and all(map(_close, a, b))
    return isinstance(a, int | float) and _real(a) and abs(a - b) <= 1e-9
