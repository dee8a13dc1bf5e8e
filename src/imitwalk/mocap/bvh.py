"""BVH reader: hierarchy + motion channels -> forward kinematics -> keypoints.

The posture is read from the motion, not from the rest pose: forward kinematics runs
over the frames first (:mod:`imitwalk.mocap.skeleton`: 0, 3 or 6 channels on any
joint, in any order), and the animated skeleton then tells

* which joints are the legs (:mod:`imitwalk.mocap.roles`: by name across CMU,
  Mixamo, LAFAN1, ``*_L``/``l_*`` rigs; by structure where names are silent; by hand
  with ``joint_names=``);
* the up axis, the direction of travel and the units (:mod:`imitwalk.mocap.orient`);
  ``up=`` and ``units=`` override the guesses.

Units: ``"m"``, ``"cm"``, ``"mm"``, ``"inch"`` or ``"cmu"`` (the CMU ASF unit, 1/0.45
inch = 5.64 cm). The file's up axis is mapped to z up (:data:`~imitwalk.mocap._common.
UP_TO_Z_UP`; y-up by (x, y, z) -> (x, -z, y)). Frame 0 of a CMU/cgspeed conversion is a
T-pose added by the converter (integer rotation channels in frame 0 only); it is dropped
and ``meta["skipped_frames"] == 1``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from imitwalk.errors import MocapError, unknown_name
from imitwalk.mocap._common import UP_AXES, check_keypoints, read_lines, snap_rate, z_up
from imitwalk.mocap.bounds import check_motion, drop_channels
from imitwalk.mocap.bvh_parse import BvhFile, parse_bvh
from imitwalk.mocap.motion import KEYPOINTS, LOWER_BODY, Motion
from imitwalk.mocap.orient import (
    UNITS_FLAG,
    UP_VECTORS,
    axis_name,
    decide_forward,
    decide_units,
    decide_up,
)
from imitwalk.mocap.roles import LegChain, assign_sides, leg_chains, load_joint_names, name_roles
from imitwalk.mocap.skeleton import Joint, children, forward_kinematics, moving_columns

__all__ = ["UNITS", "read_bvh"]

#: Length units a BVH may use -> metres per unit.
UNITS: dict[str, float] = {"m": 1.0, "cm": 0.01, "mm": 0.001, "inch": 0.0254, "cmu": 0.0254 / 0.45}

_FEET = ("l_ankle", "r_ankle", "l_toe", "r_toe")


def _skip_tpose(bvh: BvhFile, skip_tpose: bool | None, src: str) -> tuple[int, bool]:
    """Frames to drop at the start (0 or 1) and whether frame 0 looks like a T-pose."""
    is_rot = np.array([c.endswith("rotation") for c in bvh.channels], dtype=bool)
    v = bvh.values
    first_int = bool(np.all(v[0, is_rot] == np.round(v[0, is_rot])))
    tpose = bool(first_int and len(v) > 1 and not np.all(v[1, is_rot] == np.round(v[1, is_rot])))
    skip = tpose if skip_tpose is None else skip_tpose
    if skip and len(v) < 2:
        raise MocapError(f"{src}: no motion frames after the T-pose frame")
    return int(skip), tpose


def _upper_body(joints: list[Joint], pelvis: int, hips: list[int]) -> list[int]:
    """Joints below the pelvis that are not in a leg (the legs' branches left out)."""
    kids = children(joints)
    leg_roots = set()
    for h in hips:
        while joints[h].parent not in (pelvis, -1):
            h = joints[h].parent
        leg_roots.add(h)
    out, stack = [], [c for c in kids[pelvis] if c not in leg_roots]
    while stack:
        j = stack.pop()
        out.append(j)
        stack.extend(kids[j])
    return out


def _legs(
    joints: list[Joint], pos: np.ndarray, named: dict[str, int], src: str
) -> tuple[tuple[LegChain, LegChain] | None, list[int], int, list[int]]:
    """Leg joints by name if the names give them all, else the two chains by structure."""
    if all(k in named for k in LOWER_BODY):
        return None, [named[k] for k in _FEET], named["pelvis"], [named["l_hip"], named["r_hip"]]
    chains = leg_chains(joints, pos)
    if chains is None:
        names = ", ".join(jt.name for jt in joints if not jt.end_site)
        raise MocapError(
            f"{src}: cannot find the legs: no joints named like a hip, knee and ankle "
            f"(LeftUpLeg, UpperLeg_L, l_thigh, ...) and no two mirror-image chains below one "
            f"joint; joints: {names}; map them with --joint-names FILE.json"
        )
    feet = [c.ankle for c in chains] + [c.toe for c in chains]
    return chains, feet, chains[0].pelvis, [c.hip for c in chains]


def read_bvh(
    path: str | Path,
    *,
    units: str | None = None,
    up: str | None = None,
    joint_names: str | Path | dict[str, str] | None = None,
    skip_tpose: bool | None = None,
) -> Motion:
    """Read a BVH file.

    Args:
        path: the ``.bvh`` file.
        units: length unit of the file, one of :data:`UNITS`; None guesses it from the
            animated leg length and pelvis height.
        up: the file's up axis, one of ``x y z -x -y -z``; None guesses it (head above
            the feet, the lowest foot at one height).
        joint_names: a JSON file (or dict) keypoint -> joint name, for rigs whose names
            are not recognised (see :mod:`imitwalk.mocap.roles`).
        skip_tpose: drop frame 0 if it is a converter T-pose; None detects it (integer
            rotation channels in frame 0 but not in frame 1).

    Returns:
        a :class:`Motion`: ``data`` ``(T, C)`` channel values as read (degrees, file
        units), ``keypoints`` ``(T, 3)`` [m] z up; ``meta`` has ``units``,
        ``units_guessed``, ``up_axis``, ``up_guessed``, ``up_reason``, ``forward_axis``
        (file axis nearest the direction of travel), ``leg_length_m``,
        ``pelvis_height_m``, ``skipped_frames``, ``joints`` (keypoint -> joint name),
        ``roles`` (``"names"`` or ``"structure"``), ``missing_keypoints``.
    """
    src = str(path)
    _check_options(units, up)
    by_hand = load_joint_names(joint_names) if isinstance(joint_names, str | Path) else joint_names
    bvh = parse_bvh(read_lines(path), src)
    skip, tpose = _skip_tpose(bvh, skip_tpose, src)
    values, rows = bvh.values[skip:], bvh.rows[skip:]
    clean = np.where(np.isfinite(values), values, 0.0)
    joints = bvh.joints
    pos = forward_kinematics(joints, clean, 1.0)  # (T, J, 3) file axes and units
    named = name_roles(joints, src, by_hand)
    chains, feet, pelvis, hips = _legs(joints, pos, named, src)
    leg = _checked_leg_length(pos, pelvis, hips, _knees(named, chains), feet, rows, src)
    top = _top(joints, pos, named, pelvis, hips)
    feet_pos = pos[:, feet]  # (T, 4, 3)
    up_guessed = up is None
    why = "given"
    if up is None:
        up, why = decide_up(top, feet_pos, leg, src)
    e_up = UP_VECTORS[up]
    fwd, fwd_how = decide_forward(pos[:, pelvis], feet_pos[:, :2], feet_pos[:, 2:], e_up, leg)
    roles = _sided_roles(named, chains, pos, e_up, fwd, src)
    height = float(np.median(pos[:, pelvis] @ e_up - np.min(feet_pos @ e_up, axis=1)))
    guessed = units is None
    units = decide_units(leg, height, UNITS, src) if units is None else units
    used = moving_columns(joints, roles.values())
    _check_used(values, bvh.channels, used, rows, src)
    data, channels, dropped = drop_channels(values, bvh.channels, used, src)
    pos_m = z_up(forward_kinematics(joints, clean, UNITS[units]), up)
    keypoints = check_keypoints(
        {k: pos_m[:, roles[k]] for k in KEYPOINTS if k in roles}, src, len(values)
    )
    meta = {
        "units": units,
        "units_guessed": guessed,
        "up_axis": up,
        "up_guessed": up_guessed,
        "up_reason": why,
        "forward_axis": axis_name(fwd) if np.any(fwd) else "",
        "forward_from": fwd_how,
        "leg_length_m": leg * UNITS[units],
        "pelvis_height_m": height * UNITS[units],
        "skipped_frames": skip,
        "tpose_detected": tpose,
        "joints": {k: joints[j].name for k, j in roles.items() if k in KEYPOINTS},
        "roles": "names" if chains is None else "structure",
        "missing_keypoints": tuple(k for k in KEYPOINTS if k not in roles),
        "dropped_channels": dropped,
    }
    fps = snap_rate(1.0 / bvh.frame_time)
    motion = Motion(fps, channels, data, keypoints, src, "bvh", meta=meta)
    return check_motion(motion, f"{UNITS_FLAG} (read as {units})")


def _leg_length(pos: np.ndarray, hips: list[int], knees: list[int], ankles: list[int]) -> float:
    """Mean over both legs of the median hip -> knee -> ankle length (units of ``pos``)."""
    out = []
    for hip, knee, ankle in zip(hips, knees, ankles, strict=True):
        thigh = np.linalg.norm(pos[:, knee] - pos[:, hip], axis=1)
        out.append(np.median(thigh + np.linalg.norm(pos[:, ankle] - pos[:, knee], axis=1)))
    return float(np.mean(out))


def _knees(named: dict[str, int], chains: tuple[LegChain, LegChain] | None) -> list[int]:
    if chains is None:
        return [named["l_knee"], named["r_knee"]]
    return [c.knee for c in chains]


def _centre(joints: list[Joint], pos: np.ndarray, pelvis: int, hips: list[int]) -> np.ndarray:
    """``(T, 3)`` mean of the upper-body joints (the pelvis if there are none)."""
    upper = [j for j in _upper_body(joints, pelvis, hips) if np.all(np.isfinite(pos[:, j]))]
    return pos[:, upper].mean(axis=1) if upper else pos[:, pelvis]


def _check_used(
    values: np.ndarray, channels: tuple[str, ...], used: np.ndarray, rows: np.ndarray, src: str
) -> None:
    """A non-finite value in a channel that moves a keypoint -> MocapError naming its line."""
    bad = ~np.isfinite(values) & used
    if bad.any():
        t, c = (int(i[0]) for i in np.nonzero(bad))
        raise MocapError(
            f"{src}: line {rows[t]}: channel {channels[c]} is {values[t, c]}, "
            "and it moves a keypoint"
        )


def _check_options(units: str | None, up: str | None) -> None:
    """An unknown unit or up axis -> MocapError listing the valid ones."""
    if units is not None and units not in UNITS:
        raise unknown_name("BVH unit", units, UNITS, MocapError)
    if up is not None and up not in UP_AXES:
        raise unknown_name("up axis", up, UP_AXES, MocapError)


def _checked_leg_length(
    pos: np.ndarray,
    pelvis: int,
    hips: list[int],
    knees: list[int],
    feet: list[int],
    rows: np.ndarray,
    src: str,
) -> float:
    """The legs' length (:func:`_leg_length`, units of ``pos`` ``(T, J, 3)``); MocapError
    if a leg joint's position overflows or the legs have zero length."""
    legs = [pelvis, *hips, *knees, *feet]
    if not np.all(np.isfinite(pos[:, legs])):
        t = int(np.flatnonzero(~np.all(np.isfinite(pos[:, legs]), axis=(1, 2)))[0])
        raise MocapError(
            f"{src}: line {rows[t]}: the legs' positions overflow (a value too large?)"
        )
    leg = _leg_length(pos, hips, knees, feet[:2])
    if not leg > 0:
        raise MocapError(
            f"{src}: the legs have zero length (hip, knee and ankle at one point in every "
            "frame): zero-length bones in the rest pose?"
        )
    return leg


def _top(
    joints: list[Joint], pos: np.ndarray, named: dict[str, int], pelvis: int, hips: list[int]
) -> np.ndarray:
    """``(T, 3)`` the body's top: the head, else the neck, else the upper body's centre."""
    top_j = next((named[k] for k in ("head", "neck") if k in named), None)
    return pos[:, top_j] if top_j is not None else _centre(joints, pos, pelvis, hips)


def _sided_roles(
    named: dict[str, int],
    chains: tuple[LegChain, LegChain] | None,
    pos: np.ndarray,
    e_up: np.ndarray,
    fwd: np.ndarray,
    src: str,
) -> dict[str, int]:
    """Keypoint -> joint: the named joints, and legs found by structure given their side
    (``e_up`` ``(3,)`` up, ``fwd`` ``(3,)`` direction of travel, file axes)."""
    roles = dict(named)
    if chains is not None:
        if not np.any(fwd):
            raise MocapError(
                f"{src}: cannot tell the left leg from the right (no travel, no toes); "
                "map them with --joint-names FILE.json"
            )
        roles = {**assign_sides(chains, pos, e_up, fwd), **named}
    return roles
