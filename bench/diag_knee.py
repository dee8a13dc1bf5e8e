"""One-off diagnosis: a kicked hoap2 and its stance knee (2026-12-07).

``python diag_knee.py RUN back 0 0.25`` walks RUN's nominal robot, kicks it as
``imitwalk evaluate RUN --push-recovery`` does (direction, phase of 8, speed [m/s]), and
prints per tick the planner's DCM and landing beside the simulator's truth (the stance
sole's pitch, the centre of mass, the true DCM over the sole) and the stance leg's
torque over its limit. Read beside the controller, never by it.
"""

import json
import math
import sys
from dataclasses import replace

import mujoco

from imitwalk.judge.pushes import DIRECTIONS, PHASES
from imitwalk.robots import load_robot
from imitwalk.sim.types import SimOptions
from imitwalk.step.episode import StepJob, walk_step
from imitwalk.step.gains import StepGains
from imitwalk.step.gait import StepGait

run, direction, phase, speed = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
robot = load_robot("hoap2")
gait = StepGait.load(run + "/style.json")
gains = StepGains(**json.load(open(run + "/gains.json"))["learned"])
t0 = gait.kick_time(phase, PHASES)
ang = DIRECTIONS[direction]
kick = ((t0, speed * math.cos(ang), speed * math.sin(ang)),)
opts = gait.sim_options(replace(SimOptions(), pushes=kick))
ctrl, ro, m = walk_step(StepJob(robot, gait.style, gains, 0, opts, t0 + 5), log=True)
print("kick at", round(t0, 3), "fell", m.fell, m.fall_time_s)
model = robot.compile()
data = mujoco.MjData(model)
sole = {s: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, robot.soles[s]) for s in "lr"}
names = list(ro.joint_names)
end = (m.fall_time_s or t0 + 5) + 0.05
prev = None
for i, tl in enumerate(ctrl.ticks):
    data.qpos[:] = ro.qpos[i]
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    com = data.subtree_com[1].copy()
    if prev is not None and t0 - 0.1 <= tl.t <= end and i % 2 == 0:
        s = sole[tl.stance]
        mat = data.site_xmat[s].reshape(3, 3)
        pitch = math.degrees(math.atan2(-mat[2, 0], mat[0, 0]))
        v = (com - prev) / ro.control_dt
        dcm = com[0] + v[0] / ctrl.omega - data.site_xpos[s][0]
        knee = names.index(f"{tl.stance}_knee")
        load = abs(ro.torque[i, knee]) / ro.torque_limit[knee]
        print(
            f"{tl.t:5.2f} {tl.stance}{'S' if tl.single else 'D'} dcm est {tl.dcm[0]:+.3f} "
            f"true {dcm:+.3f} land {tl.landing[0]:+.3f} ss {tl.ss:.2f} sole pitch {pitch:5.1f} "
            f"stance knee {load:.2f} of its limit, "
            f"{math.degrees(ro.q_cmd[i, knee] - ro.q[i, knee]):+.1f} deg behind"
        )
    prev = com
