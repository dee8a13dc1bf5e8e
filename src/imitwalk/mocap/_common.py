"""Helpers shared by the readers: rotations, the y-up -> z-up map, file and keypoint checks.

Rotation conventions: a rotation matrix ``R`` maps child-frame vectors to the parent
frame (``v_parent = R @ v_child``); batches are ``(T, 3, 3)``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from imitwalk.errors import MocapError
from imitwalk.mocap.motion import LOWER_BODY

__all__ = [
    "Y_UP_TO_Z_UP",
    "check_keypoints",
    "euler_matrices",
    "quat_wxyz_matrices",
    "read_lines",
    "snap_rate",
    "up_axis",
    "z_up",
]

#: ``(3, 3)`` map of a y-up frame to the z-up world frame: (x, y, z) -> (x, -z, y).
Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


def read_lines(path: str | Path) -> list[str]:
    """Read a text file as lines (any line ending); a missing/unreadable file -> MocapError."""
    p = Path(path)
    if not p.is_file():
        raise MocapError(f"mocap file not found: {p}")
    try:
        return p.read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError as exc:
        raise MocapError(f"cannot read {p}: {exc}") from None


def snap_rate(fps: float) -> float:
    """Round a rate [Hz] computed from a printed frame time (e.g. ``1/0.0083333``) to the
    integer it misses by less than 0.01 %; other rates are returned unchanged."""
    nearest = round(fps)
    return float(nearest) if nearest > 0 and abs(fps - nearest) < 1e-4 * nearest else float(fps)


def euler_matrices(axes: str, angles_deg: np.ndarray, *, intrinsic: bool = True) -> np.ndarray:
    """Rotation matrices from Euler angles.

    Args:
        axes: rotation axes in the order listed in the file, e.g. ``"zyx"`` (1 to 3 axes).
        angles_deg: ``(T, len(axes))`` angles [deg], columns in the order of ``axes``.
        intrinsic: True for BVH (``R = R_a1 @ R_a2 @ R_a3``, rotations about moving axes);
            False for Acclaim ASF/AMC (``R = R_a3 @ R_a2 @ R_a1``: the first listed axis is
            applied first, about fixed axes).

    Returns:
        ``(T, 3, 3)`` rotation matrices.
    """
    angles = np.asarray(angles_deg, dtype=float)
    n = angles.shape[0]
    if not axes:
        return np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
    seq = axes.upper() if intrinsic else axes.lower()
    return Rotation.from_euler(seq, angles.reshape(n, len(axes)), degrees=True).as_matrix()


def quat_wxyz_matrices(q: np.ndarray) -> np.ndarray:
    """``(T, 4)`` unit quaternions, scalar first (w, x, y, z) -> ``(T, 3, 3)`` matrices."""
    q = np.asarray(q, dtype=float)
    norms = np.linalg.norm(q, axis=1)
    if np.any(norms < 1e-6) or not np.all(np.isfinite(q)):
        raise MocapError("a quaternion is zero or not finite")
    return Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix()


def up_axis(down_vector: np.ndarray, what: str) -> str:
    """Say which file axis is up from a rest-pose vector pointing down a leg (hip -> ankle).

    Returns ``"y"`` or ``"z"``; a leg along x, or pointing up, raises MocapError.
    """
    v = np.asarray(down_vector, dtype=float)
    k = int(np.argmax(np.abs(v)))
    if k == 0 or v[k] >= 0:
        raise MocapError(
            f"cannot tell the up axis of {what}: the rest-pose leg points along "
            f"{'+-'[int(v[k] < 0)]}{'xyz'[k]}; supported: y-up, z-up"
        )
    return "xyz"[k]


def z_up(points: np.ndarray, up: str) -> np.ndarray:
    """Map ``(..., 3)`` points of a ``up``-up frame (``"y"`` or ``"z"``) to the z-up world frame."""
    return points @ Y_UP_TO_Z_UP.T if up == "y" else points


def check_keypoints(
    keypoints: Mapping[str, np.ndarray],
    source: str | Path,
    n_frames: int,
    required: Sequence[str] = LOWER_BODY,
) -> dict[str, np.ndarray]:
    """Check that the required keypoints are present, ``(T, 3)`` and finite.

    Returns a plain dict of float arrays; raises MocapError naming what is wrong.
    """
    missing = [k for k in required if k not in keypoints]
    if missing:
        raise MocapError(f"{source}: missing required keypoints: {', '.join(missing)}")
    out: dict[str, np.ndarray] = {}
    for name, value in keypoints.items():
        arr = np.ascontiguousarray(value, dtype=float)
        if arr.shape != (n_frames, 3):
            raise MocapError(
                f"{source}: keypoint {name} has shape {arr.shape}, not ({n_frames}, 3)"
            )
        if not np.all(np.isfinite(arr)):
            raise MocapError(f"{source}: keypoint {name} has non-finite values")
        out[name] = arr
    return out
