"""A prototype: swing-foot placement on the gyro's deviation from the nominal robot's.

``bench/foot_placement.py`` moves the swing leg by the raw gyro, so the gait's own sway
moves it every step. Here the law acts on gyro_x and gyro_y less the nominal robot's, per
loop tick (the walk's own profile, as the torso gain's pitch is), so the swing foot moves
only for what the gait does not do by itself. Each gain is tried on validation robots of
the hard protocol's kicks alone and of eval.

Usage: ``python bench/step_deviation.py RUN [--seeds 20] [--first 300000]``; prints JSON.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import pathlib
from dataclasses import replace

import numpy as np

from imitwalk.balance.tickmodel import nominal_profile
from imitwalk.balance.tickrun import TickJob, run_tick_episode
from imitwalk.judge.protocol import RobotDraw, load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.robots import load_robot

_spec = importlib.util.spec_from_file_location(
    "foot_placement", pathlib.Path(__file__).with_name("foot_placement.py")
)
fp = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(fp)  # swing_law, falls

GAINS = (-0.3, -0.15, 0.15, 0.3)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir")
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--first", type=int, default=300_000)
    a = ap.parse_args()
    robot, run = load_robot("hoap2"), load_run(a.run_dir)
    base = tuple(run.laws["learned"])
    job = TickJob(run.path + "/reference.npz", robot, run.scale, base, 0,
                  RobotDraw(0, run.ref.sim_options()).options, 20.0,
                  **run.settings_of("learned"))  # fmt: skip
    ep = run_tick_episode(job).episode
    start = run.ref.starts.shape[1]
    cut = type(ep)(ep.phase[start:], ep.features[start:], ep.actions[start:])
    nominal = nominal_profile([cut], ("gyro_x", "gyro_y"), run.ref.loops.shape[1])  # (N, 2)
    hard = load_protocol("hard")
    protocols = {"kicks": hard.only(("pushes",)), "eval": load_protocol("eval")}
    rows = []
    variants = [("learned", 0.0, 0.0)]
    variants += [("roll", k, 0.0) for k in GAINS] + [("pitch", 0.0, k) for k in GAINS]
    for name, kr, kp in variants:
        laws = base
        if name != "learned":
            laws = (*base, replace(fp.swing_law(run.ref.stance, kr, kp), nominal=nominal))
        row = {"law": name, "k_roll": kr, "k_pitch": kp}
        for p, proto in protocols.items():
            row[p] = fp.falls(run, robot, laws, proto, a.seeds, a.first)["falls"]
        rows.append(row)
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
