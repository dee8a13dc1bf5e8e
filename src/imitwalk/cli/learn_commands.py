"""``imitwalk learn``: the stepping gait's gains (the default), or the joint-space
learners (``--variant extended``, the per-tick learner; ``faithful``, the paper's), into
a run folder (parsing lives in :mod:`imitwalk.cli.main`)."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from imitwalk.cli.progress import emit, progress
from imitwalk.cli.resume_checks import check_out, check_resumed_clip, check_resumed_robot
from imitwalk.cli.retarget_commands import clip_motion, with_command
from imitwalk.cli.robot_args import recorded_robot, robot_from, robot_label

if TYPE_CHECKING:
    from imitwalk.learning.refchoice import Choice
    from imitwalk.retarget import RetargetConfig
    from imitwalk.robots import Robot
    from imitwalk.runs import LearnSummary, RunDir

__all__ = ["learn"]


def learn(args: argparse.Namespace) -> int:
    from imitwalk.learning.jointspace import learn_joint_space
    from imitwalk.mocap import default_clip
    from imitwalk.retarget import Reference
    from imitwalk.runs import RunDir
    from imitwalk.sim.standing import require_standing

    rd = RunDir(args.out)
    check_out(args, rd)  # every variant, before any work
    robot = robot_from(args)
    if args.resume:  # a run goes on with the robot and clip it started with
        check_resumed_robot(args, rd, robot)
        if args.file:
            check_resumed_clip(rd, args.file)
    require_standing(robot, robot_label(args))
    args.variant = _variant(args)
    if args.variant == "step":
        return _learn_step(args, robot)
    if args.backward:
        from imitwalk.errors import ConfigError

        raise ConfigError(
            f"--backward: only --variant step (the stepping gait) walks backward, "
            f"not {args.variant}"
        )
    rt_set, learn_set = _split_settings(args.set)
    cfg, run = _joint_space_learner(args, learn_set)
    resumed = _resumed(args, rd)
    rcfg = _retarget_config(rt_set, bool(args.reference or resumed))
    if resumed:
        ref = Reference.load(rd.file("reference.npz"))
        _unused_clip_flags(args)
        progress(f"learn: resuming {rd.path}")
    elif args.reference:
        ref = Reference.load(args.reference)
    else:
        if args.resume and not args.file:  # the clip is read again: the run's own
            check_resumed_clip(rd, str(default_clip()))
        motion, rcfg = clip_motion(args, robot), with_command(rcfg, args)
        named = recorded_robot(args)
        summary, choice = learn_joint_space(
            motion, robot, args.out, cfg, rcfg, args.resume, progress, named
        )
        return _learned(summary, args, rd, choice)
    progress(f"learn: {args.variant} variant")
    summary = run(ref, robot, cfg, args.out, resume=args.resume, progress=progress)
    return _learned(summary, args, rd)


def _split_settings(items: list[str]) -> tuple[list[str], list[str]]:
    """``--set`` items for the retargeting (``retarget.``-prefixed) and for learning."""
    rt = [i.split(".", 1)[1] for i in items if i.startswith("retarget.")]
    return rt, [i for i in items if not i.startswith("retarget.")]


def _joint_space_learner(
    args: argparse.Namespace, learn_set: list[str]
) -> tuple[Any, Callable[..., LearnSummary]]:
    """The settings (``--seed``, ``--set``) and learning function of ``--variant``
    faithful (the paper's learner) or extended (the per-tick learner)."""
    from imitwalk.config import apply_overrides

    if args.variant == "faithful":
        from imitwalk.paper.learnconfig import LearnConfig
        from imitwalk.paper.learner import learn as faithful

        cfg: Any = apply_overrides(LearnConfig(seed=args.seed), learn_set)
        run: Callable[..., LearnSummary] = faithful
    else:
        from imitwalk.balance.tickconfig import TickLearnConfig
        from imitwalk.balance.ticklearn import learn_tick

        cfg = apply_overrides(TickLearnConfig(seed=args.seed), learn_set)
        run = learn_tick
    return cfg, run


def _resumed(args: argparse.Namespace, rd: RunDir) -> bool:
    """True if ``--resume`` goes on with the reference a run chose (``rd``'s own); refuses
    the commanded-gait flags with a given or resumed reference."""
    from imitwalk.errors import ConfigError
    from imitwalk.learning.refchoice import PASSES

    flags = [
        f"--{a}" for a in ("turn", "side", "forward", "slope") if getattr(args, a, None) is not None
    ]
    # a run that chose its reference resumes as it started: the same clip, flags and settings
    resumed = args.resume and rd.exists("reference.npz") and not rd.file(PASSES[0]).is_dir()
    given = args.reference or resumed
    if flags and given:
        raise ConfigError(
            f"{', '.join(flags)} shape a new reference; a given or resumed reference keeps "
            "the command it was built with (retarget again with them)"
        )
    return resumed


def _retarget_config(rt_set: list[str], given: bool) -> RetargetConfig:
    """The retargeting settings (``--set retarget.KEY=VALUE``), checked even where a
    ``given`` reference leaves them unused (said on the progress line)."""
    from imitwalk.config import apply_overrides
    from imitwalk.retarget import RetargetConfig

    rcfg = apply_overrides(RetargetConfig(), rt_set)  # checked even where it is not used
    if rt_set and given:
        unused = ", ".join(f"retarget.{i}" for i in rt_set)
        progress(f"learn: {unused}: not used, the reference is given as it is")
    return rcfg


def _variant(args: argparse.Namespace) -> str:
    """The learner ``learn`` runs: ``--variant`` if given; else the joint-space per-tick
    learner for a given ``--reference`` or a resumed run that began as one; else the
    stepping gait."""
    import json

    from imitwalk.errors import ConfigError

    config = Path(args.out) / "config.json"
    learner = None
    if args.resume and config.is_file():
        try:
            learner = json.loads(config.read_text()).get("learner")
        except (ValueError, AttributeError, OSError):
            learner = None
    resumed = {"tick": "extended", "faithful": "faithful", "step": "step"}.get(str(learner))
    if args.variant:
        if learner is not None and resumed != args.variant:
            raise ConfigError(
                f"--variant {args.variant}: {config.parent} is a {learner!r} run "
                f"({resumed or 'not learned by learn'}); resume it without --variant"
            )
        return str(args.variant)
    if args.reference:
        return "extended"
    if learner is not None:
        return resumed or "step"
    return "step"


def _learn_step(args: argparse.Namespace, robot: Robot) -> int:
    """``learn`` with the stepping gait (the default variant)."""
    from imitwalk.config import apply_overrides
    from imitwalk.errors import ConfigError
    from imitwalk.runs import RunDir
    from imitwalk.sim.protocol import load_protocol
    from imitwalk.step.learn import StepLearnConfig
    from imitwalk.step.pipeline import learn, resumed_gait

    if args.reference:
        raise ConfigError(
            "--reference is a joint-space reference for --variant extended or faithful; "
            "the stepping gait learns from the clip itself"
        )
    unsupported = [
        f"--{a}" for a in ("turn", "side", "forward", "slope") if getattr(args, a, None) is not None
    ]
    if unsupported:
        raise ConfigError(
            f"{', '.join(unsupported)}: the stepping gait walks its clip straight ahead on "
            "level ground; commanded gaits are --variant extended's"
        )
    cfg = apply_overrides(StepLearnConfig(seed=args.seed), args.set)
    load_protocol(cfg.protocol)  # an unknown one refused before any work
    rd = RunDir(args.out)
    motion = None
    if args.resume:
        resumed_gait(rd.path, args.backward)  # its direction is its own: refused at once
        _unused_clip_flags(args)
        progress(f"learn: resuming {rd.path}")
    else:
        motion = clip_motion(args, robot)
        progress(f"learn: {motion.source} ({motion.n_frames} frames at {motion.fps:g} fps)")
    progress(
        f"learn: stepping gait, gains by CMA-ES on {cfg.protocol}'s training robots "
        f"(at most {cfg.budget():.0f} simulated seconds)"
    )
    summary = learn(
        motion,
        robot,
        args.out,
        cfg,
        args.resume,
        progress,
        recorded_robot(args),
        backward=args.backward,
    )
    return _learned(summary, args, rd)


def _unused_clip_flags(args: argparse.Namespace) -> None:
    """Say which clip flags a resumed run leaves unused (it walks its own gait)."""
    flags = ("skeleton", "units", "up", "joint_names")
    given = [f"--{f.replace('_', '-')}" for f in flags if getattr(args, f, None) is not None]
    if given:
        progress(f"learn: {', '.join(given)}: not used, a resumed run keeps its own clip's gait")


def _learned(
    summary: LearnSummary, args: argparse.Namespace, rd: RunDir, choice: Choice | None = None
) -> int:
    """Print a learning run's summary (and its reference choice, if it made one)."""
    out = {k: v for k, v in summary.to_dict().items() if k not in ("config", "gait")}
    out["variant"] = args.variant
    if choice is not None:
        out["reference_choice"] = {**choice.to_dict(), **choice.cost()}
    out["run_dir"] = str(rd.path)
    emit(out, args.json)
    return 0
