"""Where a gait came from: the clip as it was read and the robot as it was named (a typed
record, pure Python), for a joint-space reference and a stepping gait alike."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

__all__ = ["Provenance"]


@dataclass(frozen=True)
class Provenance:
    """How a :class:`~imitwalk.retarget.reference.Reference` or a
    :class:`~imitwalk.step.gait.StepGait` was made, beyond what it holds.

    Attributes:
        searched: its parameters were found by the search
            (:mod:`imitwalk.retarget.search`), not given.
        motion_format: the clip's format (``"bvh"``, ``"amc"``, ``"c3d"``,
            ``"deepmimic"``; empty: not recorded); motion_fps: its frame rate [Hz] (0: not
            recorded).
        filled: the clip's joints that were missing and held at zero.
        robot: the robot as the command named it: a built-in name or a joint map's
            absolute path (``None``: not recorded, the reference's ``robot`` name stands);
            joint_map: the joint map given beside it, as an absolute path.
    """

    searched: bool = False
    motion_format: str = ""
    motion_fps: float = 0.0
    filled: tuple[str, ...] = ()
    robot: str | None = None
    joint_map: str | None = None

    def named(self, robot: str | None, joint_map: str | None) -> Provenance:
        """The same provenance with the robot as a command named it."""
        return replace(self, robot=robot, joint_map=joint_map)

    def to_settings(self) -> dict[str, Any]:
        """The ``settings`` object a reference or gait file stores."""
        return {
            "search": self.searched,
            "motion_format": self.motion_format,
            "motion_fps": self.motion_fps,
            "filled": list(self.filled),
            "robot": self.robot,
            "joint_map": self.joint_map,
        }

    @classmethod
    def from_settings(cls, settings: dict[str, Any]) -> Provenance:
        """The record of a stored ``settings`` object (missing keys: not recorded; a robot
        or joint map that is not a string: not recorded). Raises ValueError or TypeError
        for a frame rate that is not a number."""
        robot, joint_map = (settings.get(k) for k in ("robot", "joint_map"))
        return cls(
            searched=bool(settings.get("search", False)),
            motion_format=str(settings.get("motion_format") or ""),
            motion_fps=float(settings.get("motion_fps") or 0.0),
            filled=tuple(str(j) for j in settings.get("filled") or ()),
            robot=robot if isinstance(robot, str) else None,
            joint_map=joint_map if isinstance(joint_map, str) else None,
        )
