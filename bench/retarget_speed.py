"""Retargeting throughput on one core: frames of IK solved per second.

Prints JSON with the walkable reference's whole-body IK (mink) and the paper's
human-skeleton mapping, on the default clip, without the parameter search.

Usage: ``python bench/retarget_speed.py [--repeat 3]``
"""

from __future__ import annotations

import argparse
import json
import os
import time

os.environ.setdefault("IMITWALK_WORKERS", "1")

from imitwalk.mocap import default_clip, load_motion
from imitwalk.retarget import GaitParams, RetargetConfig, extract_template, retarget
from imitwalk.retarget.walkable import build_walkable
from imitwalk.robots import load_robot


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="trials; the best is kept")
    args = ap.parse_args()
    robot = load_robot("hoap2")
    motion = load_motion(default_clip())
    template = extract_template(motion)
    walk = []
    for _ in range(args.repeat):
        b = build_walkable(template, robot, GaitParams(), [0.5, 1.0], 0.01)
        walk.append(b.frames / b.seconds)
    paper = []
    for _ in range(args.repeat):
        t = time.perf_counter()
        res = retarget(motion, robot, RetargetConfig(mapping="paper", scales=(1.0,)))
        paper.append(res.frames_solved / (time.perf_counter() - t))
    print(
        json.dumps(
            {
                "clip": motion.source.rsplit("/", 1)[-1],
                "walkable_frames_per_s": round(max(walk)),
                "walkable_frames": b.frames,
                "paper_mapping_frames_per_s": round(max(paper)),
                "cores": 1,
            },
            indent=2,
        )
    )


if __name__ == "__main__":
    main()
