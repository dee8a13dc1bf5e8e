"""A BVH joint tree and its forward kinematics (file axes and units).

* Rotation channels in any order per joint, applied as listed (intrinsic: channels
  ``Zrotation Yrotation Xrotation`` give ``R = Rz @ Ry @ Rx``), degrees.
* Position channels on any joint replace the matching component of its OFFSET (the
  Blender convention; the root's position channels are its position), so a joint may
  carry 0, 3 or 6 channels, and the translation may sit below a static top joint.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from imitwalk.mocap._common import euler_matrices

__all__ = ["Joint", "bone_lengths", "children", "forward_kinematics", "moving_columns"]


@dataclass(frozen=True)
class Joint:
    """One joint of a hierarchy.

    Attributes:
        name: as in the file (an End Site is ``<parent>_end``).
        parent: index of the parent joint, -1 for a root (parents come first).
        offset: ``(3,)`` rest offset from the parent [file units, parent frame].
        channels: lower-case channel kinds in file order, e.g. ``("xposition", "zrotation")``.
        end_site: True for an ``End Site``.
        line: 1-based line of its declaration in the file.
    """

    name: str
    parent: int
    offset: np.ndarray
    channels: tuple[str, ...] = ()
    end_site: bool = False
    line: int = 0


def children(joints: list[Joint]) -> list[list[int]]:
    """Child indices of each joint, in file order."""
    out: list[list[int]] = [[] for _ in joints]
    for j, jt in enumerate(joints):
        if jt.parent >= 0:
            out[jt.parent].append(j)
    return out


def forward_kinematics(joints: list[Joint], values: np.ndarray, scale: float) -> np.ndarray:
    """Joint positions ``(T, J, 3)`` in file axes, ``scale`` metres per file unit (1 keeps
    file units), from ``(T, C)`` channel values (columns in joint order)."""
    n = values.shape[0]
    pos = np.zeros((n, len(joints), 3))
    rot = np.zeros((n, len(joints), 3, 3))
    col = 0
    for j, jt in enumerate(joints):
        local_t = np.broadcast_to(jt.offset * scale, (n, 3)).copy()
        axes = ""
        angle_cols: list[int] = []
        for c in jt.channels:
            axis = "xyz".index(c[0])
            if c.endswith("position"):
                local_t[:, axis] = values[:, col] * scale
            else:
                axes += c[0]
                angle_cols.append(col)
            col += 1
        local_r = euler_matrices(axes, values[:, angle_cols])
        if jt.parent < 0:
            pos[:, j], rot[:, j] = local_t, local_r
        else:
            parent_r = rot[:, jt.parent]
            pos[:, j] = pos[:, jt.parent] + np.einsum("tij,tj->ti", parent_r, local_t)
            rot[:, j] = parent_r @ local_r
    return pos


def bone_lengths(joints: list[Joint], pos: np.ndarray) -> np.ndarray:
    """``(J,)`` median distance of each joint from its parent over the frames (0 for a
    root), in the units of ``pos`` ``(T, J, 3)``."""
    out = np.zeros(len(joints))
    for j, jt in enumerate(joints):
        if jt.parent >= 0:
            out[j] = np.median(np.linalg.norm(pos[:, j] - pos[:, jt.parent], axis=1))
    return out


def moving_columns(joints: list[Joint], keypoint_joints: Iterable[int]) -> np.ndarray:
    """``(C,)`` bool: the channel columns that move one of ``keypoint_joints``.

    Every channel of a strict ancestor moves a joint, and so do its own position
    channels; its own rotation channels move only what lies below it.
    """
    ancestors: set[int] = set()
    own: set[int] = set()
    for k in keypoint_joints:
        own.add(k)
        p = joints[k].parent
        while p >= 0 and p not in ancestors:
            ancestors.add(p)
            p = joints[p].parent
    used = []
    for j, jt in enumerate(joints):
        for c in jt.channels:
            used.append(j in ancestors or (j in own and c.endswith("position")))
    return np.array(used, dtype=bool)
