"""Fuzz the robot loader: seeded mutations of hoap2's joint map and MJCF (issue 34).

Loads each mutated pair as a user's robot (:func:`imitwalk.robots.load_robot`) in a
worker process with a time limit per case, and prints one JSON object: per input (the
joint map, the MJCF) how many cases gave a clean project error, were accepted with finite
arrays within the plausibility bounds (:mod:`imitwalk.robots.plausible`), raised another
exception, were accepted with a NaN or infinity, were accepted outside those bounds, or
hung; and the first failing cases. The mutations are in ``tests/robot_fuzz.py``.

Usage: ``python bench/fuzz_robot.py [--cases 4000] [--seed 1] [--timeout 20]``
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from robot_fuzz import fuzz


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=4000, help="cases, half per input (4000)")
    ap.add_argument("--seed", type=int, default=1, help="random seed (1)")
    ap.add_argument("--timeout", type=float, default=20.0, help="time limit per case [s] (20)")
    args = ap.parse_args()
    t0 = time.perf_counter()
    out = fuzz(args.cases, args.seed, args.timeout)
    out["wall_seconds"] = round(time.perf_counter() - t0, 1)
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
