"""A hoap2 run's trial-picked law plus ``k`` × (the torso's pitch less the nominal robot's) on
both ankle pitches, on validation robots (a one-off measurement for the tilt gain).

Usage: ``python tilt_sweep.py RUN K1,K2,... [PROTOCOL[:FACTOR,...]] [ROBOTS] [FIRST]``,
e.g. ``python tilt_sweep.py RUN 0,0.1,0.2,0.3,0.5 hard:slope 40 300000``; the run's own
reference settings (its feedforward) are kept. Prints one line per ``k``.
"""

import sys

import numpy as np

from imitwalk.balance.tickrun import TickJob, run_tick_episode
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.parallel import run_parallel
from imitwalk.robots import load_robot

run_dir, ks = sys.argv[1], [float(x) for x in sys.argv[2].split(",")]
spec = sys.argv[3] if len(sys.argv) > 3 else "hard:slope"
n = int(sys.argv[4]) if len(sys.argv) > 4 else 40
first = int(sys.argv[5]) if len(sys.argv) > 5 else 300_000
run, robot = load_run(run_dir), load_robot("hoap2")
(base,) = run.laws["feedback"]
name, _, factors = spec.partition(":")
protocol = load_protocol(name)
if factors:
    protocol = protocol.only(tuple(factors.split(",")))
draws = [protocol.draw(first + s, robot, run.ref.sim_options(), 30.0) for s in range(n)]
for k in ks:
    law = base.with_gain("ankle_pitch", "pitch", base.gain("ankle_pitch", "pitch") + k)
    jobs = [
        TickJob(run.path + "/reference.npz", robot, run.scale, (law,), d.seed, d.options, 30.0,
                record=False, **run.settings_of("learned"))
        for d in draws
    ]  # fmt: skip
    res = run_parallel(run_tick_episode, jobs)
    print(f"k={k:g} {spec}: falls {sum(r.fell for r in res)}/{n}, "
          f"distance {np.mean([r.distance_m for r in res]):.2f} m", flush=True)  # fmt: skip
