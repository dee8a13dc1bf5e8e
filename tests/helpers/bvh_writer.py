"""A BVH writer for the tests: one motion, written in another file's conventions.

:func:`load_rig` takes a BVH apart into a skeleton and per-frame joint rotations;
:func:`write_bvh` writes it back with

* the rest pose turned by any rotation ``rest`` (OFFSETs along +x, -z, ...), the
  rotation channels turned to match, so that the animated skeleton is unchanged;
* the file's axes turned by ``world`` (``M_Z_UP`` writes a z-up file of a y-up one);
* lengths scaled (``scale``), every ``step``-th frame, any rotation order per joint;
* 6 channels on every joint (``six``), a static top joint carrying the pelvis
  (``static_top``), and joint names mapped (``names``).

With the rest pose turned by ``Q`` and the world by ``W``, the writer uses root
rotation ``W R Q^T``, joint rotations ``Q R Q^T`` and OFFSETs ``Q o``, so that every
joint lands at ``W p`` (``p``: its position in the source file).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from imitwalk.mocap.bvh_parse import parse_bvh

#: (x, y, z) -> (x, -z, y): a y-up file's axes to z-up ones.
M_Z_UP = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])


@dataclass
class Rig:
    """A skeleton and its motion, independent of file conventions (source file's units).

    names/parents/end_site per joint; offsets ``(J, 3)``; root ``(T, 3)`` root positions;
    rot ``(T, J, 3, 3)`` local joint rotations; frame_time [s].
    """

    names: list[str]
    parents: list[int]
    end_site: list[bool]
    offsets: np.ndarray
    root: np.ndarray
    rot: np.ndarray
    frame_time: float


def load_rig(path: Path, frames: slice = slice(1, None)) -> Rig:
    """Take a BVH with one translating root apart (``frames``: default all but frame 0)."""
    bvh = parse_bvh(path.read_text().splitlines(), str(path))
    vals = bvh.values[frames]
    n, joints = len(vals), bvh.joints
    rot = np.broadcast_to(np.eye(3), (n, len(joints), 3, 3)).copy()
    root = np.broadcast_to(joints[0].offset, (n, 3)).copy()
    col = 0
    for j, jt in enumerate(joints):
        axes = "".join(c[0].upper() for c in jt.channels if c.endswith("rotation"))
        cols = [col + k for k, c in enumerate(jt.channels) if c.endswith("rotation")]
        for k, c in enumerate(jt.channels):
            if c.endswith("position"):
                assert j == 0, "the writer's source may translate its root only"
                root[:, "xyz".index(c[0])] = vals[:, col + k]
        if axes:
            rot[:, j] = Rotation.from_euler(axes, vals[:, cols], degrees=True).as_matrix()
        col += len(jt.channels)
    return Rig(
        [jt.name for jt in joints],
        [jt.parent for jt in joints],
        [jt.end_site for jt in joints],
        np.array([jt.offset for jt in joints]),
        root,
        rot,
        bvh.frame_time,
    )


def _num(v) -> str:
    return " ".join(f"{x:.10g}" for x in v)


def write_bvh(
    path: Path,
    rig: Rig,
    *,
    rest: np.ndarray | None = None,
    world: np.ndarray | None = None,
    scale: float = 1.0,
    step: int = 1,
    orders: list[str] | None = None,
    six: bool = False,
    static_top: bool = False,
    names: dict[str, str] | None = None,
) -> Path:
    """Write ``rig`` as a BVH in the conventions given (see the module docstring)."""
    q = np.eye(3) if rest is None else np.asarray(rest)
    w = np.eye(3) if world is None else np.asarray(world)
    rot = rig.rot[::step]
    n, nj = rot.shape[:2]
    offsets = rig.offsets @ q.T * scale  # (J, 3)
    root = rig.root[::step] @ w.T * scale
    joint_ids = [j for j in range(nj) if not rig.end_site[j]]
    order = {j: (orders[k] if orders else "ZYX") for k, j in enumerate(joint_ids)}
    local = np.einsum("ij,tkjl,ml->tkim", q, rot, q)  # Q R Q^T
    local[:, 0] = np.einsum("ij,tjk,lk->til", w, rot[:, 0], q)  # W R Q^T
    kids: list[list[int]] = [[] for _ in range(nj)]
    for j, p in enumerate(rig.parents):
        if p >= 0:
            kids[p].append(j)
    out = ["HIERARCHY"]
    columns: list[np.ndarray] = []
    if static_top:
        out += ["ROOT joint_Root", "{", "  OFFSET 0 0 0", "  CHANNELS 0"]

    def emit(j: int, depth: int) -> None:
        pad = "  " * depth
        name = (names or {}).get(rig.names[j], rig.names[j])
        if rig.end_site[j]:
            out.extend(
                [f"{pad}End Site", f"{pad}{{", f"{pad}  OFFSET {_num(offsets[j])}", f"{pad}}}"]
            )
            return
        kind = "JOINT" if (j > 0 or static_top) else "ROOT"
        rot_names = " ".join(f"{a}rotation" for a in order[j])
        moving = j == 0 or six
        chans = (
            f"CHANNELS 6 Xposition Yposition Zposition {rot_names}"
            if moving
            else (f"CHANNELS 3 {rot_names}")
        )
        out.extend([f"{pad}{kind} {name}", f"{pad}{{", f"{pad}  OFFSET {_num(offsets[j])}"])
        out.append(f"{pad}  {chans}")
        if moving:
            columns.append(root if j == 0 else np.broadcast_to(offsets[j], (n, 3)))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # gimbal lock: the angles still give the matrix
            columns.append(Rotation.from_matrix(local[:, j]).as_euler(order[j], degrees=True))
        for c in kids[j]:
            emit(c, depth + 1)
        out.append(f"{pad}}}")

    emit(0, 1 if static_top else 0)
    if static_top:
        out.append("}")
    body = "\n".join(_num(row) for row in np.hstack(columns))
    ft = rig.frame_time * step
    path.write_text("\n".join(out) + f"\nMOTION\nFrames: {n}\nFrame Time: {ft:.9g}\n{body}\n")
    return path
