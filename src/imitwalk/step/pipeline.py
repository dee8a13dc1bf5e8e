"""A clip to a learned stepping gait, as one library call: the product's ``learn``.

:func:`learn_clip` takes a :class:`~imitwalk.mocap.Motion` and a robot to a finished run
folder: the clip's gait template (:mod:`imitwalk.retarget.template`), its style on the
robot's legs (:mod:`imitwalk.step.style`), the stride its servos carry
(:mod:`imitwalk.step.pace`), the gains learned on training robots
(:mod:`imitwalk.step.learn`), and the run's records:

RUN_DIR/
  config.json   ``learner: "step"``, the learning settings, the clip, the stride's
                choice (:mod:`imitwalk.step.pace`)
  style.json    the gait (:class:`~imitwalk.step.gait.StepGait`)
  cma.pkl       the optimiser after every generation (resume)
  log.jsonl     one line per generation
  gains.json    the kept gains and the shipped ones they started from
  metrics.json  the :class:`~imitwalk.runs.LearnSummary`
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from imitwalk.errors import ConfigError, MocapError, RunError
from imitwalk.retarget.provenance import Provenance
from imitwalk.robots import Robot
from imitwalk.runs import LearnSummary, RunDir, StepOutcome, check_resumed_clip
from imitwalk.step.gains import shipped_gains
from imitwalk.step.gait import StepGait
from imitwalk.step.learn import StepLearnConfig, learn_step
from imitwalk.step.pace import choose_stride

if TYPE_CHECKING:
    from imitwalk.mocap import Motion
    from imitwalk.sim.protocol import Protocol
    from imitwalk.step.style import GaitStyle

__all__ = ["gait_from_motion", "learn", "learn_clip", "resumed_gait"]


def gait_from_motion(
    motion: Motion,
    robot: Robot,
    named: Provenance | None = None,
    dt: float = 0.01,
    backward: bool = False,
) -> StepGait:
    """The :class:`~imitwalk.step.gait.StepGait` of ``motion`` on ``robot`` at scale 1:
    of its straight cycles, or if it has none, of its turning ones (a turning gait, its
    turn per cycle read from the clip: :attr:`~imitwalk.retarget.template.GaitTemplate.turn_deg`).
    ``named``: the robot as the command named it (default: its name); ``backward``: the
    clip played backward in time (:func:`~imitwalk.step.style.reversed_in_time`).

    Raises:
        MocapError: the clip holds no frames, or no steady walking cycle, straight or
            turning.
        ConfigError: the robot's legs cannot make the style's step.
    """
    from imitwalk.retarget.ik import leg_geometry
    from imitwalk.retarget.template import extract_template
    from imitwalk.step.style import reversed_in_time, style_from_template

    if motion.n_frames == 0:
        raise MocapError(f"no walking cycle found in {motion.source}: it holds no frames")
    try:
        template = extract_template(motion)
    except MocapError:
        template = extract_template(motion, allow_turn=True)
    style = style_from_template(template, leg_geometry(robot), 1.0)
    if backward:
        style = reversed_in_time(style)
    return StepGait(
        style=style,
        robot=robot.name,
        dt=dt,
        source=str(motion.source),
        cycles=np.asarray(template.cycles, dtype=int).reshape(-1, 2),
        provenance=replace(
            named or Provenance(robot=robot.name),
            motion_format=motion.format,
            motion_fps=motion.fps,
            filled=tuple(motion.filled),
        ),
    )


def learn_clip(
    gait: StepGait,
    robot: Robot,
    cfg: StepLearnConfig,
    out: str | Path,
    protocol: Protocol,
    resume: bool = False,
    progress: Callable[[str], None] | None = None,
) -> LearnSummary:
    """Learn ``gait`` on ``robot`` into the run folder ``out`` (see the module doc);
    ``protocol`` draws the training robots (:attr:`StepLearnConfig.protocol`'s).

    Raises:
        RunError: ``out`` holds another run (without ``resume``) or files that are not a
            run, or nothing to resume, or a run of other settings or another robot.
    """
    rd = RunDir(out)
    t0 = time.perf_counter()
    config = {"learner": "step", "learn": cfg.to_dict(), "robot": robot.name, "source": gait.source}
    if resume:
        if not rd.exists("style.json"):
            raise RunError(f"nothing to resume in {rd.path}: no style.json")
        why = started_otherwise(rd.read_json("config.json"), cfg, robot.name)
        if why is not None:
            raise RunError(f"{rd.path} was started {why}")
        gait = StepGait.load(rd.file("style.json"))
    # the search starts from the shipped gains of the walk's direction
    start = shipped_gains(backward=gait.style.backward)
    if not resume:
        rd.check_new(resume=False)  # another run, or a folder of the user's own files
        # the stride first: the run's files are written once it is chosen, so a run
        # stopped here is started again, not resumed
        style, pace = choose_stride(
            robot, gait.style, engine=cfg.engine, gains=start, progress=progress
        )
        gait = replace(gait, style=style)
        config["pace"] = pace.to_dict()
        Path(rd.path).mkdir(parents=True, exist_ok=True)
        rd.write_json("config.json", config)
        gait.save(rd.file("style.json"))
    paced = dict(rd.read_json("config.json").get("pace") or {})
    res = learn_step(
        robot, gait.style, cfg, out, protocol, resume=resume, progress=progress, start=start
    )
    rd.write_json("gains.json", {"learned": res.gains.to_dict(), "default": start.to_dict()})
    summary = LearnSummary(
        learner="step",
        scale_reached=1.0,
        scales_passed=[1.0],
        iterations=len(res.history),
        sim_seconds_used_for_learning=res.sim_seconds + float(paced.get("sim_seconds", 0.0)),
        wall_seconds_for_learning=max(res.wall_seconds, time.perf_counter() - t0),
        config=cfg.to_dict(),
        outcome=StepOutcome(gains=res.gains.to_dict(), final=res.final, pace=paced or None),
    )
    rd.write_json("metrics.json", summary.to_dict())
    return summary


def resumed_gait(out: str | Path, backward: bool = False) -> StepGait:
    """The gait of the stepping run in ``out`` that is to be resumed; refused in one line
    if ``backward`` is asked of a run that walks forward (a resumed run walks its own
    style)."""
    rd = RunDir(out)
    gait = StepGait.load(rd.file("style.json"))
    if backward and not gait.style.backward:
        raise ConfigError(
            f"--backward: {rd.path} walks forward, and a resumed run walks its own style; "
            "learn a backward walk into a new folder"
        )
    return gait


def learn(
    clip: Motion | str | Path | None = None,
    robot: Robot | str = "hoap2",
    out: str | Path = "RUN",
    cfg: StepLearnConfig | None = None,
    resume: bool = False,
    progress: Callable[[str], None] | None = None,
    named: Provenance | None = None,
    backward: bool = False,
) -> LearnSummary:
    """The product as one call: ``clip`` learned as a stepping gait on ``robot`` into the
    run folder ``out``, exactly as ``imitwalk learn CLIP --out OUT [--backward]`` does.

    Args:
        clip: a :class:`~imitwalk.mocap.Motion`, a mocap file's or the robot's motion
            file's path (:func:`~imitwalk.retarget.motionfiles.load_clip`), or ``None`` (the
            embedded walk); robot: a :class:`~imitwalk.robots.Robot` or its name or
            file; cfg: the learning settings (default :class:`StepLearnConfig`);
            resume: continue an interrupted run (its clip and gait are its own);
            named: the robot as the command named it, for the run folder (default: its
            name); backward: learn the clip played backward in time (a new run only:
            a resumed one walks its own style).
    """
    from imitwalk.mocap import Motion, default_clip
    from imitwalk.retarget.motionfiles import load_clip
    from imitwalk.robots import load_robot
    from imitwalk.sim.protocol import load_protocol

    robot = load_robot(robot) if isinstance(robot, str) else robot
    cfg = cfg or StepLearnConfig()
    protocol = load_protocol(cfg.protocol)
    if resume:
        _check_resumed_clip(out, clip)
        gait = resumed_gait(out, backward)
    else:
        motion = clip if isinstance(clip, Motion) else load_clip(clip or default_clip(), robot)
        gait = gait_from_motion(motion, robot, named, backward=backward)
        st = gait.style
        if progress is not None:
            progress(
                f"  style: a {st.step_length:.3f} m step every {st.step_time:.2f} s "
                f"({st.speed:.2f} m/s), {st.step_width:.3f} m wide, {st.clearance:.3f} m high"
                + _turning(st)
            )
    return learn_clip(gait, robot, cfg, out, protocol, resume=resume, progress=progress)


def started_otherwise(started: dict, cfg: StepLearnConfig, robot: str) -> str | None:
    """How a stepping run whose ``config.json`` is ``started`` was not started with
    ``cfg`` on ``robot`` (its name), in words that follow "was started"; ``None`` if it
    was (a run that records no robot passes as any)."""
    if started.get("learn") != cfg.to_dict():
        return "with other settings; resume with the same ones"
    if started.get("robot", robot) != robot:
        return (
            f"on robot {started['robot']!r}, not {robot!r}; resume it on that robot, or "
            "learn into a new folder"
        )
    return None


def _check_resumed_clip(out: str | Path, clip: Motion | str | Path | None) -> None:
    """Refuse to resume the run in ``out`` with another clip than it records
    (:func:`~imitwalk.runs.check_resumed_clip`): a file's or a
    :class:`~imitwalk.mocap.Motion`'s source (``None``: the run's own)."""
    from imitwalk.mocap import Motion

    if clip is None:
        return
    rd = RunDir(out)
    source = rd.read_json("config.json").get("source") if rd.exists("config.json") else None
    check_resumed_clip(rd.path, source, clip.source if isinstance(clip, Motion) else str(clip))


def _turning(style: GaitStyle) -> str:
    """How the style turns, for the learner's progress line ("" for a straight walk)."""
    if not style.turn:
        return ""
    deg = float(np.degrees(style.turn))
    out = f", turning {deg:+.1f} deg per cycle"
    clip = style.human.get("turn_deg", 0.0)
    held = abs(deg - (-clip if style.backward else clip)) > 0.05
    if style.backward:  # played backward, the walk turns the other way
        out += f" (the clip's {clip:+.1f} deg played backward" + (
            ", held at the gait's limit)" if held else ")"
        )
    elif held:
        out += f" (the clip's {clip:+.1f} deg, beyond the gait's limit)"
    return out
