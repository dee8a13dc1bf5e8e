"""BVH reader: hierarchy + motion channels -> forward kinematics -> keypoints.

* Rotation channels in any order per joint, applied as listed (intrinsic: channels
  ``Zrotation Yrotation Xrotation`` give ``R = Rz @ Ry @ Rx``), degrees.
* Position channels on any joint replace the matching component of its OFFSET (the
  Blender convention; the root's position channels are its position).
* Units: ``"m"``, ``"cm"``, ``"mm"``, ``"inch"`` or ``"cmu"`` (the CMU ASF unit,
  1/0.45 inch = 5.64 cm); ``units=None`` picks the one that makes the rest-pose
  standing hip height (hip joint to the lowest point of the leg) closest to 0.9 m.
* Up axis: told by the rest-pose leg (hip -> ankle points down); y-up files are mapped
  to z-up by (x, y, z) -> (x, -z, y).
* Frame 0 of a CMU/cgspeed conversion is a T-pose added by the converter (integer
  rotation channels in frame 0 only); it is dropped and ``meta["skipped_frames"] == 1``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from imitwalk.errors import MocapError, unknown_name
from imitwalk.mocap._common import (
    check_keypoints,
    euler_matrices,
    read_lines,
    snap_rate,
    up_axis,
    z_up,
)
from imitwalk.mocap.motion import KEYPOINTS, Motion

__all__ = ["UNITS", "read_bvh"]

#: Length units a BVH may use -> metres per unit.
UNITS: dict[str, float] = {"m": 1.0, "cm": 0.01, "mm": 0.001, "inch": 0.0254, "cmu": 0.0254 / 0.45}

#: Standing hip height [m] of an adult, used to guess the units.
HIP_HEIGHT_M = 0.9

# Keypoint -> normalised joint names tried in order (normalised: lower case, no namespace
# "xxx:", no "_ .-" or spaces, no 3ds Max "Bip01" prefix). Sided names accept the
# prefixes/suffixes "left"/"l" (resp. "right"/"r"): LeftUpLeg, L_Thigh, upperleg.l, ...
_CENTRAL = {
    "pelvis": ("hips", "pelvis", "hip", "root"),
    "neck": ("neck", "neck1", "neckbase"),
    "head": ("head",),
}
_SIDED = {
    "hip": ("upleg", "upperleg", "thigh", "hip", "femur"),
    "knee": ("knee", "shin", "lowerleg", "calf", "leg", "tibia"),
    "ankle": ("foot", "ankle"),
    "toe": ("toebase", "toe", "toes", "toe0", "ball"),
    "shoulder": ("arm", "upperarm", "humerus", "shoulder"),
    "elbow": ("forearm", "lowerarm", "elbow", "radius"),
    "wrist": ("hand", "wrist"),
}


def _candidates(key: str) -> tuple[str, ...]:
    if key in _CENTRAL:
        return _CENTRAL[key]
    side, part = key.split("_")
    words = ("left", "l") if side == "l" else ("right", "r")
    return tuple(c for b in _SIDED[part] for w in words for c in (w + b, b + w))


def _normalise(name: str) -> str:
    name = name.rsplit(":", 1)[-1].rsplit("|", 1)[-1].lower()
    return re.sub(r"^bip0*1", "", re.sub(r"[\s_.\-]", "", name))


@dataclass
class _Joint:
    name: str
    parent: int
    offset: np.ndarray
    channels: list[str] = field(default_factory=list)
    end_site: bool = False


def _parse_hierarchy(lines: list[str], src: str) -> tuple[list[_Joint], int]:
    """Parse HIERARCHY; return joints (parents first) and the index of the MOTION line."""
    joints: list[_Joint] = []
    stack: list[int] = []
    pending: int | None = None
    for i, raw in enumerate(lines):
        tok = raw.split()
        if not tok:
            continue
        key = tok[0].upper()
        where = f"{src}: line {i + 1}"
        if key == "MOTION":
            if stack or not joints:
                raise MocapError(f"{where}: MOTION before the hierarchy is closed")
            return joints, i
        if key in ("ROOT", "JOINT") or (key == "END" and len(tok) > 1):
            is_end = key == "END"
            if not is_end and len(tok) < 2:
                raise MocapError(f"{where}: {tok[0]} without a name")
            name = "" if is_end else raw.split(None, 1)[1].strip().rstrip("{").strip()
            parent = stack[-1] if stack else -1
            if is_end:
                name = f"{joints[parent].name}_end" if parent >= 0 else "end"
            joints.append(_Joint(name, parent, np.zeros(3), end_site=is_end))
            pending = len(joints) - 1
            if raw.rstrip().endswith("{"):
                stack.append(pending)
                pending = None
        elif key == "{":
            if pending is None:
                raise MocapError(f"{where}: '{{' without a joint")
            stack.append(pending)
            pending = None
        elif key == "}":
            if not stack:
                raise MocapError(f"{where}: unbalanced '}}'")
            stack.pop()
        elif key == "OFFSET":
            if not stack or len(tok) < 4:
                raise MocapError(f"{where}: malformed OFFSET")
            joints[stack[-1]].offset = _floats(tok[1:4], where)
        elif key == "CHANNELS":
            if not stack or len(tok) < 2 or len(tok) != int(_floats(tok[1:2], where)[0]) + 2:
                raise MocapError(f"{where}: malformed CHANNELS")
            chans = [c.lower() for c in tok[2:]]
            bad = [c for c in chans if c[:1] not in "xyz" or c[1:] not in ("position", "rotation")]
            if bad:
                raise MocapError(f"{where}: unknown channel {tok[2 + chans.index(bad[0])]}")
            joints[stack[-1]].channels = chans
        elif key != "HIERARCHY":
            raise MocapError(f"{where}: unexpected {tok[0]!r} in the hierarchy")
    raise MocapError(f"{src}: line {len(lines)}: file ends without a MOTION section (truncated?)")


def _floats(tokens: list[str], where: str) -> np.ndarray:
    try:
        return np.array([float(t) for t in tokens])
    except ValueError:
        raise MocapError(f"{where}: non-numeric value in {' '.join(tokens)[:40]!r}") from None


def _parse_motion(lines: list[str], start: int, n_chan: int, src: str) -> tuple[np.ndarray, float]:
    """Parse the MOTION section from line index ``start``; return ``(T, C)`` values and dt [s]."""
    header: dict[str, str] = {}
    i = start + 1
    for want in ("frames", "frame time"):
        while i < len(lines) and not lines[i].strip():
            i += 1
        if i >= len(lines) or ":" not in lines[i]:
            raise MocapError(f"{src}: line {i + 1}: expected '{want.title()}:' (file truncated?)")
        k, v = lines[i].split(":", 1)
        if k.strip().lower() != want:
            raise MocapError(f"{src}: line {i + 1}: expected '{want.title()}:', got {k.strip()!r}")
        header[want] = v.strip()
        i += 1
    n_frames = int(_floats([header["frames"]], f"{src}: line {start + 2}")[0])
    dt = float(_floats([header["frame time"]], f"{src}: line {start + 3}")[0])
    if n_frames < 1 or dt <= 0:
        raise MocapError(f"{src}: bad motion header Frames: {n_frames}, Frame Time: {dt}")
    rows: list[np.ndarray] = []
    for j in range(i, len(lines)):
        tok = lines[j].split()
        if not tok:
            continue
        if len(rows) == n_frames:
            raise MocapError(f"{src}: line {j + 1}: more frame lines than Frames: {n_frames}")
        if len(tok) != n_chan:
            raise MocapError(f"{src}: line {j + 1}: {len(tok)} values, expected {n_chan} channels")
        rows.append(_floats(tok, f"{src}: line {j + 1}"))
    if len(rows) < n_frames:
        raise MocapError(
            f"{src}: line {len(lines)}: file ends after {len(rows)} of {n_frames} frames "
            "(truncated?)"
        )
    return np.array(rows), dt


def _forward_kinematics(joints: list[_Joint], values: np.ndarray, scale: float) -> np.ndarray:
    """Joint positions ``(T, J, 3)`` in file axes, metres, from ``(T, C)`` channel values."""
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


def _keypoint_joints(joints: list[_Joint], src: str) -> dict[str, int]:
    by_name: dict[str, int] = {}
    for j, jt in enumerate(joints):
        if not jt.end_site:
            by_name.setdefault(_normalise(jt.name), j)
    found: dict[str, int] = {}
    for key in KEYPOINTS:
        hit = next((by_name[c] for c in _candidates(key) if c in by_name), None)
        if hit is None and key.endswith("_toe") and f"{key[0]}_ankle" in found:
            ankle = found[f"{key[0]}_ankle"]  # no toe joint: use the foot's End Site
            hit = next(
                (j for j, jt in enumerate(joints) if jt.end_site and jt.parent == ankle), None
            )
        if hit is not None:
            found[key] = hit
    missing = [k for k in KEYPOINTS if k not in found]
    if missing:
        names = ", ".join(jt.name for jt in joints if not jt.end_site)
        raise MocapError(
            f"{src}: no joint found for keypoints {', '.join(missing)}; joints: {names}"
        )
    return found


def _rest_leg(joints: list[_Joint], hip: int, ankle: int, src: str) -> tuple[str, float]:
    """Up axis and standing hip height (hip joint to the lowest point of its leg, file
    units) of the rest pose (all rotations zero)."""
    rest = np.zeros((len(joints), 3))
    leg = [hip]
    for j, jt in enumerate(joints):  # parents come first
        rest[j] = jt.offset + (rest[jt.parent] if jt.parent >= 0 else 0.0)
        if jt.parent in leg:
            leg.append(j)
    up = up_axis(rest[ankle] - rest[hip], src)
    k = "xyz".index(up)
    return up, float(rest[hip, k] - rest[leg, k].min())


def read_bvh(
    path: str | Path, *, units: str | None = None, skip_tpose: bool | None = None
) -> Motion:
    """Read a BVH file.

    Args:
        path: the ``.bvh`` file.
        units: length unit of the file, one of :data:`UNITS`; None guesses it from the
            standing hip height.
        skip_tpose: drop frame 0 if it is a converter T-pose; None detects it (integer
            rotation channels in frame 0 but not in frame 1).

    Returns:
        a :class:`Motion`: ``data`` ``(T, C)`` channel values as read (degrees, file
        units), ``keypoints`` ``(T, 3)`` [m] z up; ``meta`` has ``units``,
        ``units_guessed``, ``up_axis``, ``hip_height_m``, ``skipped_frames``.
    """
    src = str(path)
    if units is not None and units not in UNITS:
        raise unknown_name("BVH unit", units, UNITS, MocapError)
    lines = read_lines(path)
    joints, motion_line = _parse_hierarchy(lines, src)
    channels = tuple(f"{jt.name}.{c.capitalize()}" for jt in joints for c in jt.channels)
    values, dt = _parse_motion(lines, motion_line, len(channels), src)
    is_rot = np.array([c.endswith("rotation") for c in channels])
    first_int = bool(np.all(values[0, is_rot] == np.round(values[0, is_rot])))
    tpose = bool(
        first_int
        and len(values) > 1
        and not np.all(values[1, is_rot] == np.round(values[1, is_rot]))
    )
    skip = tpose if skip_tpose is None else skip_tpose
    values = values[1:] if skip else values
    if len(values) < 1:
        raise MocapError(f"{src}: no motion frames")
    kp_joint = _keypoint_joints(joints, src)
    up, hip_height = _rest_leg(joints, kp_joint["l_hip"], kp_joint["l_ankle"], src)
    guessed = units is None
    if guessed:
        if hip_height <= 0:
            raise MocapError(f"{src}: cannot guess units (rest-pose hip height {hip_height})")
        units = min(UNITS, key=lambda u: abs(np.log(hip_height * UNITS[u] / HIP_HEIGHT_M)))
    pos = z_up(_forward_kinematics(joints, values, UNITS[units]), up)
    keypoints = check_keypoints({k: pos[:, j] for k, j in kp_joint.items()}, src, len(values))
    meta = {
        "units": units,
        "units_guessed": guessed,
        "up_axis": up,
        "hip_height_m": hip_height * UNITS[units],
        "skipped_frames": int(skip),
        "tpose_detected": tpose,
        "joints": {k: joints[j].name for k, j in kp_joint.items()},
    }
    return Motion(snap_rate(1.0 / dt), channels, values, keypoints, src, "bvh", meta=meta)
