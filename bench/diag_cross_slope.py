"""One-off diagnosis (deleted after this commit): the stepping gait on floors tilted across
and along the walk, 10 eval robots x 30 s, with the soles tilted onto the true slope
(IW_TRUE="sx,sy", rise per metre in the start frame) or not. Usage: python
bench/diag_cross_slope.py DEG[,DEG...]"""
import sys, numpy as np
from dataclasses import replace
from imitwalk.robots import load_robot
from imitwalk.mocap import default_clip, load_motion
from imitwalk.step.pipeline import gait_from_motion
from imitwalk.step.gains import StepGains
from imitwalk.step.controller import SteppingController
from imitwalk.judge.protocol import load_protocol
from imitwalk.sim.mujoco import MujocoPlant, run
robot = load_robot("hoap2")
style = gait_from_motion(load_motion(default_clip()), robot).style
proto = load_protocol("eval")
for deg in [float(x) for x in sys.argv[1].split(",")]:
    falls = 0
    for seed in range(10):
        d = proto.draw(seed, robot, seconds=30)
        plant = MujocoPlant(robot, replace(d.options, control_hz=100))
        th = np.radians(deg)
        plant.model.opt.gravity[:] = 9.81 * np.array([0.0, -np.sin(th), -np.cos(th)])  # the floor rises to the left
        ro = run(plant, SteppingController(robot, style, StepGains(), 0.01), 3000)
        falls += ro.fell; ft = ro.fall_time
        if seed < 3: print("  seed", seed, "fall", ft, flush=True)
    print("cross slope", deg, "falls", falls, "of 10", flush=True)
