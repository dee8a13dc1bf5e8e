"""Where a learned episode spends its time.

Runs the learned controller of a finished run folder for one episode (evaluation robot
``--seed``, ``--seconds`` simulated, at the scale the run reached) under ``cProfile`` and
prints one JSON object: the episode's wall time and the cumulative time of each part,
with its share of the episode:

- ``physics``: ``mj_step`` (MuJoCo's own stepping);
- ``online_ik``: the per-tick whole-body IK (mink) that turns the step channels' task
  offsets into joint targets (:mod:`imitwalk.retarget.online`);
- ``step_search``: the step model's predictive search (:mod:`imitwalk.balance`);
- ``policy``: everything the controller does per tick (the two above and the gait);
- ``other``: the rest (the plant's sensors and servos, the run loop).

Usage: ``python bench/episode_profile.py RUN_DIR [--seed 3] [--seconds 30]``. Profiling
slows the run down; the shares, not the absolute times, are the figure.
"""

from __future__ import annotations

import argparse
import cProfile
import json
import pstats
import time

from imitwalk.evaluate import load_gait
from imitwalk.perturb import perturbed
from imitwalk.robots import load_robot
from imitwalk.sim import make_plant, run

#: Parts of an episode, by the ``(file suffix, function name)`` whose cumulative time
#: they are.
PARTS = {
    "physics": ("~", "<built-in method mujoco._functions.mj_step>"),
    "online_ik": ("imitwalk/retarget/online.py", "__call__"),
    "step_search": ("imitwalk/balance.py", "_search"),
    "policy": ("imitwalk/policy.py", "__call__"),
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir")
    ap.add_argument("--seed", type=int, default=3, help="evaluation robot (3)")
    ap.add_argument("--seconds", type=float, default=30.0)
    args = ap.parse_args()
    lg = load_gait(args.run_dir)
    robot = load_robot(lg.ref.settings.get("robot", lg.ref.robot))  # as `imitwalk evaluate`
    ref = lg.gait.ref
    opts = perturbed(args.seed, ref.sim_options(None), disturbance=args.seed != 0)
    policy = lg.policy(robot)
    plant = make_plant(robot, opts, lg.config.engine)
    prof = cProfile.Profile()
    t0 = time.perf_counter()
    prof.enable()
    ro = run(plant, policy, round(args.seconds / ref.dt))
    prof.disable()
    wall = time.perf_counter() - t0
    stats = pstats.Stats(prof).stats  # {(file, line, name): (cc, nc, tt, ct, callers)}
    out = {"run": str(args.run_dir), "seed": args.seed, "simulated_s": ro.seconds}
    out["episode_wall_s"] = wall
    parts = {}
    for part, (suffix, name) in PARTS.items():
        ct = sum(v[3] for (f, _, n), v in stats.items() if n == name and f.endswith(suffix))
        parts[part] = {"seconds": ct, "share": ct / wall}
    rest = wall - parts["physics"]["seconds"] - parts["policy"]["seconds"]
    parts["other"] = {"seconds": rest, "share": rest / wall}
    out["parts"] = parts
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
