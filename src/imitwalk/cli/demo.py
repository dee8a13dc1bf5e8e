"""``imitwalk demo``: the whole pipeline on the embedded walk, on a small budget.

Retargets pybullet's ``humanoid3d_walk`` (IK on the robot at the scales the demo's
schedule walks, with a small parameter search), learns the per-tick balance on a small
budget, judges every controller of the run against open-loop playback on the eval
protocol's first robots, and writes the HTML report. ``imitwalk learn`` and ``imitwalk
evaluate`` with their defaults are the full-budget versions.
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

from imitwalk.cli.progress import progress

__all__ = ["DEMO_LEARN", "DEMO_RETARGET", "run_demo"]


#: The demo's budget: a small reference search, a short schedule, a quick evaluation.
DEMO_RETARGET = [
    "search_config.generations=2",
    "search_config.population=6",
    "search_config.seconds=10",
    "search_config.models=2",
]
DEMO_LEARN = ["start=0.6", "step=0.2", "iterations=2", "robots=2", "seconds=6",
              "trials.robots=4", "trials.seconds=10", "trials.heading_robots=2",
              "trials.heading_seconds=20"]  # fmt: skip


def run_demo(out: Path) -> dict:
    """Retarget the embedded clip, learn, evaluate and report into ``out``; the summary."""
    from imitwalk.balance.tickconfig import TickLearnConfig
    from imitwalk.balance.ticklearn import learn_tick
    from imitwalk.config import apply_overrides
    from imitwalk.evidence.report import write_report
    from imitwalk.judge.protocol import load_protocol
    from imitwalk.judge.verdict import judge_protocol
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.retarget import Reference, RetargetConfig
    from imitwalk.retarget import retarget as do_retarget
    from imitwalk.robots import load_robot
    from imitwalk.runs import RunDir

    t0 = time.perf_counter()
    robot = load_robot("hoap2")
    rd = RunDir(out)
    rd.check_writable()
    lcfg = apply_overrides(TickLearnConfig(), DEMO_LEARN)
    if rd.exists("metrics.json"):
        progress(f"demo: {out} already holds a finished run; reusing it")
    else:
        resume = rd.exists("checkpoint.json") and rd.exists("reference.npz")
        if resume:
            progress(f"[1/4] retarget: reusing the reference of the interrupted run in {out}")
            ref = Reference.load(rd.file("reference.npz"))
        else:
            motion = load_motion(default_clip())
            progress(f"[1/4] retarget {Path(motion.source).name}: IK on the robot + search")
            cfg = apply_overrides(RetargetConfig(), DEMO_RETARGET)
            # IK only at the scales the demo's schedule walks (not the full 0.1 … 1.0 grid)
            cfg = replace(cfg, scales=lcfg.scales())
            ref = do_retarget(
                motion,
                robot,
                cfg,
                progress=lambda g, n, s, p: progress(f"      search {g}/{n}: best score {s:.3f}"),
            ).reference
            ref.settings["robot"] = "hoap2"
        progress("[2/4] learn: per-tick balance by trials, then the paper's loop (demo budget)")
        learn_tick(ref, robot, lcfg, out, resume=resume, progress=lambda s: progress("      " + s))
    progress("[3/4] evaluate: every controller on the eval protocol's first 8 robots x 20 s")
    ev = judge_protocol(out, robot, load_protocol("eval"), 8, 20.0)
    rd.write_json("protocol_eval.json", ev.to_dict())
    progress("[4/4] report: figures, film strips, video")
    report = write_report(out, robot, progress=lambda s: progress("      " + s))
    side = ev.controllers
    summary = {
        "report": str(report),
        "scale_reached": ev.settings.scale,
        **{f"{name}_falls": f"{v.falls}/{v.robots}" for name, v in side.items()},
        "learned_speed_mps": side["learned"].speed_mps,
        "wall_seconds": time.perf_counter() - t0,
    }
    progress(f"demo: report written to {report}")
    return summary
