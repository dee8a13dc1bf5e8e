"""A diagnosis, not a product option: the stepping controller with the simulator's true
centre of mass and velocity (so its DCM) in place of its estimate, on the hard protocol's
validation robots, against the estimate on the same robots.

Usage: ``python bench/oracle_state.py est|oracle [FIRST]`` (default clip, shipped gains,
40 robots from FIRST = 300 000, 30 s); prints the falls.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from multiprocessing import Pool

import mujoco
import numpy as np

from imitwalk.judge.protocol import load_protocol
from imitwalk.mocap import default_clip, load_motion
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import MujocoPlant
from imitwalk.step.controller import SteppingController
from imitwalk.step.gains import StepGains
from imitwalk.step.kinematics import rot_z
from imitwalk.step.pipeline import gait_from_motion

MODE = sys.argv[1]
ROBOT = load_robot("hoap2")
GAIT = gait_from_motion(load_motion(default_clip()), ROBOT)


def one(seed: int) -> bool:
    draw = load_protocol("hard").draw(seed, ROBOT, seconds=30)
    ctrl = SteppingController(ROBOT, GAIT.style, StepGains(), 0.01)
    plant = MujocoPlant(ROBOT, draw.options)
    m, d = plant.model, plant.data
    root = m.body("pelvis").id
    sole = {s: m.site(ROBOT.soles[s]).id for s in "lr"}
    obs = plant.reset(ctrl.q0)
    for k in range(3000):
        if k == 1 and MODE == "oracle":
            est, estimate = ctrl.est, ctrl.est.update

            def truth(o, hint, est=est, estimate=estimate):
                e = estimate(o, hint)
                mujoco.mj_subtreeVel(m, d)
                rot = d.site_xmat[sole[est.stance]].reshape(3, 3)
                turn = rot_z(-np.arctan2(rot[1, 0], rot[0, 0]))[:2, :2]
                c = turn @ (d.subtree_com[root][:2] - d.site_xpos[sole[est.stance]][:2])
                v = turn @ d.subtree_linvel[root][:2]
                est._x = np.stack([c, v], axis=1)
                com = np.array([c[0], c[1], e.com[2]])
                return replace(e, com=com, com_vel=v, dcm=c + v / ctrl.omega)

            est.update = truth
        plant.command(ctrl(k, obs))
        obs = plant.step()
        if plant.fell:
            return True
    return False


if __name__ == "__main__":
    first = int(sys.argv[2]) if len(sys.argv) > 2 else 300_000
    with Pool(2) as pool:
        falls = pool.map(one, range(first, first + 40))
    print(MODE, sum(falls), "of 40 fell")
