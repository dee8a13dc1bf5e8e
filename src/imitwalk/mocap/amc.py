"""Acclaim AMC motion reader, with its ASF skeleton (:mod:`imitwalk.mocap.asf`).

* Forward kinematics per the Acclaim spec: each bone has a fixed axis rotation ``C``
  (``axis ax ay az ORDER``, world-aligned) and per-frame DOF rotation ``M`` (the DOFs in
  the listed order, first listed applied first); its world rotation is
  ``G = G_parent @ C @ M @ C^-1`` (i.e. ``L = C^-1 M C`` in the spec's row-vector form),
  and it ends at ``start + length * G @ direction``.
* AMC: ``:FULLY-SPECIFIED``, ``:DEGREES`` (or ``:RADIANS``), 120 Hz unless told; another
  header line is refused, and so is a frame number that does not follow the one
  before (a frame block repeated or out of order).
* The up axis is told by the animated skeleton (head above the feet,
  :func:`~imitwalk.mocap.orient.decide_up`; CMU's ASF axes are y-up) unless ``up=``
  is given, and mapped to z up (:data:`~imitwalk.mocap._common.UP_TO_Z_UP`).
"""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import numpy as np

from imitwalk.errors import MocapError, unknown_name
from imitwalk.mocap._common import UP_AXES, check_keypoints, euler_matrices, read_lines, z_up
from imitwalk.mocap.asf import Bone, Skeleton, read_asf
from imitwalk.mocap.bounds import check_leg, check_motion, check_rate, drop_channels
from imitwalk.mocap.motion import LOWER_BODY, Motion
from imitwalk.mocap.orient import decide_up

__all__ = ["Bone", "Skeleton", "read_amc", "read_asf"]

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


#: The header lines of an AMC file (the Acclaim format's only ones).
HEADERS = (":FULLY-SPECIFIED", ":DEGREES", ":RADIANS")


class _AmcValues(NamedTuple):
    """An AMC's frame count ``T``, bone -> ``(T, n_dof)`` values (AMC angle unit), bone ->
    ``(T,)`` line numbers, and the AMC angle scale to degrees."""

    n: int
    values: dict[str, np.ndarray]
    lines: dict[str, np.ndarray]
    angle_scale: float


def _parse_amc(lines: list[str], skel: Skeleton, src: str) -> _AmcValues:
    """Parse the AMC's lines against its skeleton (see :class:`_AmcValues`)."""
    rows: dict[str, list[list[float]]] = {}
    at: dict[str, list[int]] = {}
    counts: list[int] = []
    frame = None
    angle_scale = 1.0
    for i, ln in enumerate(lines):
        tok = ln.split()
        if not tok or tok[0].startswith("#"):
            continue
        if tok[0].startswith(":"):
            if tok[0].upper() not in HEADERS:
                raise MocapError(
                    f"{src}: line {i + 1}: unknown AMC header {tok[0]!r}; "
                    f"valid: {', '.join(HEADERS)}"
                )
            angle_scale = float(np.degrees(1.0)) if tok[0].upper() == ":RADIANS" else angle_scale
            continue
        if len(tok) == 1 and tok[0].isdigit():
            if frame is not None and int(tok[0]) <= frame:
                raise MocapError(
                    f"{src}: line {i + 1}: frame {int(tok[0])} comes after frame {frame} "
                    "(a frame block repeated or out of order)"
                )
            frame = int(tok[0])
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
        if ndof:
            rows.setdefault(name, []).append(values)
            at.setdefault(name, []).append(i + 1)
        counts[-1] += 1
    if not counts:
        raise MocapError(f"{src}: no frames (not an AMC file?)")
    n = len(counts)
    for name, bone in skel.bones.items():
        if bone.dof and len(rows.get(name, [])) != n:
            got = len(rows.get(name, []))
            raise MocapError(f"{src}: bone {name!r} of the ASF appears in {got} of {n} frames")
    arrays = {k: np.array(v, dtype=float).reshape(n, -1) for k, v in rows.items()}
    return _AmcValues(n, arrays, {k: np.array(v) for k, v in at.items()}, angle_scale)


def _forward_kinematics(
    skel: Skeleton, values: dict[str, np.ndarray], n: int, amc_scale: float
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Start and end ``(T, 3)`` of each bone in ASF axes [m] (``amc_scale``: AMC angle
    unit -> degrees)."""
    scale = skel.metres_per_unit
    start: dict[str, np.ndarray] = {}
    end: dict[str, np.ndarray] = {}
    rot: dict[str, np.ndarray] = {}
    for name, bone in skel.bones.items():
        vals = values.get(name, np.zeros((n, 0)))
        rot_axes = "".join(d[1] for d in bone.dof if d[0] == "r")
        rot_cols = [k for k, d in enumerate(bone.dof) if d[0] == "r"]
        m = euler_matrices(rot_axes, vals[:, rot_cols] * amc_scale, intrinsic=False)
        c = euler_matrices(bone.axis_order, bone.axis[None, :] * skel.angle_scale, intrinsic=False)
        local = c[0] @ m @ c[0].T  # (T, 3, 3)
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
    return start, end


def _used_bones(skel: Skeleton, sources: dict[str, tuple[str, str]]) -> set[str]:
    """Bones whose DOFs move a keypoint: the ancestors of each keypoint's bone, and the
    bone itself when the keypoint is its end."""
    used = {"root"}
    for bone, where in sources.values():
        if where == "end":
            used.add(bone)
        at = skel.bones[bone].parent
        while at is not None and at not in used:
            used.add(at)
            at = skel.bones[at].parent
    return used


def read_amc(
    path: str | Path, skeleton: str | Path, *, fps: float = 120.0, up: str | None = None
) -> Motion:
    """Read an AMC motion with its ASF skeleton.

    Args:
        path: the ``.amc`` file; skeleton: its ``.asf`` file; fps: frame rate [Hz];
        up: the ASF's up axis (``x y z -x -y -z``); None tells it from the motion.

    Returns:
        a :class:`Motion`: ``data`` ``(T, D)`` AMC values (root translation in ASF units,
        angles as in the file), ``keypoints`` ``(T, 3)`` [m] z up, ``meta["segments_m"]``
        bone lengths [m], ``meta["skeleton"]`` the ASF path.
    """
    src = str(path)
    if up is not None and up not in UP_AXES:
        raise unknown_name("up axis", up, UP_AXES, MocapError)
    fps = check_rate(fps, src)
    skel = read_asf(skeleton)
    n, values, at, amc_scale = _parse_amc(read_lines(path), skel, src)
    sources = {}
    for key, options in _KEYPOINT_BONES.items():
        hit = next(((b, w) for b, w in options if b in skel.bones), None)
        if hit is not None:
            sources[key] = hit
    missing = [k for k in LOWER_BODY if k not in sources]
    if missing:
        raise MocapError(
            f"{skel.source}: no bones for keypoints {', '.join(missing)}; "
            f"bones: {', '.join(skel.bones)}"
        )
    channels = tuple(f"{b}.{d}" for b in skel.bones if b in values for d in skel.bones[b].dof)
    data = np.concatenate([np.zeros((n, 0))] + [values[b] for b in skel.bones if b in values], 1)
    used_bones = _used_bones(skel, sources)
    used = np.array([c.split(".", 1)[0] in used_bones for c in channels], dtype=bool)
    for b in skel.bones:
        if b in used_bones and b in values and not np.all(np.isfinite(values[b])):
            t, k = (int(i[0]) for i in np.nonzero(~np.isfinite(values[b])))
            raise MocapError(
                f"{src}: line {at[b][t]}: {b}.{skel.bones[b].dof[k]} is {values[b][t, k]}, "
                "and it moves a keypoint"
            )
    data, channels, dropped = drop_channels(data, channels, used, src)
    clean = {b: np.where(np.isfinite(v), v, 0.0) for b, v in values.items()}
    scale = skel.metres_per_unit
    start, end = _forward_kinematics(skel, clean, n, amc_scale)
    found = {k: (start if w == "start" else end)[b] for k, (b, w) in sources.items()}
    guessed = up is None
    if up is None:
        feet = np.stack([found[k] for k in ("l_ankle", "r_ankle", "l_toe", "r_toe")], axis=1)
        with np.errstate(all="ignore"):  # an absurd :units length overflows: refused below
            leg = float(np.median(np.linalg.norm(found["l_knee"] - found["l_hip"], axis=1)))
            leg += float(np.median(np.linalg.norm(found["l_ankle"] - found["l_knee"], axis=1)))
        check_leg(leg, skel.source, "check the ASF :units length")
        top = found.get("head", found.get("neck", found["pelvis"]))
        up, _ = decide_up(top, feet, leg, skel.source)
    keypoints = check_keypoints({k: z_up(v, up) for k, v in found.items()}, src, n)
    meta = {
        "skeleton": skel.source,
        "metres_per_unit": scale,
        "up_axis": up,
        "up_guessed": guessed,
        "segments_m": {b.name: b.length * scale for b in skel.bones.values() if b.parent},
        "dropped_channels": dropped,
    }
    motion = Motion(fps, channels, data, keypoints, src, "amc", meta=meta)
    return check_motion(motion, "check the ASF :units length")
