"""The reference choice of ``imitwalk learn CLIP``: search, learn, search again under the
learned law, learn again, and keep the better of the two.

The reference search (:mod:`imitwalk.retarget.search`) walks its candidates open loop,
while the learner walks the reference it keeps under per-tick feedback. Open loop, a
search can keep a reference that shuffles: CMU 07_04's lifts its swing foot 6–7 mm of the
19 mm planned, and its slowest evaluation robot makes 0.78 of the reference's progress.
Searched again with the learned law in the loop, it makes 0.94; but on the default clip
and 07_06 that second search does much worse (15 and 12 of 40 eval robots fall). So both are
learned, and training robots decide (docs/RESULTS.md, "The reference choice"):

1. ``searched/``: the reference of the open-loop search, learned
   (:func:`~imitwalk.balance.ticklearn.learn_tick`);
2. ``closed/``: the same search (same start, seed, robots, scales and score), each
   candidate walked under pass 1's trial-picked law and reference settings
   (:class:`LawWalker`), learned again;
3. ``choice.json``: each pass's learned controller walks ``choice.robots`` training robots
   (:class:`~imitwalk.balance.tickconfig.ChoiceConfig`; the learner's ``train_protocol``,
   on the engine it learned on). The pass that reached the larger scale, then fell less
   (where every robot fell, walked longer), then had the larger slowest progress ratio,
   is kept; a tie keeps pass 1. Pass 2 stops
   walking once it has fallen more often than pass 1 at the same scale, where it can no
   longer be kept. The kept pass's files are linked to the top of the run folder, where
   ``evaluate`` and ``report`` read them.

Where pass 2's search keeps pass 1's gait (the same parameters, so the same joint
trajectories), learning and judging it again would repeat pass 1 to the digit: pass 2 is
recorded as the same (:attr:`PassVerdict.same_as`) and pass 1 is kept.

Every step is kept in the run folder, so ``--resume`` goes on from the last one done.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from imitwalk.balance.feedback import FeedbackLaw
from imitwalk.balance.tickconfig import TickLearnConfig
from imitwalk.balance.ticklearn import learn_tick
from imitwalk.balance.tickrun import TickJob, tick_walk_metrics
from imitwalk.balance.tickstore import load_laws
from imitwalk.errors import ConfigError, RunError
from imitwalk.fileio import atomic_write
from imitwalk.robots import Robot
from imitwalk.runs import LearnSummary, RunDir
from imitwalk.sim.metrics import WalkMetrics
from imitwalk.sim.types import SimOptions

if TYPE_CHECKING:
    from imitwalk.balance.tickconfig import ChoiceConfig
    from imitwalk.retarget.reference import Reference
    from imitwalk.retarget.search import Walker
    from imitwalk.sim.protocol import Protocol

__all__ = [
    "PASSES",
    "Choice",
    "LawWalker",
    "PassVerdict",
    "law_walker",
    "learn_clip",
    "pick",
    "same_gait",
]

#: The two passes, in the order they run (a tie keeps the first).
PASSES = ("searched", "closed")


@dataclass(frozen=True)
class LawWalker:
    """A reference search's walker (:data:`~imitwalk.retarget.search.Walker`): a finished
    run's trial-picked law, with the reference settings its trials kept (the servo
    feedforward fraction and the load share a lift-off waits for)."""

    law: FeedbackLaw
    feedforward: float = 0.0
    wait: float = 0.0
    engine: str = "mujoco"

    def __call__(
        self,
        ref: Reference,
        robot: Robot,
        scale: float,
        seed: int,
        options: SimOptions,
        seconds: float,
    ) -> WalkMetrics:
        job = TickJob(
            "",
            robot,
            scale,
            (self.law,),
            seed,
            options,
            seconds,
            engine=self.engine,
            record=False,
            feedforward=self.feedforward,
            wait=self.wait,
        )
        return tick_walk_metrics(job, ref)


def law_walker(run_dir: str | Path) -> LawWalker:
    """The :class:`LawWalker` of the finished per-tick run in ``run_dir``."""
    rd = RunDir(run_dir)
    settings = rd.read_summary().tick().reference_settings or {}
    learn = rd.read_json("config.json", ("learn",))["learn"]
    return LawWalker(
        load_laws(run_dir)["feedback"][0],
        float(settings.get("feedforward", 0.0)),
        float(settings.get("wait", 0.0)),
        str(learn.get("engine", "mujoco")),
    )


@dataclass(frozen=True)
class PassVerdict:
    """One pass, judged on the choice's training robots.

    Attributes:
        name: the pass (:data:`PASSES`); scale: the scale its learning reached and it was
        walked at; falls, robots: counts; progress_min: the slowest robot's progress ratio;
        distance_m: mean forward distance [m]; walked_s: simulated time walked [s];
        learn_sim_seconds, learn_wall_seconds: its learning's cost [s]; search_sim_seconds:
        its reference search's simulated time [s]; same_as: the earlier pass whose gait
        its search kept, whose learning and verdict it shares (none run again; empty: its
        own).
    """

    name: str
    scale: float
    falls: int
    robots: int
    progress_min: float
    distance_m: float
    walked_s: float
    learn_sim_seconds: float
    learn_wall_seconds: float
    search_sim_seconds: float
    same_as: str = ""

    def rank(self) -> tuple:
        """The order passes are kept in (least first): the larger scale, the fewer falls;
        where every robot fell, the longer walked (as the trials rank, where a progress
        ratio says little); then the larger slowest progress ratio."""
        walked = -self.walked_s if self.falls == self.robots else 0.0
        return (-self.scale, self.falls, walked, -self.progress_min)


@dataclass(frozen=True)
class Choice:
    """The reference choice: the pass ``kept`` and every pass's verdict (``choice.json``)."""

    kept: str
    passes: tuple[PassVerdict, ...]

    def to_dict(self) -> dict:
        return {"kept": self.kept, "passes": [asdict(p) for p in self.passes]}

    @classmethod
    def from_dict(cls, d: dict) -> Choice:
        return cls(d["kept"], tuple(PassVerdict(**p) for p in d["passes"]))

    def cost(self) -> dict:
        """Simulated seconds [s] by what spent them: the kept pass's learning, and the
        choice (pass 2's search, the other pass's learning, every pass's judgement)."""
        kept = next(p for p in self.passes if p.name == self.kept)
        own = [p for p in self.passes if not p.same_as]  # a shared gait was not run again
        other = sum(p.learn_sim_seconds for p in own) - kept.learn_sim_seconds
        return {
            "learning_sim_seconds": kept.learn_sim_seconds,
            "choice_sim_seconds": other
            + sum(p.walked_s for p in own)
            + sum(p.search_sim_seconds for p in self.passes[1:]),
        }


def pick(verdicts: list[PassVerdict]) -> str:
    """The pass kept (:meth:`PassVerdict.rank`); a tie keeps the earlier pass."""
    return min(verdicts, key=PassVerdict.rank).name


def learn_clip(
    make_reference: Callable[[Walker | None], Reference],
    robot: Robot,
    cfg: TickLearnConfig,
    run_dir: str | Path,
    resume: bool = False,
    progress: Callable[[str], None] | None = None,
) -> tuple[LearnSummary, Choice]:
    """Learn the two passes (module docstring) into ``run_dir`` and keep the better.

    Args:
        make_reference: ``make_reference(walker)`` retargets the clip to ``robot`` with its
            reference search walking each candidate under ``walker`` (``None``: open
            loop; :data:`~imitwalk.retarget.search.Walker`) and returns the
            :class:`~imitwalk.retarget.reference.Reference`, e.g.
            ``lambda w: retarget(motion, robot, walker=w).reference``.
        cfg: the learner's settings; ``cfg.choice`` the choice's (``robots`` ≥ 1).

    Returns:
        the kept run's summary (``metrics.json`` at the top of ``run_dir``) and the choice.

    Raises:
        ConfigError: ``cfg.choice.robots`` is 0 (learn one reference with
        :func:`~imitwalk.balance.ticklearn.learn_tick`). RunError: ``run_dir`` holds a
        run and ``resume`` is off.
    """
    from imitwalk.retarget import Reference

    if cfg.choice.robots == 0:
        raise ConfigError("choice.robots is 0: there is no choice to make; learn one reference")
    say = progress or (lambda _s: None)
    root = RunDir(run_dir)
    if not resume and (root.exists("checkpoint.json") or root.file(PASSES[0]).is_dir()):
        raise RunError(f"{root.path} already holds a run; pass --resume or choose another --out")
    if resume and root.exists("choice.json") and root.exists("metrics.json"):
        say(f"learn: {root.path} is finished")
        return root.read_summary(), Choice.from_dict(root.read_json("choice.json"))
    summaries: dict[str, LearnSummary] = {}
    refs: dict[str, Reference] = {}
    searched: dict[str, float] = {}
    same: dict[str, str] = {}
    walker = None
    for i, name in enumerate(PASSES):
        rd = RunDir(root.file(name))
        how = "the open-loop search" if walker is None else "the search under pass 1's law"
        say(f"learn: pass {i + 1} of {len(PASSES)} ({name}): {how}")
        if rd.exists("reference.npz"):
            ref = Reference.load(rd.file("reference.npz"))
        else:
            ref = make_reference(walker)
        searched[name] = ref.search.sim_seconds if ref.search is not None else 0.0
        twin = next((n for n, r in refs.items() if same_gait(ref, r)), "")
        refs[name] = ref
        if twin:  # learning it again would repeat the twin's learning to the digit
            say(f"learn: pass {i + 1}'s search kept pass {twin}'s gait; not learned again")
            rd.path.mkdir(parents=True, exist_ok=True)
            ref.save(rd.file("reference.npz"))
            same[name], summaries[name] = twin, summaries[twin]
            continue
        go_on = rd.exists("checkpoint.json")
        summaries[name] = learn_tick(ref, robot, cfg, rd.path, resume=go_on, progress=say)
        walker = law_walker(rd.path)
    choice = _judge(root, robot, cfg, summaries, searched, same, say)
    _keep(root, choice.kept)
    root.write_json("choice.json", choice.to_dict())
    return summaries[choice.kept], choice


def same_gait(a: Reference, b: Reference) -> bool:
    """True if two references of one clip and robot play the same gait: the same
    parameters and the same joint trajectories at every scale (their search reports may
    differ)."""
    return a.params == b.params and all(
        np.array_equal(getattr(a, k), getattr(b, k))
        for k in ("scales", "loops", "starts", "start_travel")
    )


def _judge(
    root: RunDir,
    robot: Robot,
    cfg: TickLearnConfig,
    summaries: dict,
    searched: dict,
    same: dict,
    say: Callable[[str], None],
) -> Choice:
    """Each pass's learned controller on the choice's training robots; ``searched``: each
    pass's reference search's simulated seconds [s]; ``same``: the passes that share an
    earlier pass's gait, and whose."""
    from imitwalk.sim.protocol import load_protocol

    c = cfg.choice
    protocol = replace(load_protocol(cfg.train_protocol), engine=cfg.engine)  # learned there
    say(f"learn: judging both passes on {c.robots} training robots x {c.seconds:g} s")
    out: list[PassVerdict] = []
    for name in PASSES:
        if name in same:  # its twin's verdict, walked once
            out.append(_shared_verdict(out, name, same[name], searched[name], say))
            continue
        pass1 = out[0] if out else None
        v = _walk_pass(root, name, summaries[name], robot, protocol, cfg, pass1, searched[name])
        out.append(v)
        _say_verdict(v, c, say)
    kept = pick(out)
    say(f"learn: keeping pass {kept}")
    return Choice(kept, tuple(out))


def _shared_verdict(
    out: list[PassVerdict], name: str, twin_name: str, search_s: float, say: Callable[[str], None]
) -> PassVerdict:
    """Pass ``name``'s verdict where its search kept pass ``twin_name``'s gait: the twin's
    (in ``out``), with no learning of its own and its search's ``search_s`` [s]."""
    twin = next(v for v in out if v.name == twin_name)
    verdict = replace(
        twin,
        name=name,
        learn_sim_seconds=0.0,
        learn_wall_seconds=0.0,
        search_sim_seconds=search_s,
        same_as=twin.name,
    )
    say(f"  {name}: {twin.name}'s gait, {twin.name}'s verdict")
    return verdict


def _walk_pass(
    root: RunDir,
    name: str,
    s: LearnSummary,
    robot: Robot,
    protocol: Protocol,
    cfg: TickLearnConfig,
    pass1: PassVerdict | None,
    search_s: float,
) -> PassVerdict:
    """Pass ``name``'s learned controller (summary ``s``) walked on the choice's training
    robots of ``protocol``; stopped once it has fallen more often than ``pass1`` at the
    same scale. ``search_s``: its reference search's simulated seconds [s]."""
    from imitwalk.judge.verdict import judge_protocol

    c = cfg.choice
    # at pass 1's scale, a pass that has fallen more often can no longer be kept
    most_falls = None
    if pass1 is not None and s.scale_reached == pass1.scale:
        most_falls = pass1.falls
    v = judge_protocol(
        root.file(name),
        robot,
        protocol,
        c.robots,
        c.seconds,
        ("learned",),
        workers=cfg.workers,
        first=c.first,
        most_falls=most_falls,
    )
    cv = v.controllers["learned"]
    walked = sum(r.fall_time_s if r.fell and r.fall_time_s else c.seconds for r in cv.per_seed)
    return PassVerdict(
        name,
        float(s.scale_reached),
        cv.falls,
        cv.robots,
        float(cv.progress_ratio_min or 0.0),
        float(cv.distance_m or 0.0),
        float(walked),
        s.sim_seconds_used_for_learning,
        s.wall_seconds_for_learning,
        search_s,
    )


def _say_verdict(v: PassVerdict, c: ChoiceConfig, say: Callable[[str], None]) -> None:
    """One progress line: how pass ``v`` walked the choice's ``c.robots`` robots."""
    cut = f" (stopped: more falls than {PASSES[0]})" if v.robots < c.robots else ""
    how = (
        f"walked {v.walked_s / v.robots:.1f} s on average"
        if v.falls == v.robots
        else f"slowest progress {v.progress_min:.2f}"
    )
    say(f"  {v.name}: {v.falls} of {v.robots} fell, {how}{cut}")


def _keep(root: RunDir, name: str) -> None:
    """Link the kept pass's files to the top of ``root`` (copied where the file system has
    no hard links), ``metrics.json`` last. Every run file is written whole and renamed into
    place, so a link is never changed through the other name."""
    src = Path(root.file(name))
    files = sorted(
        (p for p in src.iterdir() if p.is_file() and not p.name.startswith(".")),
        key=lambda p: p.name == "metrics.json",
    )
    for p in files:
        atomic_write(root.file(p.name), partial(_link, p))


def _link(src: Path, dst: Path) -> None:
    dst.unlink()
    try:
        os.link(src, dst)
    except OSError:
        shutil.copyfile(src, dst)
