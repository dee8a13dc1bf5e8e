"""The judging commands: ``evaluate`` (a protocol's robots, or push recovery) and
``report`` (the run's HTML page)."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from imitwalk.cli.arg_checks import (
    check_count,
    check_joint_map_alone,
    check_scale,
    check_seconds,
    check_workers,
)
from imitwalk.cli.progress import emit, progress
from imitwalk.cli.robot_args import recorded_robot, robot_from, robot_label, run_robot

if TYPE_CHECKING:
    from imitwalk.robots import Robot
    from imitwalk.runs import RunDir

__all__ = ["evaluate", "report"]


def evaluate(args: argparse.Namespace) -> int:
    from imitwalk.errors import ConfigError
    from imitwalk.judge.verdict import judge_protocol
    from imitwalk.robots.urdf import rotor_note
    from imitwalk.runs import RunDir
    from imitwalk.sim.protocol import load_protocol

    check_scale(args.scale)
    check_workers(args.workers)
    check_joint_map_alone(args)
    if args.push_recovery and args.explain_falls:
        raise ConfigError(
            "--push-recovery and --explain-falls: push recovery kicks the nominal robot "
            "(no protocol's falls to explain); give one of them"
        )
    rd = RunDir(args.run_dir)
    cfg = rd.read_json("config.json")
    rd.check_writable("RUN_DIR")  # the verdict is written there
    robot = _judged_robot(args, rd, cfg)
    if args.push_recovery:
        return _push_recovery(args, rd, robot)
    protocol = load_protocol(args.protocol)
    check_count(args.seeds, "--seeds")
    check_seconds(args.seconds)
    chosen = tuple(args.controllers.split(",")) if args.controllers else None
    progress(
        f"evaluate: protocol {protocol.name} v{protocol.version} on {protocol.engine}, "
        f"{args.seeds} robots x {args.seconds:g} s"
    )
    if protocol.engine == "bullet":
        progress(f"evaluate: note: {rotor_note(robot)}")
    out = judge_protocol(
        rd.path,
        robot,
        protocol,
        args.seeds,
        args.seconds,
        controllers=chosen,
        scale=args.scale,
        workers=args.workers,
        explain=args.explain_falls,
    )
    for name, side in out.controllers.items():
        lo, hi = side.survival_ci95
        progress(
            f"  {name:>10}: survived {side.survived}/{side.robots} "
            f"({100 * lo:.0f}-{100 * hi:.0f} %), {side.distance_m:.2f} m, "
            f"|yaw| {side.abs_yaw_deg:.1f} deg"
        )
        if (line := side.explained()) is not None:
            progress(f"  {'':>10}  falls saved by one factor at nominal: {line}")
    scale = "" if args.scale is None else f"_scale{args.scale:g}"
    doc = {**out.to_dict(), "robot": _robot_record(args, robot)}
    rd.write_json(f"protocol_{protocol.name}{scale}.json", doc)
    emit(doc, args.json)
    return 0


def _judged_robot(args: argparse.Namespace, rd: RunDir, cfg: dict) -> Robot:
    """The robot a run is judged on: the one it learned on (``args.robot`` and
    ``args.joint_map`` set to it), or ``--robot``, which must be a robot of the same name
    (another joint map or MJCF of it, e.g. stronger knees, may be given).

    Raises:
        ConfigError: ``--robot`` names another robot than the run learned on.
    """
    from imitwalk.errors import ConfigError

    if args.robot is None:
        args.robot, args.joint_map = run_robot(rd, cfg)
        return robot_from(args)
    robot = robot_from(args)
    own = cfg.get("robot")
    if not isinstance(own, str):  # not in its config.json: the robot its files record
        name, joint_map = run_robot(rd, cfg)
        own = robot_from(argparse.Namespace(robot=name, joint_map=joint_map)).name
    if robot.name != own:
        raise ConfigError(
            f"--robot {robot_label(args)}: {rd.path} learned on {own!r}, not {robot.name!r}; "
            f"judge it on {own} (a joint map or MJCF of {own} may be given)"
        )
    return robot


def _robot_record(args: argparse.Namespace, robot: Robot) -> dict:
    """The robot a verdict was judged on, as its file records it
    (:class:`~imitwalk.judge.verdict.JudgedRobot`)."""
    from dataclasses import asdict

    from imitwalk.judge.verdict import JudgedRobot

    where = recorded_robot(args)
    return asdict(JudgedRobot(robot.name, where.robot or robot.name, where.joint_map))


def _push_recovery(args: argparse.Namespace, rd: RunDir, robot: Robot) -> int:
    from imitwalk.judge.pushes import push_recovery

    progress("evaluate: push recovery, 4 directions x 8 phases, bisection on the nominal robot")
    chosen = tuple(args.controllers.split(",")) if args.controllers else None
    out = push_recovery(rd.path, robot, controllers=chosen, scale=args.scale, workers=args.workers)
    for name, side in out.controllers.items():
        least = side.min_by_direction.items()
        progress(
            f"  {name:>10}: least kick survived " + ", ".join(f"{d} {v:.2f}" for d, v in least)
        )
    doc = {**out.to_dict(), "robot": _robot_record(args, robot)}
    rd.write_json("push_recovery.json", doc)
    emit(doc, args.json)
    return 0


def report(args: argparse.Namespace) -> int:
    from imitwalk.evidence.report import write_report
    from imitwalk.runs import RunDir

    check_seconds(args.seconds)
    rd = RunDir(args.run_dir)
    rd.read_summary()  # a clear error if this is not a finished run
    rd.check_writable("RUN_DIR")  # report.html is written there
    robot = None
    if args.robot:
        robot = _judged_robot(args, rd, rd.read_json("config.json"))
    path = write_report(rd.path, robot, seconds=args.seconds, progress=progress)
    emit({"report": str(path)}, args.json)
    return 0
