"""The robot a command works on: from its flags, as a run records it, and from a run.

Every command that takes ``--robot`` / ``--joint-map`` (or a positional robot) loads it
here; ``learn`` refuses one that cannot stand before any work; a run records where its
robot came from (:func:`recorded_robot`) so that ``evaluate RUN`` finds it again
(:func:`run_robot`).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from imitwalk.retarget.provenance import Provenance

if TYPE_CHECKING:
    from imitwalk.robots import Robot
    from imitwalk.runs import RunDir

__all__ = ["recorded_robot", "robot_from", "robot_label", "run_robot", "standing_robot"]


def robot_from(args: argparse.Namespace) -> Robot:
    """Load the robot named by ``--robot`` / ``--joint-map`` (or the positional ``robot``)."""
    from imitwalk.robots import load_robot

    return load_robot(args.robot, getattr(args, "joint_map", None))


def robot_label(args: argparse.Namespace) -> str:
    """The robot as the command line gave it: ``--robot`` (or the positional robot), and
    ``--joint-map`` if given."""
    jm = getattr(args, "joint_map", None)
    return str(args.robot) + (f" (joint map {jm})" if jm else "")


def standing_robot(args: argparse.Namespace) -> Robot:
    """:func:`robot_from`, refused at once if it cannot stand: the stand check of
    :mod:`imitwalk.sim.standing` (a 2 s hold of the nominal robot, well under a second of
    computing), so that ``learn`` never spends minutes on a robot that falls standing still.

    Raises:
        RobotError: one line with the tilt or height measured and the joint-map keys to change.
    """
    from imitwalk.sim.standing import require_standing

    robot = robot_from(args)
    require_standing(robot, robot_label(args))
    return robot


def _where(robot: str | None) -> str | None:
    """A robot as a reference records it: a built-in name as it is, a file as an absolute
    path (so that the reference plays from any working directory)."""
    if robot is None or not Path(robot).is_file():
        return robot
    return str(Path(robot).resolve())


def recorded_robot(args: argparse.Namespace) -> Provenance:
    """Where the command's robot came from, as a run records it (``robot``, ``joint_map``:
    a built-in name, or an absolute path)."""
    return Provenance(robot=_where(args.robot), joint_map=_where(getattr(args, "joint_map", None)))


def run_robot(rd: RunDir, cfg: dict) -> tuple[str, str | None]:
    """The robot a run learned on and its joint map: the file its reference or its
    stepping gait records (a built-in name, or the joint map's path), else the name in
    its ``config.json``."""
    from imitwalk.retarget import Reference
    from imitwalk.step.gait import StepGait

    made = Provenance()
    if rd.exists("reference.npz"):
        made = Reference.load(rd.file("reference.npz")).provenance
    elif rd.exists("style.json"):
        made = StepGait.load(rd.file("style.json")).provenance
    name = made.robot or cfg.get("reference", {}).get("robot") or cfg.get("robot")
    return name or "hoap2", made.joint_map
