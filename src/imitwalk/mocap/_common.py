"""Helpers shared by the readers: numbers, rotations, the map to z up, file and keypoint checks.

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
    "UP_AXES",
    "UP_TO_Z_UP",
    "Y_UP_TO_Z_UP",
    "check_axes",
    "check_keypoints",
    "count",
    "euler_matrices",
    "finite_floats",
    "quat_wxyz_matrices",
    "read_lines",
    "snap_rate",
    "z_up",
]

#: ``(3, 3)`` map of a y-up frame to the z-up world frame: (x, y, z) -> (x, -z, y).
Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])

#: The up axes a file may have (``--up``), each -> the ``(3, 3)`` rotation that takes it
#: to +z: a quarter turn about x for ``y``/``-y``, about y for ``x``/``-x``, a half turn
#: about x for ``-z``.
UP_TO_Z_UP: dict[str, np.ndarray] = {
    "z": np.eye(3),
    "y": Y_UP_TO_Z_UP,
    "x": np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]),
    "-x": np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]),
    "-y": np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]),
    "-z": np.diag([1.0, -1.0, -1.0]),
}
UP_AXES: tuple[str, ...] = ("x", "y", "z", "-x", "-y", "-z")


def read_lines(path: str | Path) -> list[str]:
    """Read a text file as lines (any line ending); a missing/unreadable file -> MocapError."""
    p = Path(path)
    if p.is_dir():
        raise MocapError(f"{p} is a folder, not a mocap file")
    if not p.is_file():
        raise MocapError(f"mocap file not found: {p}")
    try:
        return p.read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError as exc:
        raise MocapError(f"cannot read {p}: {exc}") from None


def finite_floats(tokens: list[str], where: str) -> np.ndarray:
    """``(n,)`` floats parsed from ``tokens``; a non-number or a non-finite one -> MocapError."""
    try:
        out = np.array([float(t) for t in tokens])
    except ValueError:
        raise MocapError(f"{where}: non-numeric value in {' '.join(tokens)[:40]!r}") from None
    if not np.all(np.isfinite(out)):
        raise MocapError(f"{where}: non-finite value in {' '.join(tokens)[:40]!r}")
    return out


def count(token: str, where: str, what: str, lo: int, hi: int) -> int:
    """An integer ``lo <= n <= hi`` written as ``token`` (``"6"``, ``"6.0"``), else MocapError."""
    try:
        value = float(token)
    except ValueError:
        value = float("nan")
    if not (np.isfinite(value) and value == int(value) and lo <= value <= hi):
        raise MocapError(f"{where}: {what} {token[:20]!r} is not an integer in {lo}-{hi}")
    return int(value)


def check_axes(axes: str, where: str, what: str = "rotation axes") -> str:
    """``axes`` lower-cased if it lists x, y, z at most once each (e.g. ``"zyx"``), else
    a MocapError naming ``what``."""
    low = axes.lower()
    if any(a not in "xyz" for a in low) or len(set(low)) != len(low):
        raise MocapError(f"{where}: {what} {axes[:20]!r} must name each of X, Y, Z at most once")
    return low


def snap_rate(fps: float) -> float:
    """Round a rate [Hz] computed from a printed frame time (e.g. ``1/0.0083333``) to the
    integer it misses by less than 0.01 %; other rates (and non-finite ones, which the
    readers refuse before) are returned unchanged."""
    if not np.isfinite(fps):
        return float(fps)
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
    axes = check_axes(axes, "euler_matrices")
    if angles.shape[1:] != (len(axes),):
        raise MocapError(f"{angles.shape[1:]} angles per frame for rotation axes {axes!r}")
    if not axes:
        return np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
    seq = axes.upper() if intrinsic else axes.lower()
    return Rotation.from_euler(seq, angles, degrees=True).as_matrix()


def quat_wxyz_matrices(q: np.ndarray) -> np.ndarray:
    """``(T, 4)`` quaternions, scalar first (w, x, y, z) -> ``(T, 3, 3)`` matrices.

    Each is normalised (after scaling by its largest entry, so that no norm overflows);
    a zero or non-finite one raises MocapError.
    """
    q = np.asarray(q, dtype=float)
    if not np.all(np.isfinite(q)):
        raise MocapError("a quaternion is not finite")
    big = np.max(np.abs(q), axis=1, keepdims=True)
    if np.any(big < 1e-6):
        raise MocapError("a quaternion is zero")
    q = q / np.where((big > 1e3) | (big < 1e-3), big, 1.0)  # rescale only the far-off ones
    return Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix()


def z_up(points: np.ndarray, up: str) -> np.ndarray:
    """Map ``(..., 3)`` points of a frame whose up axis is ``up`` (one of :data:`UP_AXES`)
    to the z-up world frame (:data:`UP_TO_Z_UP`)."""
    if up == "z":
        return points
    return points @ UP_TO_Z_UP[up].T


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
