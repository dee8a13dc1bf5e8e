"""``imitwalk demo``: the whole pipeline on the embedded walk, on a small budget.

Reads pybullet's ``humanoid3d_walk``, takes its style to the robot's legs, learns the
stepping gait's gains on a small budget (two CMA-ES generations on a few training
robots), judges the learned gains against the shipped ones on the eval protocol's first
robots, and writes the HTML report. ``imitwalk learn`` and ``imitwalk evaluate`` with
their defaults are the full-budget versions.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING

from imitwalk.cli.progress import emit, progress

if TYPE_CHECKING:
    from imitwalk.runs import RunDir
    from imitwalk.step.learn import StepLearnConfig

__all__ = ["DEMO_LEARN", "demo", "run_demo"]


#: The demo's learning budget: two generations of four candidates on three robots.
DEMO_LEARN = ["generations=2", "population=4", "robots=3", "seconds=6", "final_robots=3"]


def demo(args: argparse.Namespace) -> int:
    """``imitwalk demo``: :func:`run_demo` into ``--out``, its summary printed."""
    emit(run_demo(Path(args.out)), args.json)
    return 0


def run_demo(out: Path) -> dict:
    """Learn the embedded clip, evaluate and report into ``out``; the summary."""
    from imitwalk.config import apply_overrides
    from imitwalk.evidence.report import write_report
    from imitwalk.judge.verdict import JudgedRobot, judge_protocol
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.retarget.provenance import Provenance
    from imitwalk.robots import load_robot
    from imitwalk.runs import RunDir
    from imitwalk.sim.protocol import load_protocol
    from imitwalk.step.learn import StepLearnConfig
    from imitwalk.step.pipeline import gait_from_motion, learn_clip

    t0 = time.perf_counter()
    robot = load_robot("hoap2")
    rd = RunDir(out)
    rd.check_writable()
    cfg = apply_overrides(StepLearnConfig(), DEMO_LEARN)
    if rd.exists("metrics.json"):
        _check_demo_run(rd, cfg, robot.name)
        progress(f"demo: {out} already holds a finished demo run; reusing it")
    else:
        resume = rd.exists("style.json")
        motion = load_motion(default_clip())
        progress(f"[1/4] style: {Path(motion.source).name} on the robot's legs")
        gait = gait_from_motion(motion, robot, Provenance(robot="hoap2"))
        progress("[2/4] learn: the stepping gait's gains by CMA-ES (demo budget)")
        learn_clip(
            gait,
            robot,
            cfg,
            out,
            load_protocol(cfg.protocol),
            resume=resume,
            progress=lambda s: progress("      " + s),
        )
    progress(
        "[3/4] evaluate: learned and shipped gains on the eval protocol's first 8 robots x 20 s"
    )
    ev = judge_protocol(out, robot, load_protocol("eval"), 8, 20.0)
    judged = JudgedRobot(robot.name, "hoap2")  # recorded as `imitwalk evaluate` does
    rd.write_json("protocol_eval.json", {**ev.to_dict(), "robot": asdict(judged)})
    progress("[4/4] report: film strips, video")
    report = write_report(out, robot, progress=lambda s: progress("      " + s))
    side = ev.controllers
    summary = {
        "report": str(report),
        **{f"{name}_falls": f"{v.falls}/{v.robots}" for name, v in side.items()},
        "learned_speed_mps": side["learned"].speed_mps,
        "wall_seconds": time.perf_counter() - t0,
    }
    progress(f"demo: report written to {report}")
    return summary


def _check_demo_run(rd: RunDir, cfg: StepLearnConfig, robot: str) -> None:
    """Refuse a finished run that is not the demo's own (a stepping run of ``cfg`` on
    ``robot``, :func:`~imitwalk.step.pipeline.started_otherwise`): the demo would judge it
    as its own and overwrite its verdict.

    Raises:
        RunError: one line naming the folder.
    """
    from imitwalk.errors import RunError
    from imitwalk.step.pipeline import started_otherwise

    try:
        config = rd.read_json("config.json")
    except RunError:
        config = {}
    if config.get("learner") != "step" or started_otherwise(config, cfg, robot) is not None:
        raise RunError(
            f"--out {rd.path} holds a run that is not the demo's (other settings, robot or "
            "files); nothing was changed: give a new folder, or the demo's own"
        )
