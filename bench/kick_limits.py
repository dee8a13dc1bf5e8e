"""A diagnosis: are the hard robots' falls the servos' torque limits, or the crouch?

Walks a run's learned controller (its laws and reference settings) on validation robots
(seeds from ``--first``) of the hard protocol's kicks alone, of hard without its kicks,
and of eval, with the leg servos' torque limits of ``--joints`` multiplied by each of
``--factors`` (1: as the robot is), and on each reference of ``--refs`` (the run's own by
default; e.g. ones with a higher pelvis, built with ``imitwalk retarget --no-search
--set params.height=H ...``). A raised limit is not a product option: it asks whether
the 4 Nm the knees reach in every step is what fells the kicked robots.

Usage: ``python bench/kick_limits.py RUN [--refs A.npz,B.npz] [--joints knee]
[--factors 1,1.5,2] [--robots 20] [--first 300000]``; prints JSON lines.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

import imitwalk.sim.mujoco as sim
from imitwalk.balance.tickrun import TickJob, run_tick_episode
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.parallel import run_parallel
from imitwalk.robots import load_robot

_FACTOR = {"joints": (), "factor": 1.0}
_init = sim.MujocoPlant.__init__


def _plant_init(self, robot, options=None):
    """The plant as built, with the named leg servos' torque limits scaled."""
    _init(self, robot, options)
    for role in _FACTOR["joints"]:
        for side in "lr":
            j = robot.joint_names.index(f"{side}_{role}")
            self.model.actuator_forcerange[self._act[j]] *= _FACTOR["factor"]
            self.model.jnt_actfrcrange[self._jid[j]] *= _FACTOR["factor"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir")
    ap.add_argument("--refs", default="", help="references to walk (default: the run's)")
    ap.add_argument("--joints", default="knee", help="leg roles whose limits are scaled")
    ap.add_argument("--factors", default="1")
    ap.add_argument("--robots", type=int, default=20)
    ap.add_argument("--first", type=int, default=300_000)
    a = ap.parse_args()
    sim.MujocoPlant.__init__ = _plant_init  # workers fork from here
    run, robot = load_run(a.run_dir), load_robot("hoap2")
    hard = load_protocol("hard")
    protocols = {
        "kicks": hard.only(("pushes",)),
        "no kicks": hard.only(tuple(f for f in hard.factors if f != "pushes")),
        "eval": load_protocol("eval"),
    }
    refs = [r for r in a.refs.split(",") if r] or [run.path + "/reference.npz"]
    _FACTOR["joints"] = tuple(a.joints.split(","))
    for ref in refs:
        for factor in (float(x) for x in a.factors.split(",")):
            _FACTOR["factor"] = factor
            row = {"ref": ref, "joints": a.joints, "factor": factor}
            for name, proto in protocols.items():
                draws = [proto.draw(a.first + s, robot, run.ref.sim_options(), 30.0)
                         for s in range(a.robots)]  # fmt: skip
                jobs = [TickJob(ref, robot, run.scale, tuple(run.laws["learned"]), d.seed,
                                d.options, 30.0, record=False, **run.settings_of("learned"))
                        for d in draws]  # fmt: skip
                res = run_parallel(run_tick_episode, jobs)
                row[name] = int(sum(r.fell for r in res))
                row[name + " m"] = round(float(np.mean([r.distance_m for r in res])), 2)
            print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
