"""DeepMimic motion JSON reader (``{"Loop": ..., "Frames": [[dt, root_pos, ...], ...]}``).

Each frame has 44 values, y-up, metres, quaternions ``(w, x, y, z)``::

    dt, root_pos(3), root_quat(4), chest(4), neck(4), r_hip(4), r_knee(1), r_ankle(4),
    r_shoulder(4), r_elbow(1), l_hip(4), l_knee(1), l_ankle(4), l_shoulder(4), l_elbow(1)

``root_quat`` is the world orientation of the pelvis, the others are local rotations
relative to the parent link; knees and elbows are angles [rad] about the local z axis.
Keypoints come from forward kinematics of the DeepMimic ``humanoid3d`` character (see
:data:`OFFSETS`). As in DeepMimic and pybullet's ``MotionCaptureData.getCycleTime``, a
looping clip lasts ``(T - 1) * dt``: its last frame is the first pose of the next loop,
so ``meta["period_frames"] == T - 1``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from imitwalk.errors import MocapError
from imitwalk.mocap._common import check_keypoints, quat_wxyz_matrices, snap_rate, z_up
from imitwalk.mocap.bounds import check_motion, check_rate, drop_channels
from imitwalk.mocap.motion import Motion

__all__ = ["OFFSETS", "SCALE", "read_deepmimic"]

#: pybullet's deep_mimic env loads the character with ``globalScaling=0.25``
#: (pybullet_envs/deep_mimic/env/humanoid_stable_pd.py), giving a ~0.85 m pelvis height.
SCALE = 0.25

#: Joint origins in the parent link frame, unscaled, y-up, from pybullet_data
#: ``humanoid/humanoid.urdf`` (pybullet 3.2.7; same character as DeepMimic
#: ``data/characters/humanoid3d.txt``): name -> (parent, offset).
OFFSETS: dict[str, tuple[str, tuple[float, float, float]]] = {
    "chest": ("root", (0.0, 0.944604, 0.0)),
    "neck": ("chest", (0.0, 0.895576, 0.0)),
    "right_hip": ("root", (0.0, 0.0, 0.339548)),
    "right_knee": ("right_hip", (0.0, -1.686184, 0.0)),
    "right_ankle": ("right_knee", (0.0, -1.639480, 0.0)),
    "right_shoulder": ("chest", (-0.096200, 0.974000, 0.732440)),
    "right_elbow": ("right_shoulder", (0.0, -1.099152, 0.0)),
    "right_wrist": ("right_elbow", (0.0, -1.035788, 0.0)),
    "left_hip": ("root", (0.0, 0.0, -0.339548)),
    "left_knee": ("left_hip", (0.0, -1.686184, 0.0)),
    "left_ankle": ("left_knee", (0.0, -1.639480, 0.0)),
    "left_shoulder": ("chest", (-0.096200, 0.974000, -0.732440)),
    "left_elbow": ("left_shoulder", (0.0, -1.099152, 0.0)),
    "left_wrist": ("left_elbow", (0.0, -1.035788, 0.0)),
}

# Extra points in a link frame, unscaled (from the same URDF): the head sphere centre
# (neck link, sphere at y = 0.7) and the ball of the foot on the sole (ankle link, box
# centre (0.18, -0.09, 0), size 0.708 x 0.22: sole at y = -0.2, 3/4 of the way from the
# heel at x = 0.357).
_POINTS = {
    "head": ("neck", (0.0, 0.7, 0.0)),
    "r_toe": ("right_ankle", (0.357, -0.2, 0.0)),
    "l_toe": ("left_ankle", (0.357, -0.2, 0.0)),
}

# Frame layout: link -> (first column, number of values: 4 quaternion, 1 z-angle).
_COLUMNS = {
    "root": (4, 4),
    "chest": (8, 4),
    "neck": (12, 4),
    "right_hip": (16, 4),
    "right_knee": (20, 1),
    "right_ankle": (21, 4),
    "right_shoulder": (25, 4),
    "right_elbow": (29, 1),
    "left_hip": (30, 4),
    "left_knee": (34, 1),
    "left_ankle": (35, 4),
    "left_shoulder": (39, 4),
    "left_elbow": (43, 1),
}

_KEYPOINT_LINKS = {
    "pelvis": "root",
    "neck": "neck",
    **{f"{s[0]}_{j}": f"{s}_{j}" for s in ("left", "right") for j in ("hip", "knee", "ankle")},
    **{
        f"{s[0]}_{j}": f"{s}_{j}" for s in ("left", "right") for j in ("shoulder", "elbow", "wrist")
    },
}


def _channels() -> tuple[str, ...]:
    names = ["dt", "root_pos.x", "root_pos.y", "root_pos.z"]
    for link, (_, n) in _COLUMNS.items():
        names += [f"{link}.{c}" for c in ("wxyz" if n == 4 else ("angle",))]
    return tuple(names)


def _z_rotations(angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros((len(angle), 3, 3))
    out[:, 0, 0], out[:, 0, 1], out[:, 1, 0], out[:, 1, 1], out[:, 2, 2] = c, -s, s, c, 1.0
    return out


def _frames(p: Path, src: str) -> tuple[np.ndarray, str]:
    """The ``(T, 44)`` frames of a DeepMimic file as floats, and its ``"Loop"`` mode."""
    if not p.is_file():
        raise MocapError(f"mocap file not found: {p}")
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError, RecursionError, OSError) as exc:
        what = "nested too deeply" if isinstance(exc, RecursionError) else str(exc)
        raise MocapError(f"{src}: not DeepMimic JSON: {what}".replace("\n", " ")[:300]) from None
    if not isinstance(doc, dict) or not isinstance(doc.get("Frames"), list):
        raise MocapError(f"{src}: no 'Frames' list (not a DeepMimic motion file?)")
    frames = doc["Frames"]
    if len(frames) < 2:
        raise MocapError(f"{src}: 'Frames' holds {len(frames)} frame(s), need >= 2")
    for i, fr in enumerate(frames):
        if not isinstance(fr, list) or len(fr) != 44:
            got = len(fr) if isinstance(fr, list) else type(fr).__name__
            raise MocapError(f"{src}: frame {i} has {got} values, expected 44")
        if not all(isinstance(v, int | float) and not isinstance(v, bool) for v in fr):
            raise MocapError(f"{src}: frame {i}: a value is not a number")
    try:
        data = np.array(frames, dtype=float)
    except OverflowError:
        raise MocapError(f"{src}: a number in 'Frames' is too large for a float") from None
    loop = doc.get("Loop", "none")
    return data, loop if isinstance(loop, str) else str(loop)[:20]


def read_deepmimic(path: str | Path) -> Motion:
    """Read a DeepMimic motion file (``.txt`` or ``.json``).

    Returns:
        a :class:`Motion`: ``data`` ``(T, 44)`` frames as read, ``keypoints`` ``(T, 3)``
        [m] z up, ``fps = 1/dt`` of the first frame, ``loop`` if ``"Loop": "wrap"``.
    """
    src = str(path)
    data, mode = _frames(Path(path), src)
    channels = _channels()
    bad = ~np.isfinite(data[:, 1:])
    if bad.any():
        t, k = (int(i[0]) for i in np.nonzero(bad))
        raise MocapError(f"{src}: frame {t}: {channels[1 + k]} is {data[t, 1 + k]}, not finite")
    if not (np.isfinite(data[0, 0]) and data[0, 0] > 0):
        raise MocapError(f"{src}: frame 0: dt {data[0, 0]} must be a finite time > 0 s")
    fps = check_rate(1.0 / float(data[0, 0]), f"{src}: frame 0: dt {data[0, 0]:.6g} s")
    used = np.arange(data.shape[1]) > 0  # every column but the per-frame dt moves a keypoint
    kept, kept_channels, dropped = drop_channels(data, channels, used, src)
    n = len(data)
    rot: dict[str, np.ndarray] = {}
    pos: dict[str, np.ndarray] = {"root": data[:, 1:4]}
    for link, (col, width) in _COLUMNS.items():
        vals = data[:, col : col + width]
        try:
            rot[link] = quat_wxyz_matrices(vals) if width == 4 else _z_rotations(vals[:, 0])
        except MocapError as exc:
            raise MocapError(f"{src}: {link}: {exc}") from None
    rot["right_wrist"] = rot["left_wrist"] = np.broadcast_to(np.eye(3), (n, 3, 3))
    for link, (parent, offset) in OFFSETS.items():
        pos[link] = pos[parent] + rot[parent] @ (SCALE * np.array(offset))  # parents first
        rot[link] = rot[parent] @ rot[link]  # local -> world
    keypoints = {k: pos[link] for k, link in _KEYPOINT_LINKS.items()}
    for key, (link, offset) in _POINTS.items():
        keypoints[key] = pos[link] + rot[link] @ (SCALE * np.array(offset))
    keypoints = check_keypoints({k: z_up(v, "y") for k, v in keypoints.items()}, src, n)
    loop = mode == "wrap"
    meta: dict = {"loop_mode": mode, "dropped_channels": dropped}
    if loop:
        meta["period_frames"] = n - 1
    motion = Motion(
        snap_rate(fps), kept_channels, kept, keypoints, src, "deepmimic", loop=loop, meta=meta
    )
    return check_motion(motion)
