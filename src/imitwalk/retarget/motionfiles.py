"""Robot-motion files of the field's tools, read and written
(:class:`~imitwalk.retarget.robotmotion.RobotMotion`).

- **GMR** (General Motion Retargeting, Ze et al. 2025): a pickle of a dict with ``fps``,
  ``root_pos`` ``(T, 3)`` [m], ``root_rot`` ``(T, 4)`` as ``(x, y, z, w)``, ``dof_pos``
  ``(T, D)`` [rad] (the robot model's ``qpos[7:]``: every joint after the floating base,
  in the model's order and signs), and ``local_body_pos``, ``link_body_list`` (``None``
  in GMR's own writers). Read with an unpickler that builds nothing but NumPy arrays,
  numbers, strings, lists and dicts (a pickle can otherwise run code).
- **LocoMuJoCo** (``loco_mujoco.trajectory.Trajectory.save``): an ``.npz`` whose keys
  are the fields of its ``TrajectoryData`` (``qpos`` ``(T, nq)``, ``qvel`` ``(T, nv)``,
  ``split_points``: where each trajectory starts, and the end), ``TrajectoryInfo``
  (``joint_names``: every joint of the model, ``frequency`` [Hz]) and ``TrajectoryModel``
  (``njnt``, ``jnt_type``). The base quaternion in ``qpos`` is MuJoCo's ``(w, x, y, z)``.
  Written without pickled objects; read without unpickling (the first trajectory).

:func:`load_clip` reads either, or a mocap file, as a clip for ``imitwalk learn``.
"""

from __future__ import annotations

import io
import pickle
from pathlib import Path
from typing import Any, ClassVar

import mujoco
import numpy as np

from imitwalk.errors import MocapError
from imitwalk.fileio import atomic_write, write_npz
from imitwalk.mocap import Motion, load_motion
from imitwalk.retarget.robotmotion import MotionModel, RobotMotion, clip_of_motion
from imitwalk.robots import Robot

__all__ = ["FORMATS", "load_clip", "read_robot_motion", "write_gmr", "write_locomujoco"]

#: Robot-motion file formats by extension.
FORMATS = {".pkl": "gmr", ".npz": "locomujoco"}


def _check_suffix(path: Path, fmt: str) -> None:
    want = next(s for s, f in FORMATS.items() if f == fmt)
    if path.suffix.lower() != want:
        raise MocapError(f"a {fmt} file is written as {want}, not {path.name}")


def write_gmr(motion: RobotMotion, robot: Robot, path: str | Path) -> Path:
    """Write ``motion`` as GMR's robot-motion pickle at ``path`` (atomically)."""
    path = Path(path)
    _check_suffix(path, "gmr")
    q = MotionModel(robot).qpos(motion.root_pos, motion.root_quat, motion.joints)
    data = {
        "fps": float(motion.fps),
        "root_pos": q[:, 0:3].copy(),
        "root_rot": q[:, [4, 5, 6, 3]].copy(),  # MuJoCo's (w, x, y, z) -> (x, y, z, w)
        "dof_pos": q[:, 7:].copy(),
        "local_body_pos": None,
        "link_body_list": None,
    }
    return atomic_write(path, lambda tmp: tmp.write_bytes(pickle.dumps(data, protocol=4)))


def write_locomujoco(motion: RobotMotion, robot: Robot, path: str | Path) -> Path:
    """Write ``motion`` as a LocoMuJoCo trajectory ``.npz`` at ``path`` (atomically);
    ``qvel`` by finite differences of ``qpos`` (``mj_differentiatePos``)."""
    path = Path(path)
    _check_suffix(path, "locomujoco")
    mod = MotionModel(robot)
    m, q = mod.m, mod.qpos(motion.root_pos, motion.root_quat, motion.joints)
    dt = 1.0 / motion.fps
    qvel = np.zeros((len(q), m.nv))
    for k in range(len(q) - 1):
        mujoco.mj_differentiatePos(m, qvel[k], dt, q[k], q[k + 1])
    qvel[-1] = qvel[-2]
    arrays: dict[str, Any] = {
        "qpos": q,
        "qvel": qvel,
        "split_points": np.array([0, len(q)]),
        "joint_names": np.array(mod.names),
        "frequency": np.array(float(motion.fps)),
        "njnt": np.array(m.njnt),
        "jnt_type": np.asarray(m.jnt_type).copy(),
    }
    return write_npz(path, arrays, compressed=False)


class _ArraysOnly(pickle.Unpickler):
    """Builds NumPy arrays and plain Python values, and refuses anything else."""

    ALLOWED: ClassVar[set[tuple[str, str]]] = {
        ("numpy.core.multiarray", "_reconstruct"),
        ("numpy._core.multiarray", "_reconstruct"),
        ("numpy.core.multiarray", "scalar"),
        ("numpy._core.multiarray", "scalar"),
        ("numpy", "ndarray"),
        ("numpy", "dtype"),
        ("builtins", "float"),
        ("builtins", "int"),
    }

    def find_class(self, module: str, name: str) -> Any:
        if (module, name) not in self.ALLOWED:
            raise MocapError(f"it holds a {module}.{name}: a GMR file holds arrays only")
        return super().find_class(module, name)


def _read_gmr(path: Path, robot: Robot) -> RobotMotion:
    try:
        data = _ArraysOnly(io.BytesIO(path.read_bytes())).load()
    except MocapError as exc:
        raise MocapError(f"{path}: {exc}") from None
    except Exception as exc:
        raise MocapError(f"{path} is not a GMR robot-motion pickle: {type(exc).__name__}") from None
    need = ("fps", "root_pos", "root_rot", "dof_pos")
    if not isinstance(data, dict) or any(k not in data for k in need):
        raise MocapError(f"{path} is not a GMR robot-motion file: it needs {', '.join(need)}")
    mod = MotionModel(robot)
    try:
        fps = float(data["fps"])
        pos, rot, dof = (np.asarray(data[k], dtype=float) for k in need[1:])
    except (TypeError, ValueError):
        raise MocapError(f"{path}: fps, root_pos, root_rot and dof_pos must be numbers") from None
    if dof.ndim != 2 or dof.shape[1] != mod.m.nq - 7:
        raise MocapError(
            f"{path}: dof_pos is {dof.shape}; robot {robot.name} has {mod.m.nq - 7} joint "
            "angles after its floating base (a motion of another robot?)"
        )
    if pos.shape != (len(dof), 3) or rot.shape != (len(dof), 4):
        raise MocapError(
            f"{path}: root_pos {pos.shape} and root_rot {rot.shape} must be (T, 3), (T, 4)"
        )
    q = np.concatenate([pos, rot[:, [3, 0, 1, 2]], dof], axis=1)
    if not np.all(np.isfinite(q)):
        raise MocapError(f"{path}: holds values that are not finite")
    return mod.motion(q, fps, str(path))


def _read_locomujoco(path: Path, robot: Robot) -> RobotMotion:
    try:
        z = np.load(path, allow_pickle=False)
        names = [str(n) for n in z["joint_names"]]
        qpos = np.asarray(z["qpos"], dtype=float)
        fps = float(z["frequency"])
        types = np.asarray(z["jnt_type"], dtype=int)
        split = np.asarray(z["split_points"], dtype=int) if "split_points" in z else None
    except KeyError as exc:
        raise MocapError(f"{path} is not a LocoMuJoCo trajectory: it has no {exc}") from None
    except (OSError, ValueError, TypeError) as exc:
        raise MocapError(f"{path} is not a LocoMuJoCo trajectory .npz: {exc}") from None
    sizes = {0: 7, 1: 4, 2: 1, 3: 1}  # free, ball, slide, hinge
    if len(types) != len(names) or any(int(t) not in sizes for t in types):
        raise MocapError(f"{path}: joint_names and jnt_type disagree, or a joint type is unknown")
    adr = np.concatenate([[0], np.cumsum([sizes[int(t)] for t in types])])
    if qpos.ndim != 2 or qpos.shape[1] != adr[-1] or not np.all(np.isfinite(qpos)):
        raise MocapError(f"{path}: qpos must be finite (T, {adr[-1]}), is {qpos.shape}")
    if split is not None and len(split) >= 2:
        qpos = qpos[split[0] : split[1]]
    if types[0] != 0:
        raise MocapError(f"{path}: its first joint is not a floating base")
    mod = MotionModel(robot)
    missing = [j for j in robot.mj_joints if j not in names]
    if missing:
        raise MocapError(
            f"{path} has no joint {missing[0]!r} of robot {robot.name} (a trajectory of "
            "another robot?)"
        )
    q = np.tile(robot.stand_qpos, (len(qpos), 1))
    q[:, 0:7] = qpos[:, 0:7]
    q[:, mod.qadr] = qpos[:, [adr[names.index(j)] for j in robot.mj_joints]]
    return mod.motion(q, fps, str(path))


def read_robot_motion(path: str | Path, robot: Robot) -> RobotMotion:
    """A GMR ``.pkl`` or LocoMuJoCo ``.npz`` of ``robot`` as a robot motion.

    Raises:
        MocapError: one line: the file is missing, of another format or another robot,
            or damaged.
    """
    p = Path(path)
    fmt = FORMATS.get(p.suffix.lower())
    if fmt is None:
        raise MocapError(
            f"unknown robot-motion extension {p.suffix!r}; valid: {', '.join(FORMATS)}"
        )
    if not p.is_file():
        raise MocapError(f"robot-motion file not found: {p}")
    return _read_gmr(p, robot) if fmt == "gmr" else _read_locomujoco(p, robot)


def load_clip(path: str | Path, robot: Robot, **mocap: Any) -> Motion:
    """A clip to learn from: a mocap file (:func:`~imitwalk.mocap.load_motion`, with
    ``mocap``'s options), or a robot-motion file of ``robot`` (GMR, LocoMuJoCo) as the
    joint centres its forward kinematics give
    (:func:`~imitwalk.retarget.robotmotion.clip_of_motion`)."""
    if Path(path).suffix.lower() in FORMATS:
        given = [k for k, v in mocap.items() if v is not None]
        if given:
            raise MocapError(
                f"{', '.join(given)}: mocap options; {Path(path).name} is a robot motion"
            )
        return clip_of_motion(read_robot_motion(path, robot), robot)
    return load_motion(path, **mocap)
