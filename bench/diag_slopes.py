"""One-off diagnosis (deleted in the next commit): the stepping gait on floors sloped along
and across the walk, default clip, shipped gains, 10 eval robots x 30 s. Usage: python
bench/diag_slopes.py a5,a-5,c5,c-5 (a: along the walk, positive uphill; c: across, positive
rising to the left; degrees)."""

import sys
from dataclasses import replace

from imitwalk.mocap import default_clip, load_motion
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import make_plant, run
from imitwalk.sim.protocol import load_protocol
from imitwalk.step.controller import SteppingController
from imitwalk.step.gains import StepGains
from imitwalk.step.pipeline import gait_from_motion

robot = load_robot("hoap2")
style = gait_from_motion(load_motion(default_clip()), robot).style
proto = load_protocol("eval")
for spec in sys.argv[1].split(","):
    kind, deg = spec[0], float(spec[1:])
    falls, times = 0, []
    for seed in range(10):
        d = proto.draw(seed, robot, seconds=30)
        kw = {"slope_deg": deg} if kind == "a" else {"cross_slope_deg": deg}
        c = SteppingController(robot, style, StepGains(), 0.01)
        ro = run(make_plant(robot, replace(d.options, control_hz=100, **kw)), c, 3000)
        falls += ro.fell
        if ro.fell:
            times.append(round(ro.fall_time, 1))
    print(spec, "falls", falls, "of 10", times, flush=True)
