"""Which joint of a skeleton is the pelvis, a hip, a knee, ...: by name, by hand, by structure.

1. **By hand**: ``--joint-names FILE.json`` maps keypoints to the file's joint names,
   ``{"l_knee": "Bone.007", ...}`` (:func:`load_joint_names`); it wins over the rest.
2. **By name**: a name is normalised (lower case; no namespace ``mixamorig:``, no
   ``Bip01`` prefix, no separators ``_ . - |`` or spaces, no prefix shared by every
   joint such as ``Character1_``) and looked up in :data:`CENTRAL` / :data:`SIDED`.
   A sided name carries ``left``/``l`` or ``right``/``r`` before or after the part:
   CMU ``LeftUpLeg``, Mixamo ``mixamorig:LeftUpLeg``, LAFAN1 ``LeftToe``, ``UpperLeg_L``,
   ``l_thigh``, ``thigh.L``, ``Bip01 L Calf``. A foot without a toe joint gives its
   End Site as the toe.
3. **By structure**, for the legs the names leave out (:func:`leg_chains`): the two
   mirror-image chains (same length within 10 %) below the joint nearest the root that
   has them; in each chain the two consecutive bones that are longest together are the
   thigh and the shank, so hip, knee and ankle follow, and the next joint (or End Site)
   is the toe. Which chain is the left one is told by the direction of travel
   (:func:`assign_sides`).
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from imitwalk.errors import MocapError, unknown_name
from imitwalk.mocap.motion import KEYPOINTS
from imitwalk.mocap.skeleton import Joint, bone_lengths, children

__all__ = [
    "CENTRAL",
    "SIDED",
    "LegChain",
    "assign_sides",
    "leg_chains",
    "load_joint_names",
    "name_roles",
    "normalise",
]

#: Unsided keypoint -> normalised joint names tried in order.
CENTRAL: dict[str, tuple[str, ...]] = {
    "pelvis": ("hips", "pelvis", "hip", "root"),
    "neck": ("neck", "neck1", "neck01", "neckbase"),
    "head": ("head",),
}
#: Sided keypoint part -> normalised joint names (without the side) tried in order.
SIDED: dict[str, tuple[str, ...]] = {
    "hip": ("upleg", "upperleg", "thigh", "hip", "femur"),
    "knee": ("knee", "shin", "lowerleg", "calf", "leg", "tibia"),
    "ankle": ("foot", "ankle"),
    "toe": ("toebase", "toe", "toes", "toe0", "ball"),
    "shoulder": ("arm", "upperarm", "humerus", "shoulder"),
    "elbow": ("forearm", "lowerarm", "elbow", "radius"),
    "wrist": ("hand", "wrist"),
}
LEG_PARTS = ("hip", "knee", "ankle", "toe")


def candidates(key: str) -> tuple[str, ...]:
    """Normalised joint names that give keypoint ``key``, best first."""
    if key in CENTRAL:
        return CENTRAL[key]
    side, part = key.split("_")
    words = ("left", "l") if side == "l" else ("right", "r")
    return tuple(c for b in SIDED[part] for w in words for c in (w + b, b + w))


def normalise(name: str) -> str:
    """A joint name reduced for lookup: ``"mixamorig:Left_UpLeg"`` -> ``"leftupleg"``."""
    name = name.rsplit(":", 1)[-1].rsplit("|", 1)[-1].lower()
    return re.sub(r"^bip0*1", "", re.sub(r"[\s_.\-]", "", name))


def _by_name(joints: list[Joint]) -> dict[str, int]:
    names = [(j, normalise(jt.name)) for j, jt in enumerate(joints) if not jt.end_site]
    common = _common_prefix([n for _, n in names]) if len(names) > 1 else ""
    out: dict[str, int] = {}
    for j, n in names:
        out.setdefault(n, j)
        if len(common) >= 3:
            out.setdefault(n[len(common) :], j)
    return out


def _common_prefix(names: list[str]) -> str:
    first, last = min(names), max(names)
    k = 0
    while k < min(len(first), len(last)) and first[k] == last[k]:
        k += 1
    return first[:k]


def load_joint_names(path: str | Path) -> dict[str, str]:
    """Read a ``--joint-names`` file: a JSON object keypoint -> joint name."""
    p = Path(path)
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        raise MocapError(f"cannot read joint names {p}: {exc}".replace("\n", " ")) from None
    if not isinstance(doc, dict) or not all(isinstance(v, str) for v in doc.values()):
        raise MocapError(
            f'{p}: expected a JSON object keypoint -> joint name, e.g. {{"l_knee": "LowerLeg_L"}}'
        )
    for key in doc:
        if key not in KEYPOINTS:
            raise unknown_name(f"keypoint in {p.name}", key, KEYPOINTS, MocapError)
    return dict(doc)


def name_roles(joints: list[Joint], src: str, by_hand: dict[str, str] | None = None) -> dict:
    """Keypoint -> joint index for the keypoints the names (and ``by_hand``) give."""
    found: dict[str, int] = {}
    index = {jt.name: j for j, jt in reversed(list(enumerate(joints)))}
    for key, name in (by_hand or {}).items():
        if name not in index:
            raise unknown_name(f"joint of {src}", name, index, MocapError)
        found[key] = index[name]
    by_name = _by_name(joints)
    for key in KEYPOINTS:
        hit = next((by_name[c] for c in candidates(key) if c in by_name), None)
        if hit is None and key.endswith("_toe") and f"{key[0]}_ankle" in found:
            ankle = found[f"{key[0]}_ankle"]  # no toe joint: use the foot's End Site
            hit = next(
                (j for j, jt in enumerate(joints) if jt.end_site and jt.parent == ankle), None
            )
        if hit is not None:
            found.setdefault(key, hit)
    return found


@dataclass(frozen=True)
class LegChain:
    """One leg found by structure: joint indices of the pelvis and of the leg's joints."""

    pelvis: int
    hip: int
    knee: int
    ankle: int
    toe: int


def _chain(pelvis: int, path: list[int], bone: np.ndarray) -> LegChain | None:
    nodes = [pelvis, *path]  # nodes[k] ends the bone of length bone[nodes[k]]
    if len(nodes) < 5:  # pelvis, hip, knee, ankle, toe
        return None
    k = max(range(2, len(nodes) - 2), key=lambda k: bone[nodes[k]] + bone[nodes[k + 1]])
    total = sum(bone[n] for n in path)
    thigh, shank = bone[nodes[k]], bone[nodes[k + 1]]
    if thigh <= 0 or shank <= 0 or thigh + shank < 0.5 * total:
        return None
    return LegChain(pelvis, nodes[k - 1], nodes[k], nodes[k + 1], nodes[k + 2])


def leg_chains(joints: list[Joint], pos: np.ndarray) -> tuple[LegChain, LegChain] | None:
    """The two legs by structure (unsided; see the module docstring), or None.

    Args:
        pos: ``(T, J, 3)`` animated joint positions (any units).
    """
    kids = children(joints)
    bone = bone_lengths(joints, pos)
    reach = np.zeros(len(joints))  # longest path below each joint, and its next joint
    nxt = np.full(len(joints), -1)
    for j in reversed(range(len(joints))):  # children come after their parents
        for c in kids[j]:
            if nxt[j] < 0 or bone[c] + reach[c] > reach[j]:
                reach[j], nxt[j] = bone[c] + reach[c], c
    depth = np.zeros(len(joints), dtype=int)
    for j, jt in enumerate(joints):
        depth[j] = depth[jt.parent] + 1 if jt.parent >= 0 else 0

    def path(c: int) -> list[int]:
        out = [c]
        while nxt[out[-1]] >= 0:
            out.append(int(nxt[out[-1]]))
        return out

    best = None
    for p in sorted((j for j in range(len(joints)) if len(kids[j]) > 1), key=lambda j: depth[j]):
        if best is not None and depth[p] > best[0]:
            break
        lengths = {c: bone[c] + reach[c] for c in kids[p]}
        for a in kids[p]:
            for b in kids[p]:
                la, lb = lengths[a], lengths[b]
                if a >= b or min(la, lb) <= 0 or abs(la - lb) > 0.1 * max(la, lb):
                    continue
                left, right = _chain(p, path(a), bone), _chain(p, path(b), bone)
                if left and right and (best is None or la + lb > best[1]):
                    best = (depth[p], la + lb, (left, right))
    return None if best is None else best[2]


def assign_sides(
    legs: tuple[LegChain, LegChain], pos: np.ndarray, up: np.ndarray, forward: np.ndarray
) -> dict[str, int]:
    """Keypoint -> joint index of both legs and the pelvis: the left leg's hip is on the
    left of ``forward`` about ``up`` (both ``(3,)`` unit vectors in file axes)."""
    left = np.cross(up, forward)
    a, b = legs
    if np.median((pos[:, a.hip] - pos[:, b.hip]) @ left) < 0:
        a, b = b, a
    out = {"pelvis": a.pelvis}
    for side, leg in (("l", a), ("r", b)):
        out.update({f"{side}_{part}": getattr(leg, part) for part in LEG_PARTS})
    return out
