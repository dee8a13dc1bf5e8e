"""An export's ``manifest.json``: written from a bundle, and read back checked field by
field.

The manifest is the one file of an export its SHA-256 list cannot cover, and the one a
robot is wired from (joint order, signs, ranges; the sensor vector; the control rate).
:func:`read_manifest` therefore checks the fields the runtime reads, each refused in one
line (:class:`~imitwalk.errors.RunError`): the control period ``dt_s`` finite and within
:data:`DT_RANGE` [s], and ``rate_hz`` its inverse; the robot's name a string; the files
listed, with their SHA-256. :func:`check_robot` then holds the robot's name, the joints
(name, MJCF joint, sign, unit, standing angle, range) and the sensor blocks to what
:func:`build_manifest` writes for the export's ``robot.json`` (which the SHA-256 list
covers), naming the first field that differs. :func:`is_export` says whether a folder is
an earlier export that ``imitwalk export`` may replace.
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
from imitwalk.step.fields import shown

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


def _blocks(r: Robot, lay: SensorLayout) -> list[dict[str, Any]]:
    """The manifest's sensor blocks of robot ``r`` (without their ``frame`` texts)."""
    mjcf: dict[str, dict[str, Any]] = {
        "gyro": {"mjcf_sensor": r.gyro},
        "accel": {"mjcf_sensor": r.accelerometer},
        "foot_force": {"mjcf_sensors": [*r.foot_force["l"], *r.foot_force["r"]]},
    }
    return [
        {"name": name, "size": lay.sizes[name], "unit": unit, **mjcf.get(name, {})}
        for name, unit in BLOCKS
    ]


def _joints(r: Robot) -> list[dict[str, Any]]:
    """The manifest's joints of robot ``r``: name, MJCF joint, sign, unit, standing angle
    and range [rad]."""
    return [
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
    from imitwalk import __version__

    blocks = [{**b, "frame": _FRAMES[b["name"]]} for b in _blocks(r, lay)]
    return {
        readback.FORMAT_KEY: BUNDLE_FORMAT,
        "kind": KIND,
        "controller": controller,
        "versions": {"imitwalk": __version__, "mujoco": MUJOCO_VERSION},
        "source": source,
        "robot": r.name,
        "control": {"rate_hz": 1.0 / dt, "dt_s": dt},
        "joints": _joints(r),
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
    """Refuse, in one line, a robot name, source or control period of the wrong type or
    value (the joints and sensors are held to ``robot.json`` by :func:`check_robot`)."""
    if not isinstance(m["robot"], str) or not m["robot"]:
        raise RunError(f"{path}: robot must be the robot's name (a string); got {m['robot']!r}")
    if not isinstance(m.get("source", {}), dict):
        raise RunError(f"{path}: source must be an object (run, learner, controller, scale)")
    lo, hi = DT_RANGE
    c = m["control"]
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


def check_robot(m: dict[str, Any], robot: Robot, path: Path) -> None:
    """Refuse, in one line, a manifest ``m`` whose robot, joints (name, MJCF joint, sign,
    unit, standing angle, range) or sensor blocks (name, size, unit, MJCF sensors) are not
    the ones :func:`build_manifest` writes for the export's ``robot.json`` (``robot``)."""
    lay = SensorLayout(len(robot.foot_force["l"]), robot.dof)
    want = {"size": lay.size, "blocks": _blocks(robot, lay)}
    for at, got, exp in (
        ("robot", m["robot"], robot.name),
        ("joints", m["joints"], _joints(robot)),
        ("sensors", m["sensors"], want),
    ):
        where = _difference(got, exp, at)
        if where is not None:
            raise RunError(
                f"{path}: {where[0]} is {shown(where[1])}, not robot.json's {shown(where[2])}; "
                "export the run again"
            )


def _difference(got: object, want: object, at: str) -> tuple[str, object, object] | None:
    """The first place where ``got`` differs from ``want`` (the keys of ``want`` only),
    as (its path, e.g. ``joints[3] (l_knee).sign``, the value there, the one wanted);
    ``None`` if nowhere. Numbers are equal only exactly (JSON keeps a float's bits)."""
    if isinstance(want, dict):
        if not isinstance(got, dict):
            return at, got, want
        for key, w in want.items():
            found = _difference(got.get(key), w, f"{at}.{key}")
            if found is not None:
                return found
        return None
    if isinstance(want, list):
        if not isinstance(got, list) or len(got) != len(want):
            return at, got, want
        for i, (g, w) in enumerate(zip(got, want, strict=True)):
            label = f" ({w['name']})" if isinstance(w, dict) and "name" in w else ""
            found = _difference(g, w, f"{at}[{i}]{label}")
            if found is not None:
                return found
        return None
    same = type(got) is type(want) or (_real(got) and _real(want) and type(want) is float)
    return None if same and got == want else (at, got, want)
