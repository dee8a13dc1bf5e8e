"""The rolled runs judged on validation robots (eval's factors from seed 300 000, 30 s).

Usage: ``ROLL_ROBOT=g1.json python bench/rolling_validate.py SCALE N RUN [RUN ...]``: the
learned controller of each run at ``SCALE`` on ``N`` robots, with the servo feedforward
taught the rolling foot's pitch (``bench/rolling_foot.py``).
"""

from __future__ import annotations

import importlib.util
import json
import os
import sys
from pathlib import Path

from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.verdict import judge_protocol
from imitwalk.retarget.ik import leg_geometry
from imitwalk.robots import load_robot


def main() -> None:
    spec = importlib.util.spec_from_file_location(
        "rolling_foot", Path(__file__).with_name("rolling_foot.py")
    )
    assert spec is not None and spec.loader is not None
    rolling = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(rolling)
    state = rolling._install_walk()
    robot = load_robot(os.environ["ROLL_ROBOT"])
    state["foot_length"] = leg_geometry(robot).foot_length
    scale, n = float(sys.argv[1]), int(sys.argv[2])
    for run in sys.argv[3:]:
        v = judge_protocol(
            run, robot, load_protocol("eval"), n, 30.0, ("learned",), scale=scale, first=300_000
        )
        c = v.controllers["learned"]
        print(
            json.dumps({"run": run, "scale": scale, "falls": c.falls, "d": round(c.distance_m, 2)})
        )


if __name__ == "__main__":
    main()
