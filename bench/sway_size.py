"""Does the start-up rock on grippy floors come from the sway's size? (A one-off check.)

Walks a run's learned laws on references that differ only in their sway (``imitwalk
retarget --no-search --set params.sway=S --set params.X=...`` with the run's other
searched parameters), on validation robots (seeds from 300 000) of the hard protocol's
friction factor alone, of the hard protocol without its kicks, and of eval; 30 s each.

Usage: ``python bench/sway_size.py RUN ROBOTS REF.npz [REF.npz ...]``; prints JSON lines.
"""

from __future__ import annotations

import json
import sys

from imitwalk.balance.tickrun import TickJob, run_tick_episode
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.parallel import run_parallel
from imitwalk.retarget import Reference
from imitwalk.robots import load_robot


def main() -> None:
    run, robot = load_run(sys.argv[1]), load_robot("hoap2")
    laws, n = tuple(run.laws["learned"]), int(sys.argv[2])
    hard = load_protocol("hard")
    variants = [
        hard.only(("friction",)),
        hard.only(tuple(f for f in hard.factors if f != "pushes")),
        load_protocol("eval"),
    ]
    for path in sys.argv[3:]:
        ref = Reference.load(path)
        for p in variants:
            draws = [p.draw(300_000 + s, robot, ref.sim_options(), 30.0) for s in range(n)]
            jobs = [TickJob(path, robot, 1.0, laws, d.seed, d.options, 30.0, record=False)
                    for d in draws]  # fmt: skip
            res = run_parallel(run_tick_episode, jobs)
            falls = sorted(round(float(r.fall_time_s or 0.0), 1) for r in res if r.fell)
            print(json.dumps({"ref": path, "sway": ref.params["sway"], "protocol": p.name,
                              "falls": len(falls), "fall_times_s": falls}), flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
