"""One-off diagnosis (deleted after this commit): the stepping gait on a floor sloped DEG
along the walk, 10 eval robots x 30 s (IW_TRUE as in diag_cross_slope.py)."""
import os, sys, numpy as np
from dataclasses import replace
from imitwalk.robots import load_robot
from imitwalk.mocap import default_clip, load_motion
from imitwalk.step.pipeline import gait_from_motion
from imitwalk.step.gains import StepGains
from imitwalk.step.controller import SteppingController
from imitwalk.judge.protocol import load_protocol
from imitwalk.sim.mujoco import make_plant, run
robot = load_robot("hoap2")
style = gait_from_motion(load_motion(default_clip()), robot).style
proto = load_protocol("eval")
deg = float(sys.argv[1])
falls = 0
for seed in range(10):
    d = proto.draw(seed, robot, seconds=30)
    c = SteppingController(robot, style, StepGains(), 0.01)
    ro = run(make_plant(robot, replace(d.options, control_hz=100, slope_deg=deg)), c, 3000)
    falls += ro.fell
print(deg, "truth-slope" if os.environ.get("IW_TRUE_SLOPE") else "plain", "falls", falls)
