"""A run's learned controller judged on one protocol's robots from seed ``FIRST`` on.

``imitwalk evaluate`` judges robots 0 … N − 1; this walks ``FIRST`` … ``FIRST + N − 1``
instead: training robots (``--first 1001``, the default; ``imitwalk learn CLIP`` judges
its two references there itself, :mod:`imitwalk.learning.refchoice`) or validation robots
(``--first 300000``). It prints JSON: the falls, each fall's seed and time [s], the
slowest robot's progress ratio and the mean forward distance [m].

Usage: ``python bench/judge_training.py RUN [--protocol eval] [--first 1001]
[--robots 40] [--seconds 30] [--robot hoap2]``.
"""

from __future__ import annotations

import argparse
import json

from imitwalk.judge.verdict import judge_protocol
from imitwalk.robots import load_robot
from imitwalk.sim.protocol import load_protocol


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run")
    ap.add_argument("--protocol", default="eval")
    ap.add_argument("--first", type=int, default=1001)
    ap.add_argument("--robots", type=int, default=40)
    ap.add_argument("--seconds", type=float, default=30.0, help="simulated seconds per robot")
    ap.add_argument("--robot", default="hoap2")
    a = ap.parse_args()
    p = load_protocol(a.protocol)
    out = judge_protocol(
        a.run, load_robot(a.robot), p, a.robots, a.seconds, ("learned",), first=a.first
    )
    v = out.controllers["learned"]
    fell = [(s.seed, round(s.fall_time_s, 1)) for s in v.per_seed if s.fell]
    print(
        json.dumps(
            {
                "first": a.first,
                "falls": v.falls,
                "robots": v.robots,
                "fell": fell,
                "progress_min": round(v.progress_ratio_min, 3),
                "distance_m": round(v.distance_m, 3),
            }
        )
    )


if __name__ == "__main__":
    main()
