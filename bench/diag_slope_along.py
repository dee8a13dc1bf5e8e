"""One-off diagnosis (committed to be cited, then deleted): the stepping gait on ±5°
along the walk with both soles laid onto the floor's slope (along and across), by the
estimator's smoothed slope (``est``), its fast one (``estfast``) or the simulator's true
slope (``true``, an oracle never in the product), against the product (``product``: the
soles laid onto the slope across the walk only).

Usage: ``MODE=product|est|estfast|true python d.py walk RUN DEG [STRIDES]`` (10 ``eval``
robots × 30 s; STRIDES a comma list of stride shares, 1 the style's) or ``MODE=...
python d.py trace RUN DEG [TICKS]`` (the nominal robot: the centre of mass in gravity's
frame against the stance sole, the torso's pitch, the knees' torques).
"""

import math
import os
import sys
from dataclasses import replace
from multiprocessing import Pool

import numpy as np

from imitwalk.judge.replay import load_run
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import MujocoPlant, make_plant, run
from imitwalk.sim.protocol import load_protocol
from imitwalk.sim.types import SimOptions
from imitwalk.step import controller as C
from imitwalk.step.controller import SteppingController
from imitwalk.step.odometry import StepCommand

MODE = os.environ.get("MODE", "product")
CMD, RUN, DEG = sys.argv[1], sys.argv[2], float(sys.argv[3])
_orig, _fm, _cur = C.SteppingController._joints, C.floor_mat, {}
C.floor_mat = lambda s: _fm(_cur["s"]) if "s" in _cur else _fm(s)


def _joints(self, e):
    if MODE == "product":
        return _orig(self, e)
    if MODE == "est":
        sl = e.settled_slope.copy()
    elif MODE == "estfast":
        sl = e.slope.copy()
    else:  # the true slope in the stance frame (heading from the controller's estimate)
        t = math.tan(math.radians(DEG))
        sl = np.array([t * math.cos(self._heading), -t * math.sin(self._heading)])
    _cur["s"] = sl
    try:
        return _orig(self, e)
    finally:
        _cur.clear()


C.SteppingController._joints = _joints
robot = load_robot("hoap2")
lr = load_run(RUN)
style, gains = lr.step_gait.style, lr.step_gains["learned"]


def one(args):
    seed, stride = args
    d = load_protocol("eval").draw(seed, robot, seconds=30)
    c = SteppingController(robot, style, gains, 0.01)
    if stride < 1:
        c.steer(StepCommand(stride=stride))
    ro = run(make_plant(robot, replace(d.options, slope_deg=DEG)), c, 3000)
    return ro.fell, ro.fall_time, float(ro.torso_pos[-1, 0] - ro.torso_pos[0, 0])


def trace(ticks: int) -> None:
    p = MujocoPlant(robot, SimOptions(slope_deg=DEG))
    c = SteppingController(robot, style, gains, 0.01, log=True)
    obs = p.reset(c.q0)
    m, d = p.model, p.data
    zg = -m.opt.gravity / np.linalg.norm(m.opt.gravity)
    xg = np.array([1.0, 0, 0]) - zg * zg[0]
    xg /= np.linalg.norm(xg)
    kn = robot.indices(["l_knee", "r_knee"])
    sl = {s: m.site(robot.soles[s]).id for s in "lr"}
    for k in range(ticks):
        q = c(k, obs)
        p.command(q)
        obs = p.step()
        if k % 10 == 0:
            t = c.ticks[-1]
            st = d.site_xpos[sl[c.stance]]
            R = d.xmat[p._torso].reshape(3, 3)
            pitch = math.degrees(math.atan2(-(R[:, 2] @ xg), R[:, 2] @ zg))
            print(
                f"t {k * 0.01:.2f} {t.stance}{'S' if t.single else 'D'} "
                f"com-stance sole (gravity frame) {1000 * ((p.com() - st) @ xg):6.1f} mm, "
                f"dcm est {1000 * t.dcm[0]:6.1f}, zmp {1000 * t.zmp[0]:6.1f} mm, torso "
                f"pitch {pitch:5.1f} deg, knees {p.torques()[kn].round(2)} Nm"
            )
        if p.fell:
            print("fell", round(k * 0.01, 2))
            break


if __name__ == "__main__":
    if CMD == "trace":
        trace(int(sys.argv[4]) if len(sys.argv) > 4 else 400)
    else:
        for stride in map(float, (sys.argv[4] if len(sys.argv) > 4 else "1").split(",")):
            with Pool(2) as pool:
                r = pool.map(one, [(s, stride) for s in range(10)])
            print(
                MODE,
                DEG,
                stride,
                "fell",
                sum(x[0] for x in r),
                "at",
                [round(x[1], 1) for x in r if x[0]],
                "walked",
                [round(x[2], 2) for x in r],
                flush=True,
            )
