"""``imitwalk learn CLIP --variant extended|faithful`` as one library call: the clip
retargeted to the robot, then learned by the per-tick learner (with the reference choice
of :mod:`imitwalk.learning.refchoice` where it applies) or by the paper's learner."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from imitwalk.balance.tickconfig import TickLearnConfig
from imitwalk.balance.ticklearn import learn_tick
from imitwalk.learning.refchoice import Choice, learn_clip
from imitwalk.mocap.motion import Motion
from imitwalk.paper.learnconfig import LearnConfig
from imitwalk.paper.learner import learn as learn_faithful
from imitwalk.retarget.pipeline import RetargetConfig, retarget
from imitwalk.retarget.provenance import Provenance
from imitwalk.retarget.reference import Reference
from imitwalk.retarget.search import Walker, search_line
from imitwalk.robots import Robot
from imitwalk.runs import LearnSummary

__all__ = ["learn_joint_space"]


def learn_joint_space(
    motion: Motion,
    robot: Robot,
    out: str | Path,
    cfg: TickLearnConfig | LearnConfig,
    retarget_cfg: RetargetConfig | None = None,
    resume: bool = False,
    progress: Callable[[str], None] | None = None,
    named: Provenance | None = None,
) -> tuple[LearnSummary, Choice | None]:
    """Learn ``motion`` on ``robot`` into the run folder ``out`` as a joint-space reference.

    Args:
        cfg: a :class:`~imitwalk.balance.tickconfig.TickLearnConfig` (the per-tick
            learner, ``--variant extended``) or a
            :class:`~imitwalk.paper.learnconfig.LearnConfig` (the paper's, ``faithful``).
        retarget_cfg: how the clip is retargeted (default :class:`RetargetConfig`).
        resume: go on with an interrupted run in ``out``.
        progress: one line at a time; named: the robot as the command named it, recorded
            in the reference for ``evaluate`` to find again.

    Returns:
        the learning's summary, and the reference choice where the per-tick learner made
        one (its ``choice.robots`` above 0 and a searched reference), else ``None``.
    """
    rcfg = retarget_cfg or RetargetConfig()
    say = progress or (lambda _line: None)

    def make_reference(walker: Walker | None = None) -> Reference:
        say(f"learn: retargeting {motion.source}")
        searched = retarget(motion, robot, rcfg, lambda *a: say(search_line(*a)), walker=walker)
        say(f"  cycles: {searched.template.meta['cycles_report']}")
        ref = searched.reference
        if named is None:
            return ref
        return replace(ref, provenance=ref.provenance.named(named.robot, named.joint_map))

    if isinstance(cfg, TickLearnConfig) and cfg.choice.robots and rcfg.searches:
        return learn_clip(make_reference, robot, cfg, out, resume, progress)
    ref = make_reference()
    if isinstance(cfg, TickLearnConfig):
        say("learn: extended variant")
        return learn_tick(ref, robot, cfg, out, resume=resume, progress=progress), None
    say("learn: faithful variant")
    return learn_faithful(ref, robot, cfg, out, resume=resume, progress=progress), None
