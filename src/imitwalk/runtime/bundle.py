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
another format, in one line (the manifest's fields: :mod:`imitwalk.runtime.manifest`).
:func:`write_bundle` replaces only an earlier export, and never through a symbolic link
(:func:`check_out`): a folder holding anything else is refused and left as it was.
"""

from __future__ import annotations

import json
import numbers
import os
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from imitwalk import readback
from imitwalk.errors import ConfigError, ImitwalkError, RunError, unknown_name
from imitwalk.fileio import sync_file, sync_folder
from imitwalk.robots import Robot
from imitwalk.robots.saved import MUJOCO_VERSION, load_saved_robot, save_robot
from imitwalk.runtime.manifest import (
    BUNDLE_FORMAT,
    DT_RANGE,
    KINDS,
    MANIFEST,
    PARTS,
    build_manifest,
    check_robot,
    is_export,
    not_export,
    read_manifest,
    sha256,
)
from imitwalk.runtime.sensors import SensorLayout
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
    "check_out",
    "is_export",
    "read_bundle",
    "read_manifest",
    "write_bundle",
]


@dataclass(frozen=True)
class Bundle:
    """An exported controller's content (see the module doc).

    Attributes:
        kind: one of :data:`KINDS`; robot: the nominal robot; dt: the control period
        [s], within :data:`~imitwalk.runtime.manifest.DT_RANGE`; style: the stepping
        gait's style (at the scale exported), ``None`` for a policy from scratch; gains:
        its gains; actor: a PPO policy's spec and network; source: where it came from
        (the run's folder, learner, controller and scale).
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
            raise ConfigError(f"a {self.kind!r} controller needs {', '.join(PARTS[self.kind])}")
        if stepping and self.gains is None:
            raise ConfigError("a stepping gait needs its gains")
        lo, hi = DT_RANGE
        if not (isinstance(self.dt, numbers.Real) and lo < self.dt <= hi):  # NaN fails too
            raise ConfigError(f"dt must be the control period [s], {lo:g} < dt <= {hi:g}")

    @property
    def sensors(self) -> SensorLayout:
        """The sensor vector this controller reads."""
        return SensorLayout(len(self.robot.foot_force["l"]), self.robot.dof)


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


def check_out(folder: str | Path) -> Path:
    """``folder`` as a place :func:`write_bundle` may write an export: missing, an empty
    folder, or an earlier export (:func:`~imitwalk.runtime.manifest.is_export`: its
    manifest of kind ``"imitwalk controller"``, and nothing in it but the files that
    manifest lists). Nothing is deleted here.

    Raises:
        ConfigError: one line: ``folder`` is ``""``, ``.`` or ``..``, a symbolic link
            (write to a new folder and point the link at it), a file, or a folder that
            holds anything else.
    """
    if Path(folder).name in ("", ".."):  # "", ".", "..": it would rename the folder it is in
        raise ConfigError(
            f"--out {str(folder)!r} names no folder of its own; give the export folder's name"
        )
    folder = Path(folder)
    if folder.is_symlink():
        raise ConfigError(
            f"--out {folder} is a symbolic link (to {os.readlink(folder)}); give a new folder "
            "and point the link at it, or the link's target itself"
        )
    if folder.exists() and not folder.is_dir():
        raise ConfigError(f"--out {folder} is a file, not an export folder; give a folder")
    if folder.is_dir() and any(folder.iterdir()):
        why = not_export(folder)
        if why is not None:
            raise ConfigError(
                f"--out {folder} is not an export ({why}); nothing was replaced: give a new "
                "folder, an empty one, or an earlier export"
            )
    return folder


def write_bundle(b: Bundle, folder: str | Path) -> Path:
    """Write ``b`` to ``folder`` atomically: into a new folder beside it, then renamed
    over it. ``folder`` may be missing, empty, or an earlier export (replaced); anything
    else is refused before anything is written (:func:`check_out`).

    Raises:
        ConfigError: ``folder`` is a symbolic link, a file, or a folder that holds
            something other than an export.
    """
    folder = check_out(folder)
    folder.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{folder.name}.", suffix=".tmp", dir=folder.parent))
    try:
        _write_parts(b, tmp)
        files = {p.name: sha256(p) for p in sorted(tmp.iterdir())}
        (tmp / MANIFEST).write_text(
            json.dumps(build_manifest(b.robot, b.sensors, b.kind, b.source, b.dt, files), indent=1)
            + "\n"
        )
        os.chmod(tmp, 0o755)
        for p in tmp.iterdir():
            sync_file(p)
        sync_folder(tmp)
        old = None
        if folder.exists():
            old = folder.with_name(f".{folder.name}.old-{os.getpid()}")
            os.replace(folder, old)
        os.replace(tmp, folder)
        sync_folder(folder.parent)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
    return folder


def read_bundle(folder: str | Path) -> Bundle:
    """The controller exported to ``folder`` (checked by :func:`read_manifest`, its
    manifest held to its ``robot.json`` by :func:`~imitwalk.runtime.manifest.check_robot`).

    Raises:
        RunError: the folder is not a complete, unchanged export of this format, or its
            manifest says something its files do not.
    """
    folder = Path(folder)
    m = read_manifest(folder)
    kind = m["controller"]
    read = lambda name, what: readback.read_json(folder / name, what, RunError)  # noqa: E731
    try:
        robot = load_saved_robot(folder)
        _check_model_readable(robot, m, folder)
        dt = float(m["control"]["dt_s"])
        style = gains = actor = None
        if "style.json" in PARTS[kind]:
            style = GaitStyle.from_dict(read("style.json", "a gait style"))
            gains = StepGains.from_dict(read("gains.json", "a stepping gait's gains"))
        if "actor.json" in PARTS[kind]:
            from imitwalk.rl.actor import ActorSpec
            from imitwalk.rl.network import MLP

            actor = (ActorSpec.load(folder / "actor.json"), MLP.load(folder / "policy.npz"))
        b = Bundle(kind, robot, dt, style, gains, actor, dict(m.get("source", {})))
    except RunError:
        raise
    except (ImitwalkError, KeyError, TypeError, ValueError) as exc:
        raise RunError(f"{folder} is not a usable export: {type(exc).__name__}: {exc}") from None
    check_robot(m, robot, folder / MANIFEST)
    return b


def _check_model_readable(robot: Robot, manifest: dict, folder: Path) -> None:
    """An export written by another MuJoCo than this one is read if this one reads its
    ``robot.mjb``, and refused in one line naming both versions if it does not.

    Raises:
        RunError: this MuJoCo cannot read the export's compiled model.
    """
    versions = manifest.get("versions")
    made = versions.get("mujoco") if isinstance(versions, dict) else None
    if made == MUJOCO_VERSION:
        return
    try:
        robot.compile()
    except ImitwalkError:
        raise RunError(
            f"{folder} was exported with MuJoCo {made}, and this MuJoCo ({MUJOCO_VERSION}) "
            f"cannot read its robot.mjb: install mujoco=={made}, or export the run again"
        ) from None
