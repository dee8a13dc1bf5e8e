"""Which hinge plays which role, guessed from the kinematic tree (for ``robot import``).

The legs are the two chains of hinges from the floating base to its two lowest bodies,
one on each side. In a leg, the knee is the pitch hinge farthest from both ends of the
chain; the hinges above it are the hip (one yaw, one roll, one pitch), those below it the
ankle (pitch and roll). A hinge's kind comes from its axis at the zero posture (z: yaw,
x: roll, y: pitch) and its sign from that axis's direction, so that canonical angles
follow the right-hand rule about +x (forward), +y (left) and +z (up). Joint names are only
hints: where one disagrees with its axis, the axis wins and a note says so.

The arms are the two other chains that end farthest apart sideways; the torso is where
they meet (else the floating base). Hinges between the floating base and the torso are
the waist, those from the torso to the highest remaining body the neck. Every role
beyond the legs is optional.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from imitwalk.errors import RobotError
from imitwalk.robots.tree import Tree

__all__ = ["Guess", "Skeleton", "guess_roles"]

_HINTS = {"yaw": "yaw", "roll": "roll", "pitch": "pitch", "knee": "pitch"}


@dataclass(frozen=True)
class Guess:
    """One role: the MJCF ``joint`` that plays it, its ``sign`` (canonical = sign × MJCF
    angle) and why (``note``, one line)."""

    role: str
    joint: str
    sign: float
    note: str


@dataclass
class Skeleton:
    """What :func:`guess_roles` found.

    Attributes:
        guesses: the roles it could map; missed: one line per thing it could not.
        torso: the torso body; feet: side → the body the sole belongs to, and its subtree.
        arm_ends: side → the last body of each arm (for a hanging-arm posture).
        unmapped: hinges that play no role (held at the standing posture).
    """

    guesses: list[Guess] = field(default_factory=list)
    missed: list[str] = field(default_factory=list)
    torso: int = 0
    feet: dict[str, tuple[int, list[int]]] = field(default_factory=dict)
    arm_ends: dict[str, int] = field(default_factory=dict)
    unmapped: list[str] = field(default_factory=list)


def _side(tree: Tree, body: int) -> float:
    return float(tree.data.xpos[body][1] - tree.data.xpos[tree.root][1])


def _find_legs(tree: Tree, source: str) -> tuple[int, int, int]:
    """``(left leaf, right leaf, the body both legs hang from)``."""
    order = sorted(tree.leaves(), key=tree.lowest)
    for i, a in enumerate(order[:6]):
        for b in order[i + 1 :]:
            top = tree.common(a, b)
            if min(len(tree.hinges(tree.path(x, top))) for x in (a, b)) < 6:
                continue
            if _side(tree, a) * _side(tree, b) < 0:
                left, right = (a, b) if _side(tree, a) > 0 else (b, a)
                return left, right, top
    seen = ", ".join(tree.name(b) for b in tree.subtree(tree.root))
    raise RobotError(
        f"{source}: no legs found (two chains of at least 6 hinges from the floating base "
        f"to its lowest bodies, one on each side); bodies seen: {seen}"
    )


def _hint(name: str) -> str | None:
    low = name.lower()
    hits = {kind for word, kind in _HINTS.items() if word in low}
    return hits.pop() if len(hits) == 1 else None


def _pick(
    tree: Tree,
    sk: Skeleton,
    joints: list[int],
    kind: str,
    role: str,
    where: str,
    used: set[int],
) -> int | None:
    """The best-aligned hinge of ``kind`` among ``joints``; a guess for ``role``."""
    cands = [j for j in joints if tree.axis(j)[0] == kind and j not in used]
    if not cands:
        return None
    j = max(cands, key=lambda j: tree.axis(j)[2])
    _, sign, cos = tree.axis(j)
    name = tree.joint_name(j)
    axis = f"{'+' if sign > 0 else '-'}{dict(yaw='z', roll='x', pitch='y')[kind]}"
    note = f"axis {axis} ({np.degrees(np.arccos(min(cos, 1.0))):.0f} deg off), {where}"
    hint = _hint(name)
    if hint is not None and hint != kind:
        note += f"; its name says {hint}, its axis {kind}: the axis wins"
    sk.guesses.append(Guess(role, name, sign, note))
    used.add(j)
    return j


def _leg(tree: Tree, sk: Skeleton, side: str, leaf: int, top: int) -> None:
    word = {"l": "left", "r": "right"}[side]
    joints = tree.hinges(tree.path(leaf, top))
    ends = tree.anchor(joints[0]), tree.anchor(joints[-1])
    pitches = [j for j in joints if tree.axis(j)[0] == "pitch"]
    knee = max(
        pitches or joints,
        key=lambda j: min(np.linalg.norm(tree.anchor(j) - e) for e in ends),
    )
    used: set[int] = set()
    k = joints.index(knee)
    for kind in ("yaw", "roll", "pitch"):
        if _pick(tree, sk, joints[:k], kind, f"{side}_hip_{kind}", f"{word} hip", used) is None:
            sk.missed.append(f"{side}_hip_{kind}: no {kind} hinge above the {word} knee")
    if tree.axis(knee)[0] != "pitch":
        sk.missed.append(f"{side}_knee: no pitch hinge in the {word} leg")
    else:
        _pick(tree, sk, [knee], "pitch", f"{side}_knee", f"mid-leg on the {word} side", used)
    last = knee
    for kind in ("pitch", "roll"):
        j = _pick(tree, sk, joints[k + 1 :], kind, f"{side}_ankle_{kind}", f"{word} ankle", used)
        if j is None:
            sk.missed.append(f"{side}_ankle_{kind}: no {kind} hinge below the {word} knee")
        else:
            last = max(last, j, key=joints.index)
    foot = int(tree.model.jnt_bodyid[last])
    sk.feet[side] = (foot, tree.subtree(foot))
    sk.unmapped += [tree.joint_name(j) for j in joints if j not in used]


def _arm(tree: Tree, sk: Skeleton, side: str, leaf: int) -> None:
    word = {"l": "left", "r": "right"}[side]
    joints = tree.hinges(tree.path(leaf, sk.torso))
    used: set[int] = set()
    where = f"{word} shoulder"
    for kind, role in (("pitch", "shoulder_pitch"), ("roll", "shoulder_roll"), ("yaw", "arm_yaw")):
        _pick(tree, sk, joints[:3], kind, f"{side}_{role}", where, used)
    rest = joints[max((joints.index(j) for j in used), default=-1) + 1 :]
    elbow = _pick(tree, sk, rest[:1], "pitch", f"{side}_elbow", f"{word} elbow", used)
    if elbow is None:
        axis = {"yaw": "z", "roll": "x", "pitch": "y"}[tree.axis(rest[0])[0]] if rest else ""
        turns = f" ({tree.joint_name(rest[0])} turns about {axis})" if rest else ""
        sk.missed.append(f"{side}_elbow: no hinge about y after the {word} shoulder{turns}")
    else:
        after = joints[joints.index(elbow) + 1 :]
        forearm = tree.data.xpos[leaf] - tree.anchor(elbow)
        if after and np.linalg.norm(forearm) > 1e-6:
            j = after[0]
            a = tree.data.xaxis[j]
            along = (
                float(a @ forearm) / np.linalg.norm(forearm) / max(float(np.linalg.norm(a)), 1e-12)
            )
            if abs(along) > 0.9:
                sign = -1.0 if along > 0 else 1.0  # positive: as a yaw of the hanging arm
                note = f"turns about the {word} forearm"
                sk.guesses.append(Guess(f"{side}_hand", tree.joint_name(j), sign, note))
                used.add(j)
    sk.arm_ends[side] = leaf
    sk.unmapped += [tree.joint_name(j) for j in joints if j not in used]


def guess_roles(tree: Tree, source: str = "the model") -> Skeleton:
    """Map the hinges of ``tree`` to canonical roles (see the module's docstring).

    Raises:
        RobotError: no two legs can be found (the message lists the bodies seen).
    """
    sk = Skeleton(torso=tree.root)
    left, right, top = _find_legs(tree, source)
    for side, leaf in (("l", left), ("r", right)):
        _leg(tree, sk, side, leaf, top)
    legs = set(tree.path(left)) | set(tree.path(right))
    rest = [b for b in tree.leaves() if b not in legs]
    pairs = [
        (a, b)
        for a in rest
        for b in rest
        if _side(tree, a) > 0 > _side(tree, b)
        and min(len(tree.hinges(tree.path(x, tree.common(a, b)))) for x in (a, b)) >= 3
    ]
    if pairs:
        la, ra = max(pairs, key=lambda p: _side(tree, p[0]) - _side(tree, p[1]))
        sk.torso = tree.common(la, ra)
        for side, leaf in (("l", la), ("r", ra)):
            _arm(tree, sk, side, leaf)
    else:
        sk.missed.append("arms: no two chains of 3 or more hinges, one on each side")
    waist = tree.hinges(tree.path(sk.torso)) if sk.torso != tree.root else []
    used: set[int] = set()
    if waist:
        _pick(tree, sk, waist, "yaw", "waist_yaw", "between the base and the torso", used)
        sk.unmapped += [tree.joint_name(j) for j in waist if j not in used]
    below = [b for b in rest if sk.torso == tree.root or sk.torso in tree.path(b)[:-1]]
    heads = [b for b in below if b not in sk.arm_ends.values()]
    heads = [b for b in heads if tree.hinges(tree.path(b, sk.torso))]
    if heads:
        head = max(heads, key=lambda b: float(tree.data.xpos[b][2]))
        neck = tree.hinges(tree.path(head, sk.torso))
        _pick(tree, sk, neck, "yaw", "neck_yaw", "neck", used)
        _pick(tree, sk, neck, "pitch", "neck_pitch", "neck", used)
        sk.unmapped += [tree.joint_name(j) for j in neck if j not in used]
    mapped = {g.joint for g in sk.guesses}
    every = {tree.joint_name(j) for j in tree.hinges(tree.subtree(tree.root))}
    sk.unmapped = sorted((every - mapped) | (set(sk.unmapped) - mapped))
    return sk
