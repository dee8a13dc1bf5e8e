"""An exported controller on disk: its folder, manifest and parts.

``imitwalk export RUN --out DIR`` writes a folder that holds everything a controller
needs, and nothing of imitwalk's learning:

- ``manifest.json``: what the controller reads and writes (the joint names, order, signs
  and units; the sensor vector's blocks, their units and frames; the control rate), its
  kind, the versions that wrote it, the run it came from, and the SHA-256 of every other
  file;
- ``robot.json`` and ``robot.mjb``: the robot's record and its compiled MuJoCo model
  (``mj_saveModel``), which the controller uses for kinematics only (forward
  kinematics, Jacobians and the centre of mass; never to step physics or render);
- the controller's parameters: ``style.json`` and ``gains.json`` for the stepping gait;
  ``actor.json`` and ``policy.npz`` for a PPO policy (with the stepping gait's files for
  a residual one).

:class:`Bundle` is the same content in memory: the judge builds one from a run folder
and :func:`read_bundle` one from an export, so both play the controller by the same
code (:class:`~imitwalk.runtime.controller.Controller`). :func:`write_bundle` writes a
folder atomically (a reader sees the old export or the new one, never part of one; an
earlier export being replaced is absent for the instant between two renames);
:func:`read_bundle` refuses one that was tampered with, truncated, or written for
another format, in one line.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from imitwalk import readback
from imitwalk.errors import ConfigError, ImitwalkError, RunError, unknown_name
from imitwalk.robots import Robot
from imitwalk.robots.saved import MUJOCO_VERSION, ROBOT_FILES, load_saved_robot, save_robot
from imitwalk.runtime.sensors import BLOCKS, SensorLayout
from imitwalk.step.gains import StepGains
from imitwalk.step.style import GaitStyle

if TYPE_CHECKING:
    from imitwalk.rl.actor import ActorSpec
    from imitwalk.rl.network import MLP

__all__ = [
    "BUNDLE_FORMAT",
    "KINDS",
    "MANIFEST",
    "Bundle",
    "is_export",
    "read_bundle",
    "read_manifest",
    "write_bundle",
]

#: The format version of an export written here (and the newest read). 2: the stepping
#: gait's style carries its ``stride_share`` (a format-1 style walks its whole stride).
BUNDLE_FORMAT = 2
#: The manifest's file name, and the value of its ``"kind"`` key.
MANIFEST, KIND = "manifest.json", "imitwalk controller"
#: The controllers an export holds: the stepping gait, or a PPO policy (on the stepping
#: gait, or joint targets from scratch).
KINDS = ("stepping", "rl-residual", "rl-joints")

#: The sensor blocks' frames and meanings, as the manifest states them.
_FRAMES = {
    "gyro": "the IMU site's frame (the robot's gyro sensor)",
    "accel": "the IMU site's frame; specific force, +9.81 up when still",
    "foot_force": "normal force of each sole sensor, left sole first, in the order listed",
    "joints": "encoder angle x the joint's sign, in the joint order",
}
_PARTS = {
    "stepping": ("style.json", "gains.json"),
    "rl-residual": ("style.json", "gains.json", "actor.json", "policy.npz"),
    "rl-joints": ("actor.json", "policy.npz"),
}


@dataclass(frozen=True)
class Bundle:
    """An exported controller's content (see the module doc).

    Attributes:
        kind: one of :data:`KINDS`; robot: the nominal robot; dt: the control period
        [s]; style: the stepping gait's style (at the scale exported), ``None`` for a
        policy from scratch; gains: its gains; actor: a PPO policy's spec and network;
        source: where it came from (the run's folder, learner, controller and scale).
    """

    kind: str
    robot: Robot
    dt: float
    style: GaitStyle | None = None
    gains: StepGains | None = None
    actor: tuple[ActorSpec, MLP] | None = None
    source: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise unknown_name("controller kind", self.kind, KINDS, ConfigError)
        stepping, policy = self.style is not None, self.actor is not None
        if (stepping != (self.kind != "rl-joints")) or (policy != self.kind.startswith("rl")):
            raise ConfigError(f"a {self.kind!r} controller needs {', '.join(_PARTS[self.kind])}")
        if stepping and self.gains is None:
            raise ConfigError("a stepping gait needs its gains")

    @property
    def sensors(self) -> SensorLayout:
        """The sensor vector this controller reads."""
        return SensorLayout(len(self.robot.foot_force["l"]), self.robot.dof)


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with path.open("rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def _manifest(b: Bundle, files: dict[str, str]) -> dict[str, Any]:
    r, lay = b.robot, b.sensors
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
        "controller": b.kind,
        "versions": {"imitwalk": __version__, "mujoco": MUJOCO_VERSION},
        "source": b.source,
        "robot": r.name,
        "control": {"rate_hz": 1.0 / b.dt, "dt_s": b.dt},
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


def _write_parts(b: Bundle, folder: Path) -> None:
    r = b.robot
    save_robot(r, folder)
    if b.style is not None and b.gains is not None:
        (folder / "style.json").write_text(json.dumps(b.style.to_dict(), indent=1) + "\n")
        (folder / "gains.json").write_text(json.dumps(b.gains.to_dict(), indent=1) + "\n")
    if b.actor is not None:
        spec, net = b.actor
        spec.save(folder / "actor.json")
        net.save(folder / "policy.npz")


def is_export(folder: Path) -> bool:
    """True if ``folder`` holds an export's manifest."""
    return (Path(folder) / MANIFEST).is_file()


def write_bundle(b: Bundle, folder: str | Path) -> Path:
    """Write ``b`` to ``folder`` atomically: into a new folder beside it, then renamed
    over it. ``folder`` may be missing, empty, or an earlier export (replaced).

    Raises:
        ConfigError: ``folder`` is a file, or a folder that holds something else.
    """
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise ConfigError(f"--out {folder} is a file; give a folder for the export")
    if folder.is_dir() and any(folder.iterdir()) and not is_export(folder):
        raise ConfigError(f"--out {folder} holds files that are not an export; give a new folder")
    folder.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{folder.name}.", suffix=".tmp", dir=folder.parent))
    try:
        _write_parts(b, tmp)
        files = {p.name: _sha256(p) for p in sorted(tmp.iterdir())}
        (tmp / MANIFEST).write_text(json.dumps(_manifest(b, files), indent=1) + "\n")
        os.chmod(tmp, 0o755)
        old = None
        if folder.exists():
            old = folder.with_name(f".{folder.name}.old-{os.getpid()}")
            os.replace(folder, old)
        os.replace(tmp, folder)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
    return folder


def read_manifest(folder: str | Path) -> dict[str, Any]:
    """An export's manifest, checked: its kind, format and the files it lists (each
    present, with the SHA-256 recorded).

    Raises:
        RunError: one line naming what is wrong (not an export, another format, a file
            missing, changed or truncated).
    """
    folder = Path(folder)
    path = folder / MANIFEST
    what = "an exported controller's manifest (from 'imitwalk export')"
    if not folder.is_dir():
        raise RunError(f"{folder} is not a folder: give the folder 'imitwalk export' wrote")
    req = ("kind", "controller", "control", "joints", "sensors", "files")
    m = readback.read_json(path, what, RunError, required=req)
    if m["kind"] != KIND:
        raise RunError(f"{path} is not {what}: its kind is {m['kind']!r}")
    if readback.FORMAT_KEY not in m:
        raise RunError(f"{path} has no {readback.FORMAT_KEY!r}: not {what}")
    readback.check_format(m, BUNDLE_FORMAT, str(path), RunError)
    kind = m["controller"]
    if kind not in KINDS:
        raise RunError(f"{path}: controller {kind!r} is not one of {', '.join(KINDS)}")
    files = m["files"]
    need = (*ROBOT_FILES, *_PARTS[kind])
    if not isinstance(files, dict) or sorted(files) != sorted(need):
        raise RunError(f"{path}: a {kind!r} export lists the files {', '.join(need)}")
    for name in need:
        p = folder / name
        if not p.is_file():
            raise RunError(f"{folder}: {name} is missing; export the run again")
        if _sha256(p) != files[name]:
            raise RunError(
                f"{p} differs from what the manifest recorded (changed or truncated); "
                "export the run again"
            )
    return m


def read_bundle(folder: str | Path) -> Bundle:
    """The controller exported to ``folder`` (checked by :func:`read_manifest`).

    Raises:
        RunError: the folder is not a complete, unchanged export of this format.
    """
    folder = Path(folder)
    m = read_manifest(folder)
    kind = m["controller"]
    read = lambda name, what: readback.read_json(folder / name, what, RunError)  # noqa: E731
    try:
        robot = load_saved_robot(folder)
        dt = float(m["control"]["dt_s"])
        style = gains = actor = None
        if "style.json" in _PARTS[kind]:
            style = GaitStyle.from_dict(read("style.json", "a gait style"))
            gains = StepGains.from_dict(read("gains.json", "a stepping gait's gains"))
        if "actor.json" in _PARTS[kind]:
            from imitwalk.rl.actor import ActorSpec
            from imitwalk.rl.network import MLP

            actor = (ActorSpec.load(folder / "actor.json"), MLP.load(folder / "policy.npz"))
        b = Bundle(kind, robot, dt, style, gains, actor, dict(m.get("source", {})))
    except RunError:
        raise
    except (ImitwalkError, KeyError, TypeError, ValueError) as exc:
        raise RunError(f"{folder} is not a usable export: {type(exc).__name__}: {exc}") from None
    names = [j.get("name") for j in m["joints"]] if isinstance(m["joints"], list) else None
    if names != list(robot.joint_names) or m["sensors"].get("size") != b.sensors.size:
        raise RunError(f"{folder / MANIFEST}: its joints or sensors disagree with robot.json")
    return b
