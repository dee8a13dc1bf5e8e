"""A robot's kinematic tree, read from its compiled model at the zero posture.

Helpers for drafting a joint map (:mod:`imitwalk.robots.draft`) and for building the
model (:mod:`imitwalk.robots.spec`): the floating base, each body's chain of hinges, the
lowest bodies, a hinge's axis in the world, and the footprint of a foot's collision
geoms. The world frame is the file's: z up; the robot faces +x with its left along +y.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable
from dataclasses import dataclass

import mujoco
import numpy as np

from imitwalk.errors import RobotError

__all__ = ["AXES", "Footprint", "Tree", "footprint"]

#: Canonical axes: yaw about +z, roll about +x, pitch about +y.
AXES = {
    "yaw": np.array([0.0, 0.0, 1.0]),
    "roll": np.array([1.0, 0.0, 0.0]),
    "pitch": np.array([0.0, 1.0, 0.0]),
}


@dataclass(frozen=True)
class Footprint:
    """The collision geoms of a foot seen from below (world frame, zero posture).

    ``centre`` ``(3,)`` the centre of their bottom face [m] (z: its height); ``half``
    ``(2,)`` half length (x) and half width (y) [m]; ``geoms`` the geom ids counted.
    """

    centre: np.ndarray
    half: np.ndarray
    geoms: tuple[int, ...]


def _colliding(model: mujoco.MjModel, g: int) -> bool:
    return bool(model.geom_contype[g] or model.geom_conaffinity[g])


def _box(model: mujoco.MjModel, data: mujoco.MjData, g: int) -> tuple[np.ndarray, np.ndarray]:
    """World-aligned bounding box of geom ``g``: centre ``(3,)`` and half sizes ``(3,)``."""
    rot = data.geom_xmat[g].reshape(3, 3)
    centre = data.geom_xpos[g] + rot @ model.geom_aabb[g, :3]
    return centre, np.abs(rot) @ model.geom_aabb[g, 3:]


def footprint(
    model: mujoco.MjModel, data: mujoco.MjData, bodies: Collection[int], near: float = 0.01
) -> Footprint:
    """The footprint of the colliding geoms of ``bodies`` whose bottom is within ``near``
    [m] of the lowest one (the sole, not the ankle bracket above it)."""
    geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] in set(bodies)]
    geoms = [g for g in geoms if _colliding(model, g)] or geoms
    if not geoms:
        raise RobotError("a foot body has no geoms to stand on")
    boxes = [_box(model, data, g) for g in geoms]
    low = min(c[2] - h[2] for c, h in boxes)
    keep = [(g, c, h) for g, (c, h) in zip(geoms, boxes, strict=True) if c[2] - h[2] <= low + near]
    lo = np.min([c[:2] - h[:2] for _, c, h in keep], axis=0)
    hi = np.max([c[:2] + h[:2] for _, c, h in keep], axis=0)
    centre = np.array([*(lo + hi) / 2, low])
    return Footprint(centre, (hi - lo) / 2, tuple(g for g, _, _ in keep))


class Tree:
    """The body tree of ``model`` at its zero posture (``qpos0``).

    Attributes:
        model, data: the model and its kinematics at ``qpos0``; root: the floating
        base (the heaviest body with a free joint).
    """

    def __init__(self, model: mujoco.MjModel, source: str = "the model"):
        self.model = m = model
        self.data = d = mujoco.MjData(m)
        mujoco.mj_kinematics(m, d)
        free = [
            b
            for b in range(1, m.nbody)
            if m.body_jntnum[b] and m.jnt_type[m.body_jntadr[b]] == mujoco.mjtJoint.mjJNT_FREE
        ]
        if not free:
            raise RobotError(
                f"{source} has no floating base: no body has a free joint (<freejoint/>); "
                "a robot fixed to the world cannot walk"
            )
        self.root = max(free, key=lambda b: float(m.body_subtreemass[b]))
        self.children: dict[int, list[int]] = {b: [] for b in range(m.nbody)}
        for b in range(1, m.nbody):
            self.children[int(m.body_parentid[b])].append(b)

    def name(self, body: int) -> str:
        """A body's name (``body<id>`` if it has none)."""
        return self.model.body(body).name or f"body{body}"

    def subtree(self, body: int) -> list[int]:
        """``body`` and every body below it."""
        out, todo = [], [body]
        while todo:
            b = todo.pop()
            out.append(b)
            todo.extend(self.children[b])
        return sorted(out)

    def path(self, body: int, top: int | None = None) -> list[int]:
        """Bodies from just below ``top`` (default: the root) down to ``body``."""
        top = self.root if top is None else top
        out = []
        while body not in (top, 0):
            out.append(body)
            body = int(self.model.body_parentid[body])
        if body != top:
            raise RobotError(f"body {self.name(out[-1])!r} is not below {self.name(top)!r}")
        return out[::-1]

    def hinges(self, bodies: Iterable[int]) -> list[int]:
        """Hinge joint ids of ``bodies``, in order."""
        m = self.model
        return [
            j
            for b in bodies
            for j in range(m.body_jntadr[b], m.body_jntadr[b] + m.body_jntnum[b])
            if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE
        ]

    def leaves(self) -> list[int]:
        """Bodies below the root with no children."""
        return [b for b in self.subtree(self.root) if b != self.root and not self.children[b]]

    def lowest(self, body: int) -> float:
        """Lowest point of ``body``'s geoms [m] (its origin if it has none)."""
        m, d = self.model, self.data
        geoms = [g for g in range(m.ngeom) if m.geom_bodyid[g] == body]
        if not geoms:
            return float(d.xpos[body][2])
        return min(float(c[2] - h[2]) for c, h in (_box(m, d, g) for g in geoms))

    def common(self, a: int, b: int) -> int:
        """The lowest body above both ``a`` and ``b`` (the root if only it is)."""
        above = set([self.root, *self.path(a)])
        while b not in above:
            b = int(self.model.body_parentid[b])
        return b

    def axis(self, joint: int) -> tuple[str, float, float]:
        """Which canonical axis a hinge turns about in the world: ``(kind, sign, cos)``,
        kind one of :data:`AXES`, sign ±1 of its axis along that one, cos how well it
        lines up (1: exactly)."""
        a = self.data.xaxis[joint] / max(np.linalg.norm(self.data.xaxis[joint]), 1e-12)
        kind = max(AXES, key=lambda k: abs(float(a @ AXES[k])))
        c = float(a @ AXES[kind])
        return kind, 1.0 if c > 0 else -1.0, abs(c)

    def anchor(self, joint: int) -> np.ndarray:
        """A hinge's anchor in the world ``(3,)`` [m]."""
        return self.data.xanchor[joint].copy()

    def joint_name(self, joint: int) -> str:
        """A joint's name (``joint<id>`` if it has none)."""
        return self.model.joint(joint).name or f"joint{joint}"
