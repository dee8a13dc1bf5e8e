"""Acclaim ASF (skeleton) + AMC (motion) reader, the CMU database's own format.

* ASF ``:units``: ``length L`` means 1 unit = 1/L inch (CMU: L = 0.45, 1 unit = 5.64 cm);
  ``angle deg|rad`` applies to the ``axis``/``orientation`` values.
* Forward kinematics per the Acclaim spec: each bone has a fixed axis rotation ``C``
  (``axis ax ay az ORDER``, world-aligned) and per-frame DOF rotation ``M`` (the DOFs in
  the listed order, first listed applied first); its world rotation is
  ``G = G_parent @ C @ M @ C^-1`` (i.e. ``L = C^-1 M C`` in the spec's row-vector form),
  and it ends at ``start + length * G @ direction``.
* AMC: ``:FULLY-SPECIFIED``, ``:DEGREES`` (or ``:RADIANS``), 120 Hz unless told.
* The ASF axes are y-up: mapped to z-up by (x, y, z) -> (x, -z, y).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from imitwalk.errors import MocapError
from imitwalk.mocap._common import check_keypoints, euler_matrices, read_lines, up_axis, z_up
from imitwalk.mocap.motion import Motion

__all__ = ["read_amc", "read_asf"]

# Keypoint -> (bone, "start"|"end") alternatives, CMU ASF bone names.
_KEYPOINT_BONES: dict[str, tuple[tuple[str, str], ...]] = {
    "pelvis": (("root", "start"),),
    "neck": (("lowerneck", "start"), ("thorax", "end")),
    "head": (("head", "start"), ("upperneck", "end")),
}
for _s in "lr":
    _KEYPOINT_BONES.update(
        {
            f"{_s}_hip": ((f"{_s}femur", "start"),),
            f"{_s}_knee": ((f"{_s}tibia", "start"), (f"{_s}femur", "end")),
            f"{_s}_ankle": ((f"{_s}foot", "start"), (f"{_s}tibia", "end")),
            f"{_s}_toe": ((f"{_s}toes", "start"), (f"{_s}foot", "end")),
            f"{_s}_shoulder": ((f"{_s}humerus", "start"), (f"{_s}clavicle", "end")),
            f"{_s}_elbow": ((f"{_s}radius", "start"), (f"{_s}humerus", "end")),
            f"{_s}_wrist": ((f"{_s}wrist", "start"), (f"{_s}radius", "end")),
        }
    )


@dataclass
class Bone:
    """One ASF bone. ``direction`` is a world-frame unit vector, ``length`` in ASF units."""

    name: str
    direction: np.ndarray = field(default_factory=lambda: np.zeros(3))
    length: float = 0.0
    axis: np.ndarray = field(default_factory=lambda: np.zeros(3))  # (3,) angles, ASF angle unit
    axis_order: str = "xyz"
    dof: tuple[str, ...] = ()
    parent: str | None = None


@dataclass
class Skeleton:
    """A parsed ASF: bones in hierarchy order (parents first; ``bones[0]`` is the root)."""

    bones: dict[str, Bone]
    metres_per_unit: float
    angle_scale: float  # ASF angle unit -> degrees
    root_position: np.ndarray
    source: str


def read_asf(path: str | Path) -> Skeleton:
    """Parse an ASF skeleton file."""
    src = str(path)
    lines = [ln.split("#", 1)[0].strip() for ln in read_lines(path)]
    root = Bone("root", dof=())
    bones: dict[str, Bone] = {}
    children: dict[str, list[str]] = {}
    length_unit, angle_scale = 1.0, 1.0
    root_pos = np.zeros(3)
    section, bone = "", None
    for i, ln in enumerate(lines):
        tok = ln.split()
        if not tok:
            continue
        where = f"{src}: line {i + 1}"
        try:
            if tok[0].startswith(":"):
                section = tok[0][1:].lower()
            elif section == "units" and tok[0] == "length":
                length_unit = float(tok[1])
            elif section == "units" and tok[0] == "angle":
                angle_scale = 1.0 if tok[1].lower().startswith("deg") else float(np.degrees(1.0))
            elif section == "root" and tok[0] == "order":
                root.dof = tuple(t.lower() for t in tok[1:])
            elif section == "root" and tok[0] == "axis":
                root.axis_order = tok[1].lower()
            elif section == "root" and tok[0] == "position":
                root_pos = np.array([float(v) for v in tok[1:4]])
            elif section == "root" and tok[0] == "orientation":
                root.axis = np.array([float(v) for v in tok[1:4]])
            elif section == "bonedata":
                bone = _bone_line(tok, bone, bones)
            elif section == "hierarchy" and tok[0] not in ("begin", "end"):
                children.setdefault(tok[0], []).extend(tok[1:])
        except (ValueError, IndexError):
            raise MocapError(f"{where}: malformed ASF line {ln[:40]!r}") from None
    if not bones or not children:
        raise MocapError(f"{src}: no :bonedata or :hierarchy section (not an ASF file?)")
    if length_unit <= 0:
        raise MocapError(f"{src}: bad :units length {length_unit}")
    ordered: dict[str, Bone] = {"root": root}
    queue = ["root"]
    while queue:
        parent = queue.pop(0)
        for child in children.get(parent, []):
            if child not in bones:
                raise MocapError(f"{src}: :hierarchy names unknown bone {child!r}")
            bones[child].parent = parent
            ordered[child] = bones[child]
            queue.append(child)
    return Skeleton(ordered, 0.0254 / length_unit, angle_scale, root_pos, src)


def _bone_line(tok: list[str], bone: Bone | None, bones: dict[str, Bone]) -> Bone | None:
    key = tok[0].lower()
    if key == "begin":
        return Bone("")
    if bone is None:
        return None
    if key == "end":
        bones[bone.name] = bone
        return None
    if key == "name":
        bone.name = tok[1]
    elif key == "direction":
        bone.direction = np.array([float(v) for v in tok[1:4]])
    elif key == "length":
        bone.length = float(tok[1])
    elif key == "axis":
        bone.axis = np.array([float(v) for v in tok[1:4]])
        bone.axis_order = tok[4].lower() if len(tok) > 4 else "xyz"
    elif key == "dof":
        bone.dof = tuple(t.lower() for t in tok[1:])
    return bone


def _parse_amc(lines: list[str], skel: Skeleton, src: str) -> tuple[dict[str, np.ndarray], float]:
    """Return bone -> ``(T, n_dof)`` values (AMC angle unit) and the AMC angle scale to degrees."""
    rows: dict[str, list[list[float]]] = {}
    counts: list[int] = []
    angle_scale = 1.0
    for i, ln in enumerate(lines):
        tok = ln.split()
        if not tok or tok[0].startswith("#"):
            continue
        if tok[0].startswith(":"):
            angle_scale = float(np.degrees(1.0)) if tok[0].upper() == ":RADIANS" else angle_scale
            continue
        if len(tok) == 1 and tok[0].isdigit():
            counts.append(0)
            continue
        name = tok[0]
        if not counts:
            raise MocapError(f"{src}: line {i + 1}: bone values before the first frame number")
        if name not in skel.bones:
            raise MocapError(f"{src}: line {i + 1}: bone {name!r} is not in the ASF {skel.source}")
        ndof = len(skel.bones[name].dof)
        if len(tok) - 1 != ndof:
            raise MocapError(
                f"{src}: line {i + 1}: bone {name!r} has {len(tok) - 1} values, "
                f"its ASF dof has {ndof}"
            )
        try:
            values = [float(v) for v in tok[1:]]
        except ValueError:
            raise MocapError(f"{src}: line {i + 1}: non-numeric value for bone {name!r}") from None
        rows.setdefault(name, []).append(values)
        counts[-1] += 1
    if not counts:
        raise MocapError(f"{src}: no frames (not an AMC file?)")
    n = len(counts)
    for name, bone in skel.bones.items():
        if bone.dof and len(rows.get(name, [])) != n:
            got = len(rows.get(name, []))
            raise MocapError(f"{src}: bone {name!r} of the ASF appears in {got} of {n} frames")
    return {k: np.array(v) for k, v in rows.items()}, angle_scale


def read_amc(path: str | Path, skeleton: str | Path, *, fps: float = 120.0) -> Motion:
    """Read an AMC motion with its ASF skeleton.

    Args:
        path: the ``.amc`` file; skeleton: its ``.asf`` file; fps: frame rate [Hz].

    Returns:
        a :class:`Motion`: ``data`` ``(T, D)`` AMC values (root translation in ASF units,
        angles as in the file), ``keypoints`` ``(T, 3)`` [m] z up, ``meta["segments_m"]``
        bone lengths [m], ``meta["skeleton"]`` the ASF path.
    """
    src = str(path)
    skel = read_asf(skeleton)
    values, amc_scale = _parse_amc(read_lines(path), skel, src)
    n = len(next(iter(values.values())))
    scale = skel.metres_per_unit
    start: dict[str, np.ndarray] = {}
    end: dict[str, np.ndarray] = {}
    rot: dict[str, np.ndarray] = {}
    for name, bone in skel.bones.items():
        vals = values.get(name, np.zeros((n, 0)))
        rot_axes = "".join(d[1] for d in bone.dof if d[0] == "r")
        rot_cols = [k for k, d in enumerate(bone.dof) if d[0] == "r"]
        if len(rot_cols) + sum(d in ("tx", "ty", "tz") for d in bone.dof) != len(bone.dof):
            raise MocapError(f"{skel.source}: bone {name!r} has unsupported dof {bone.dof}")
        if name != "root" and len(rot_cols) != len(bone.dof):
            raise MocapError(f"{skel.source}: bone {name!r} has translation dof {bone.dof}")
        m = euler_matrices(rot_axes, vals[:, rot_cols] * amc_scale, intrinsic=False)
        c = euler_matrices(bone.axis_order, bone.axis[None, :] * skel.angle_scale, intrinsic=False)[
            0
        ]
        local = c @ m @ c.T  # (T, 3, 3)
        if bone.parent is None:
            pos = np.broadcast_to(skel.root_position * scale, (n, 3)).copy()
            for k, d in enumerate(bone.dof):
                if d[0] == "t":
                    pos[:, "xyz".index(d[1])] += vals[:, k] * scale
            rot[name], start[name], end[name] = local, pos, pos
        else:
            rot[name] = rot[bone.parent] @ local
            start[name] = end[bone.parent]
            offset = bone.length * scale * bone.direction
            end[name] = start[name] + np.einsum("tij,j->ti", rot[name], offset)
    found: dict[str, np.ndarray] = {}
    for key, options in _KEYPOINT_BONES.items():
        for bone_name, where in options:
            if bone_name in skel.bones:
                found[key] = (start if where == "start" else end)[bone_name]
                break
    leg = [b for b in ("lfemur", "ltibia") if b in skel.bones]
    if len(leg) < 2:
        raise MocapError(f"{skel.source}: no lfemur/ltibia bones; bones: {', '.join(skel.bones)}")
    up = up_axis(sum(skel.bones[b].direction * skel.bones[b].length for b in leg), skel.source)
    keypoints = check_keypoints({k: z_up(v, up) for k, v in found.items()}, src, n)
    channels = tuple(f"{b}.{d}" for b in skel.bones if b in values for d in skel.bones[b].dof)
    data = np.concatenate([values[b] for b in skel.bones if b in values], axis=1)
    meta = {
        "skeleton": skel.source,
        "metres_per_unit": scale,
        "up_axis": up,
        "segments_m": {b.name: b.length * scale for b in skel.bones.values() if b.parent},
    }
    return Motion(float(fps), channels, data, keypoints, src, "amc", meta=meta)
