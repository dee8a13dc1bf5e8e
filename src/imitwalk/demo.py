"""``imitwalk demo``: the whole pipeline on the embedded walk, on a small budget.

Retargets pybullet's ``humanoid3d_walk`` (IK on the robot, with a small parameter
search), learns with the extended variant on a short schedule, evaluates the learned
gait against open-loop playback, and writes the HTML report. ``imitwalk learn`` and
``imitwalk evaluate`` with their defaults are the full-budget versions.
"""

from __future__ import annotations

import time
from pathlib import Path

from imitwalk.commands import progress

__all__ = ["DEMO_LEARN", "DEMO_RETARGET", "run_demo"]


#: The demo's budget: a small reference search, a short schedule, a quick evaluation.
DEMO_RETARGET = [
    "search_config.generations=2",
    "search_config.population=6",
    "search_config.seconds=10",
    "search_config.models=2",
]
DEMO_LEARN = [
    "schedule.start=0.5",
    "schedule.iterations=2",
    "schedule.seconds=10",
    "train_models=2",
    "schedule.confirm=1",
    "schedule.retries=3",
    "schedule.consolidate=0",
    "gain_robots=3",
    "gain_seconds=12",
]


def run_demo(out: Path) -> dict:
    """Retarget the embedded clip, learn, evaluate and report into ``out``; the summary."""
    from imitwalk.config import apply_overrides
    from imitwalk.evaluate import evaluate_run
    from imitwalk.learnconfig import preset
    from imitwalk.learner import learn as run_learn
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.report import write_report
    from imitwalk.retarget import Reference, RetargetConfig
    from imitwalk.retarget import retarget as do_retarget
    from imitwalk.robots import load_robot
    from imitwalk.runs import RunDir

    t0 = time.perf_counter()
    robot = load_robot("hoap2")
    rd = RunDir(out)
    lcfg = apply_overrides(preset("extended"), DEMO_LEARN)
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
            ref = do_retarget(
                motion,
                robot,
                cfg,
                progress=lambda g, n, s, p: progress(f"      search {g}/{n}: best score {s:.3f}"),
            ).reference
            ref.settings["robot"] = "hoap2"
        progress("[2/4] learn (extended variant; demo schedule 0.5 -> 1.0)")
        run_learn(ref, robot, lcfg, out, resume=resume, progress=lambda s: progress("      " + s))
    progress("[3/4] evaluate: learned vs open loop on 4 robots x 20 s")
    ev = evaluate_run(out, robot, seconds=20.0, seeds=4)
    rd.write_json("evaluation.json", ev)
    progress("[4/4] report: figures, film strips, video")
    report = write_report(out, robot, progress=lambda s: progress("      " + s))
    wall = time.perf_counter() - t0
    summary = {
        "report": str(report),
        "scale_reached": ev["learned"]["scale_reached"],
        "learned_falls": f"{ev['learned']['falls']}/{ev['learned']['seeds']}",
        "open_loop_falls": f"{ev['open_loop']['falls']}/{ev['open_loop']['seeds']}",
        "learned_speed_mps": ev["learned"]["forward_speed_mps"]["mean"],
        "wall_seconds": wall,
    }
    progress(f"demo: report written to {report}")
    return summary
