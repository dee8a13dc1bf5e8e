"""A robot saved beside what it runs: its record (``robot.json``) and its compiled MuJoCo
model (``robot.mjb``, ``mj_saveModel``: the MJCF with what building added), as an export
holds it (:mod:`imitwalk.runtime.bundle`).

:func:`load_saved_robot` gives back the same :class:`~imitwalk.robots.Robot`, its model
file the ``.mjb`` (loaded as it is by :func:`~imitwalk.robots.build.compile_model`), so
the robot's own MJCF, meshes and joint map are no longer needed. A ``.mjb`` is specific to
the MuJoCo that wrote it (:data:`MUJOCO_VERSION`).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from imitwalk import readback
from imitwalk.errors import RunError
from imitwalk.robots.spec import Robot

__all__ = ["MUJOCO_VERSION", "ROBOT_FILES", "load_saved_robot", "save_robot"]

#: The files of a saved robot: its record and its compiled model.
ROBOT_FILES = ("robot.json", "robot.mjb")
#: The MuJoCo that writes (and can read) a saved robot's ``.mjb``.
MUJOCO_VERSION = mujoco.__version__


def _finite_or_none(x: np.ndarray) -> list:
    return [float(v) if np.isfinite(v) else None for v in np.asarray(x, float).ravel()]


def _robot_dict(r: Robot) -> dict[str, Any]:
    return {
        "name": r.name,
        "joint_names": list(r.joint_names),
        "mj_joints": list(r.mj_joints),
        "signs": r.signs.tolist(),
        "gyro": r.gyro,
        "accelerometer": r.accelerometer,
        "foot_force": {s: list(v) for s, v in r.foot_force.items()},
        "torso": r.torso,
        "soles": dict(r.soles),
        "stand": r.stand.tolist(),
        "stand_qpos": r.stand_qpos.tolist(),
        "limits": r.limits.tolist(),
        "kp": r.kp.tolist(),
        "torque_limit": _finite_or_none(r.torque_limit),  # None: no limit
        "total_mass": r.total_mass,
        "torso_height": r.torso_height,
        "height": r.height,
        "sensors": list(r.sensors),
        "stand_ctrl": None if r.stand_ctrl is None else r.stand_ctrl.tolist(),
    }


def _robot_from(d: dict, mjb: Path) -> Robot:
    arr = lambda k: np.asarray(d[k], dtype=float)  # noqa: E731
    return Robot(
        name=str(d["name"]),
        mjcf=mjb,
        joint_names=tuple(map(str, d["joint_names"])),
        mj_joints=tuple(map(str, d["mj_joints"])),
        signs=np.asarray(d["signs"], dtype=int),
        gyro=str(d["gyro"]),
        accelerometer=None if d["accelerometer"] is None else str(d["accelerometer"]),
        foot_force={s: tuple(map(str, d["foot_force"][s])) for s in ("l", "r")},
        torso=str(d["torso"]),
        soles={s: str(d["soles"][s]) for s in ("l", "r")},
        stand=arr("stand"),
        stand_qpos=arr("stand_qpos"),
        limits=arr("limits").reshape(-1, 2),
        kp=arr("kp"),
        torque_limit=np.array([np.inf if v is None else float(v) for v in d["torque_limit"]]),
        total_mass=float(d["total_mass"]),
        torso_height=float(d["torso_height"]),
        height=float(d["height"]),
        sensors=tuple(map(str, d["sensors"])),
        stand_ctrl=None if d["stand_ctrl"] is None else arr("stand_ctrl"),
    )


def save_robot(robot: Robot, folder: str | Path) -> None:
    """Write ``robot``'s :data:`ROBOT_FILES` into ``folder`` (which the caller writes
    atomically as a whole)."""
    folder = Path(folder)
    record, model = (folder / n for n in ROBOT_FILES)
    record.write_text(json.dumps(_robot_dict(robot), indent=1) + "\n")
    mujoco.mj_saveModel(robot.compile(), str(model), None)


def load_saved_robot(folder: str | Path) -> Robot:
    """The robot :func:`save_robot` wrote into ``folder``.

    Raises:
        RunError: ``robot.json`` is missing, not JSON, or not a robot's record.
    """
    folder = Path(folder)
    record, model = (folder / n for n in ROBOT_FILES)
    d = readback.read_json(record, "a robot's record", RunError)
    try:
        return _robot_from(d, model)
    except (KeyError, TypeError, ValueError) as exc:
        raise RunError(f"{record} is not a robot's record: {type(exc).__name__}: {exc}") from None
