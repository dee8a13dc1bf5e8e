"""The servos' sag taken out of the reference (:mod:`imitwalk.retarget.feedforward`) and
the phase wait, at fixed settings side by side on validation robots.

The product's learner picks both by trials (``trials.feedforward``, ``trials.wait``);
this bench walks chosen ones: ``--fractions`` scale the offset (0: the reference as it
is), ``--wait`` is the load share at which the reference's clock waits before a lift-off
(:class:`~imitwalk.balance.feedback.TickPolicy`; 0: never). The walk is the run's
controller, or open loop on a reference plus the learner's law with the gains of
``--gains pitch=G,roll=G,heading=G`` (a missing one is 0), on training robots (variant
``train``) or validation robots of hard's variants, eval's and bullet's (on Bullet).
Prints one JSON line per (variant, fraction): falls, their times, the mean distance [m]
(ground truth, for the figure only) and the largest offset [rad]. With ``--sway``,
instead, how the nominal robot's centre of mass follows the plan's sway in the first
cycle.

Usage: ``python bench/feedforward.py REF.npz --robot g1.json --scale 0.3 --robots 4
--seconds 10 --variants train --fractions 0,0.5,1 [--gains pitch=0.05] [--wait 0.3]``,
or ``python bench/feedforward.py RUN --variants friction,nokicks,eval``, or ``... --sway``.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from imitwalk.balance.feedback import TickPolicy
from imitwalk.balance.tickconfig import TickLearnConfig
from imitwalk.balance.tickstore import TRIAL_GAINS, feedback_law
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import OPEN_LOOP, load_run
from imitwalk.parallel import run_parallel
from imitwalk.retarget import Reference
from imitwalk.retarget.feedforward import reference_offsets, walk_offsets
from imitwalk.robots import load_robot
from imitwalk.sim.perturb import perturbed, train_seeds


def _walk(job) -> tuple[bool, float | None, float, float]:
    path, robot_name, scale, laws, options, seconds, offsets, wait, engine = job
    from imitwalk.sim.mujoco import make_plant, run

    ref, robot = Reference.load(path), load_robot(robot_name)
    policy = TickPolicy(ref, scale, laws, robot.joint_names, seconds, offsets=offsets, wait=wait)
    plant = make_plant(robot, ref.sim_options(options), engine)
    ro = run(plant, policy, round(seconds / ref.dt))
    distance = float(ro.torso_pos[-1, 0] - ro.torso_pos[0, 0]) if len(ro.t) else 0.0
    return bool(ro.fell), ro.fall_time, distance


def sway_follow(ref: Reference, robot, scale: float, offsets: np.ndarray) -> dict:
    """How the nominal training robot follows its reference over the start-up's first
    cycle (feet down), open loop: the knees' RMS error [°], and the centre of mass's
    sideways peak-to-peak ÷ the plan's and its lag [s] (ground truth, for the diagnosis)."""
    from imitwalk.sim.mujoco import MujocoPlant

    n = ref.loops.shape[1]
    plan = ref.plan_at(scale)["com"][:n, 1]
    policy = TickPolicy(ref, scale, (), robot.joint_names, n * ref.dt, offsets=offsets)
    plant = MujocoPlant(robot, perturbed(train_seeds(1)[0], ref.sim_options()))
    q_ref = ref.trajectory(scale, 2 * n * ref.dt)
    knees = [robot.joint_names.index(j) for j in ("l_knee", "r_knee")]
    obs, com, err = plant.reset(policy.q0), [], []
    for t in range(n):
        plant.command(policy(t, obs))
        obs = plant.step()
        com.append(plant.data.subtree_com[0][1])
        err.append(obs.joints[knees] - q_ref[t + 1, knees])
    y = np.array(com) - com[0]
    return {
        "knee_rms_deg": round(float(np.degrees(np.sqrt(np.mean(np.square(err))))), 2),
        "sway_measured_over_planned": round(float(np.ptp(y) / np.ptp(plan)), 2),
        "lag_s": round(float((np.argmin(y) - np.argmin(plan)) * ref.dt), 2),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("source", help="a per-tick run folder, or a reference (.npz)")
    ap.add_argument("--robot", default="hoap2")
    ap.add_argument("--controller", default="learned")
    ap.add_argument("--scale", type=float, default=0.3, help="with a reference")
    ap.add_argument("--robots", type=int, default=40)
    ap.add_argument("--first", type=int, default=300_000)
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--variants", default="friction,nokicks,eval")
    ap.add_argument("--fractions", default="0,1")
    ap.add_argument("--gains", default=None, help="with a reference: pitch=G,roll=G,heading=G")
    ap.add_argument("--sway", action="store_true", help="only how the body follows its sway")
    ap.add_argument("--wait", type=float, default=0.0, help="the phase wait's load share")
    args = ap.parse_args()
    robot = load_robot(args.robot)
    if args.source.endswith(".npz"):
        path, ref, scale = args.source, Reference.load(args.source), args.scale
        gains = dict(x.split("=") for x in args.gains.split(",")) if args.gains else None
        valid = [g.name for g in TRIAL_GAINS if not g.profiled]  # no nominal walk here
        if gains and set(gains) - set(valid):
            ap.error(f"--gains names one of {', '.join(valid)}; got {', '.join(gains)}")
        laws = (feedback_law(TickLearnConfig(), gains),) if gains else ()  # the learner's law
    else:
        run = load_run(args.source)
        path, ref, scale = run.path + "/reference.npz", run.ref, run.scale
        laws = () if args.controller == OPEN_LOOP else tuple(run.laws[args.controller])
    hard = load_protocol("hard")
    protos = {
        "friction": hard.only(("friction",)),
        "nokicks": hard.only(tuple(f for f in hard.factors if f != "pushes")),
        "hard": hard,
        "eval": load_protocol("eval"),
        "bullet": load_protocol("bullet"),
    }
    if args.sway:
        offsets = reference_offsets(ref, robot, scale, ref.loops.shape[1] * ref.dt)
        for text in args.fractions.split(","):
            out = sway_follow(ref, robot, scale, float(text) * offsets)
            print(json.dumps({"fraction": float(text), **out}))
        return
    offsets = walk_offsets(ref, robot, scale, args.seconds, 1.0)
    summary = {}
    for name in args.variants.split(","):
        engine = "mujoco" if name == "train" else protos[name].engine
        if name == "train":
            options = [perturbed(s, ref.sim_options()) for s in train_seeds(args.robots)]
        else:
            p = protos[name]
            options = [
                p.draw(args.first + s, robot, ref.sim_options(), args.seconds).options
                for s in range(args.robots)
            ]
        for text in args.fractions.split(","):
            off = float(text) * offsets
            jobs = [
                (path, args.robot, scale, laws, o, args.seconds, off, args.wait, engine)
                for o in options
            ]
            res = run_parallel(_walk, jobs)
            times = sorted(round(t, 2) for f, t, *_ in res if f)
            row = {
                "variant": name,
                "fraction": float(text),
                "falls": len(times),
                "fall_times_s": times,
                "distance_m": round(float(np.mean([r[2] for r in res])), 2),
                "offset_max_rad": round(float(np.abs(off).max()), 3),
            }
            summary[f"{name} {text}"] = len(times)
            print(json.dumps(row), flush=True)
    print(json.dumps({"source": args.source, "falls": summary}))


if __name__ == "__main__":
    main()
