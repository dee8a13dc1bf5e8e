"""``imitwalk retarget`` and ``imitwalk playback``: a clip made the robot's joint-space
reference, and that reference played open-loop on protocol robots; and the clip and
reference helpers that ``learn`` shares (parsing lives in :mod:`imitwalk.cli.main`)."""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from imitwalk.cli.progress import emit, progress
from imitwalk.cli.robot_args import recorded_robot, robot_from

if TYPE_CHECKING:
    from imitwalk.mocap import Motion
    from imitwalk.retarget import Reference, RetargetConfig
    from imitwalk.robots import Robot

__all__ = [
    "clip_motion",
    "named_reference",
    "playback",
    "retarget",
    "search_report",
    "with_command",
]


def clip_motion(args: argparse.Namespace, robot: Robot) -> Motion:
    """The clip: a mocap file, or ``robot``'s motion from another tool (GMR, LocoMuJoCo)."""
    from imitwalk.mocap import default_clip
    from imitwalk.retarget.motionfiles import load_clip

    path = args.file or default_clip()
    return load_clip(
        path,
        robot,
        skeleton=args.skeleton,
        units=getattr(args, "units", None),
        up=getattr(args, "up", None),
        joint_names=getattr(args, "joint_names", None),
    )


def retarget(args: argparse.Namespace) -> int:
    from imitwalk.config import apply_overrides
    from imitwalk.fileio import check_writable
    from imitwalk.retarget import RetargetConfig
    from imitwalk.retarget import retarget as run

    check_writable(args.out)
    robot = robot_from(args)
    cfg = RetargetConfig(mapping=args.mapping, search=not args.no_search)
    cfg = with_command(apply_overrides(cfg, args.set), args)
    motion = clip_motion(args, robot)
    progress(f"retarget: {motion.source} ({motion.n_frames} frames at {motion.fps:g} fps)")

    res = run(motion, robot, cfg, progress=search_report)
    progress(f"  cycles: {res.template.meta['cycles_report']}")
    named_reference(res.reference, args).save(args.out)
    stats = res.stats()
    stats["out"] = str(Path(args.out))
    emit(stats, args.json)
    return 0


def search_report(gen: int, total: int, score: float, params: dict) -> None:
    """Progress of the reference search (:mod:`imitwalk.retarget.search`)."""
    from imitwalk.retarget.search import search_line

    progress(search_line(gen, total, score, params))


def playback(args: argparse.Namespace) -> int:
    from imitwalk.cli.arg_checks import (
        check_count,
        check_joint_map_alone,
        check_scale,
        check_seconds,
        check_workers,
    )
    from imitwalk.retarget import Reference
    from imitwalk.retarget.playback import play_reference, summary
    from imitwalk.retarget.robotmotion import check_reference_robot

    check_scale(args.scale)
    check_seconds(args.seconds)
    check_count(args.models, "--models")
    check_workers(args.workers)
    check_joint_map_alone(args)
    ref = Reference.load(args.reference)
    if args.robot is None:
        args.robot = ref.provenance.robot or ref.robot
        args.joint_map = ref.provenance.joint_map
    robot = robot_from(args)
    check_reference_robot(ref, robot)
    seeds = list(range(args.models))
    progress(f"playback: scale {args.scale:g}, {args.seconds:g} s on {len(seeds)} robots")
    runs = play_reference(
        ref, robot, args.scale, args.seconds, seeds, workers=args.workers, engine=args.engine
    )
    out = {"scale": args.scale, "seconds": args.seconds, "engine": args.engine, **summary(runs)}
    emit(out, args.json)
    return 0


def named_reference(ref: Reference, args: argparse.Namespace) -> Reference:
    """``ref`` with the robot as this command named it (for ``evaluate`` to find again)."""
    where = recorded_robot(args)
    return replace(ref, provenance=ref.provenance.named(where.robot, where.joint_map))


def with_command(cfg: RetargetConfig, args: argparse.Namespace) -> RetargetConfig:
    """``cfg`` (a RetargetConfig) with the ``--turn/--side/--forward/--slope`` flags given."""
    flags = {"turn_deg": "turn", "side_m": "side", "forward": "forward", "slope_deg": "slope"}
    given = {k: getattr(args, a) for k, a in flags.items() if getattr(args, a, None) is not None}
    return replace(cfg, command=replace(cfg.command, **given)) if given else cfg
