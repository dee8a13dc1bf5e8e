"""What ``learn --out RUN [--resume]`` may write into, checked before any work: a folder
that is new, empty or a run (never a folder of the user's own files), and a resumed run's
own robot and clip (never another's)."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from imitwalk.cli.robot_args import recorded_robot, robot_label

if TYPE_CHECKING:
    from imitwalk.retarget.provenance import Provenance
    from imitwalk.robots import Robot
    from imitwalk.runs import RunDir

__all__ = ["check_out", "check_resumed_clip", "check_resumed_robot"]


def check_out(args: argparse.Namespace, rd: RunDir) -> None:
    """Refuse, before any work starts, a run folder ``--out`` that learning could not
    write or would overwrite (:meth:`~imitwalk.runs.RunDir.check_new`), or an empty name
    (the working directory)."""
    from imitwalk.cli.arg_checks import check_folder_name

    check_folder_name(str(args.out), "--out")
    rd.check_writable()
    rd.check_new(args.resume)


def _recorded(rd: RunDir) -> tuple[RunDir, dict]:
    """The folder of the run in ``rd`` that records its robot and clip, and its
    ``config.json`` (``{}``: none yet): ``rd``, or an unfinished reference choice's first
    pass."""
    from imitwalk.learning.refchoice import PASSES
    from imitwalk.runs import RunDir

    for folder in (rd, RunDir(rd.file(PASSES[0]))):
        if folder.exists("config.json"):
            return folder, folder.read_json("config.json")
    return rd, {}


def _made(rd: RunDir) -> Provenance:
    """How the run in ``rd`` named its robot: as its reference or its stepping gait records
    it (empty: neither is there)."""
    from imitwalk.retarget.provenance import Provenance

    if rd.exists("reference.npz"):
        from imitwalk.retarget import Reference

        return Reference.load(rd.file("reference.npz")).provenance
    if rd.exists("style.json"):
        from imitwalk.step.gait import StepGait

        return StepGait.load(rd.file("style.json")).provenance
    return Provenance()


def check_resumed_robot(args: argparse.Namespace, rd: RunDir, robot: Robot) -> None:
    """Refuse to resume the run in ``rd`` on another robot than it started on: another
    robot's name, or another robot file or joint map than it records (a built-in name, or
    the file's absolute path). Nothing to check in a folder without a run."""
    from imitwalk.errors import ConfigError

    folder, cfg = _recorded(rd)
    made, given = _made(folder), recorded_robot(args)
    name = cfg.get("robot")
    named_other = isinstance(name, str) and name != robot.name
    if made.robot is None and not named_other:  # only its name recorded, and it is the same
        return
    if not named_other and (made.robot, made.joint_map) == (given.robot, given.joint_map):
        return
    was = made.robot or repr(name)
    was += f" (joint map {made.joint_map})" if made.joint_map else ""
    now = str(given.robot) + (f" (joint map {given.joint_map})" if given.joint_map else "")
    raise ConfigError(
        f"--robot {robot_label(args)}: {rd.path} was started on {was}, not {now} "
        f"({robot.name!r}); resume it with the robot it started on, or learn into a new folder"
    )


def check_resumed_clip(rd: RunDir, clip: str) -> None:
    """Refuse to resume the run in ``rd`` with another clip than it records
    (:func:`~imitwalk.runs.check_resumed_clip`), a stepping gait's or a reference's."""
    from imitwalk.runs import check_resumed_clip as check

    _folder, cfg = _recorded(rd)
    ref = cfg.get("reference")
    check(
        rd.path, cfg.get("source") or (ref.get("source") if isinstance(ref, dict) else None), clip
    )
