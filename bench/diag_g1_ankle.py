"""One-off diagnosis (committed to be cited, then deleted): a robot's stepping gait with
the shipped gains but for the ones given, the nominal robot, 5 s; with ``NOLIFT=1`` it
never lifts a foot (the start's double support held), to see whether it stands.

Usage: ``[NOLIFT=1] python d.py ROBOT [GAIN=VALUE ...]``, e.g. ``NOLIFT=1 python d.py
g1.json ankle=1``; prints every 0.2 s the torso's pitch [deg], the centre of mass ahead of
the stance sole [mm] (simulator's truth, never the controller's), the estimated DCM and
the commanded ZMP [mm].
"""

import math
import os
import sys
from dataclasses import replace

from imitwalk.mocap import default_clip, load_motion
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import MujocoPlant
from imitwalk.sim.types import SimOptions
from imitwalk.step import controller as C
from imitwalk.step.gains import StepGains
from imitwalk.step.pipeline import gait_from_motion

robot = load_robot(sys.argv[1])
style = gait_from_motion(load_motion(default_clip()), robot).style
kw = dict(a.split("=") for a in sys.argv[2:])
gains = replace(StepGains(), **{k: float(v) for k, v in kw.items()})
if os.environ.get("NOLIFT"):
    C.SteppingController._advance = lambda self, e: None
p = MujocoPlant(robot, SimOptions())
c = C.SteppingController(robot, style, gains, 0.01, log=True)
obs = p.reset(c.q0)
m, d = p.model, p.data
for k in range(500):
    q = c(k, obs)
    p.command(q)
    obs = p.step()
    if k % 20 == 0:
        t = c.ticks[-1]
        R = d.xmat[p._torso].reshape(3, 3)
        pitch = math.degrees(math.atan2(-R[0, 2], R[2, 2]))
        ahead = p.com()[0] - d.site_xpos[m.site(robot.soles[c.stance]).id][0]
        print(
            f"t {k * 0.01:.2f} {t.stance}{'S' if t.single else 'D'} pitch {pitch:5.1f} "
            f"com ahead {1000 * ahead:6.1f} dcm est {1000 * t.dcm[0]:6.1f},"
            f"{1000 * t.dcm[1]:6.1f} zmp {1000 * t.zmp[0]:6.1f}"
        )
    if p.fell:
        print("fell", round(k * 0.01, 2))
        break
