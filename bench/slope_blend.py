"""A prototype: the reference blended toward the one planned for the robot's true floor slope.

The simulator's slope (an oracle: an upper bound for an estimate from the IMU and the
encoders) picks the reference built for ±TOP degrees (`imitwalk retarget --no-search --set
params.…=<the run's searched ones> --slope ±TOP --out UP.npz / DOWN.npz`), and each tick's
target moves by w × |slope| / TOP of the way from the run's reference to it. Walks the
run's learned controller on validation robots (seeds from 300 000) of hard's slopes alone,
of hard without its kicks, or of eval.

Usage: ``python bench/slope_blend.py RUN UP.npz DOWN.npz TOP W1,W2 ROBOTS slopes,nokicks``
"""
import sys, json, numpy as np
from imitwalk.balance.feedback import TickPolicy
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.parallel import run_parallel
from imitwalk.retarget.feedforward import walk_offsets
from imitwalk.retarget.reference import Reference
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import make_plant, run as sim_run
R = load_run(sys.argv[1]); up, down = Reference.load(sys.argv[2]), Reference.load(sys.argv[3]); top = float(sys.argv[4])
weights = [float(x) for x in sys.argv[5].split(",")]; n = int(sys.argv[6]); protos = sys.argv[7].split(",")
robot = load_robot("hoap2"); hard = load_protocol("hard")
P = {"slopes": hard.only(("slope",)), "nokicks": hard.only(tuple(f for f in hard.factors if f != "pushes")), "eval": load_protocol("eval")}
st = R.settings_of("learned")
def walk(job):
    opts, w = job
    ref = R.ref; T = 30.0
    off = walk_offsets(ref, robot, R.scale, T, st["feedforward"])
    pol = TickPolicy(ref, R.scale, tuple(R.laws["learned"]), robot.joint_names, T, offsets=off, wait=st["wait"])
    a = opts.slope_deg / top
    other = up if a > 0 else down
    q0, qs = ref.trajectory(R.scale, T), other.trajectory(R.scale, T)
    pol.q_cmd = pol.q_cmd + w * abs(a) * (qs - q0)[: len(pol.q_cmd)]
    plant = make_plant(robot, ref.sim_options(opts))
    ro = sim_run(plant, pol, len(pol.q_ref))
    return ro.fell
for w in weights:
    row = {"w": w}
    for p in protos:
        draws = [P[p].draw(300000 + s, robot, R.ref.sim_options(), 30.0) for s in range(n)]
        row[p] = int(sum(run_parallel(walk, [(d.options, w) for d in draws])))
    print(json.dumps(row), flush=True)
