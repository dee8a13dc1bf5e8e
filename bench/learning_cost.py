"""What learning one clip costs: simulated seconds and wall seconds, per stage.

Retargets the clip (with the reference-parameter search, unless ``--reference`` is
given), learns with the given variant, and evaluates; prints JSON with each stage's
wall time and the learning's simulated time.

Usage: ``python bench/learning_cost.py [CLIP] [--variant extended] [--reference REF.npz]``
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time

from imitwalk.evaluate import evaluate_run
from imitwalk.learnconfig import preset
from imitwalk.learner import learn
from imitwalk.mocap import default_clip, load_motion
from imitwalk.retarget import Reference, retarget
from imitwalk.robots import load_robot


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("clip", nargs="?", help="mocap file (default: the embedded walk)")
    ap.add_argument("--variant", default="extended")
    ap.add_argument("--reference", help="skip retargeting: use this .npz")
    ap.add_argument("--seeds", type=int, default=10)
    args = ap.parse_args()
    robot = load_robot("hoap2")
    out = {
        "clip": args.clip or "humanoid3d_walk (default)",
        "variant": args.variant,
        "cores": os.cpu_count(),
    }
    t = time.perf_counter()
    if args.reference:
        ref = Reference.load(args.reference)
    else:
        res = retarget(load_motion(args.clip or default_clip()), robot)
        ref = res.reference
        out["retarget_search_sim_seconds"] = ref.search["sim_seconds"]
    out["retarget_wall_seconds"] = round(time.perf_counter() - t, 1)
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        summary = learn(ref, robot, preset(args.variant), tmp)
        out["learn_wall_seconds"] = round(time.perf_counter() - t, 1)
        out["learn_sim_seconds"] = round(summary["sim_seconds_used_for_learning"], 1)
        out["iterations"] = summary["iterations"]
        out["scale_reached"] = summary["scale_reached"]
        t = time.perf_counter()
        ev = evaluate_run(tmp, robot, 30.0, args.seeds)
        out["evaluate_wall_seconds"] = round(time.perf_counter() - t, 1)
        out["learned_falls"] = ev["learned"]["falls"]
        out["open_loop_falls"] = ev["open_loop"]["falls"]
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
