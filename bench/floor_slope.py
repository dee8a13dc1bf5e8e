"""The floor's slope, estimated from the robot's own sensors, trimmed out at both ankles.

A prototype for issue 30's hard robots (sloped floors fell 24 of 40 alone). With its
feet flat on a floor of slope α the robot stands tilted by α: the torso's pitch to
gravity (the complementary filter's, from the gyro and accelerometer) differs from its
pitch to the stance sole (forward kinematics of the encoders) by the floor's pitch. Unlike
the torso's tilt alone, that difference does not see the body's own lean (a shifted
torso, a sagging servo): the encoders see those too. Its low-pass ``α̂`` (time constant
``--tau``, folded in while the soles carry weight) is turned into a change of both ankle
pitches that pitches the body by ``k · α̂`` against the floor, ``k`` a candidate for the
trials (1: upright on any floor). The run's learned laws stay as they are. The bench
walks each ``k`` on validation robots (seeds from 300 000) of the protocol's factors one at
a time, all but the kicks, the whole protocol and eval.

Usage: ``python bench/floor_slope.py RUN --gains 0,1 [--factors slope] [--robots 20]``;
prints JSON lines, one per (k, protocol variant).
"""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass

import mujoco
import numpy as np

from imitwalk.balance.feedback import TickPolicy
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.parallel import run_parallel
from imitwalk.robots import load_robot


def _pitch(rot: np.ndarray) -> float:
    """Pitch [rad] (about y, nose down +) of a ``(3, 3)`` rotation, ZYX angles."""
    return float(np.arcsin(np.clip(-rot[2, 0], -1.0, 1.0)))


class Kinematics:
    """The IMU's pitch to each sole from the encoders (the robot's model, base fixed)."""

    def __init__(self, robot):
        self.m = robot.compile()
        self.d = mujoco.MjData(self.m)
        self.d.qpos[:] = robot.stand_qpos
        jid = [self.m.joint(j).id for j in robot.mj_joints]
        self.qadr, self.sign = self.m.jnt_qposadr[jid], robot.signs
        s = self.m.sensor(robot.accelerometer)
        self.imu = int(s.objid[0])
        self.soles = [self.m.site(robot.soles[side]).id for side in "lr"]

    def rel_pitch(self, q: np.ndarray) -> np.ndarray:
        """``(2,)`` the IMU's pitch in the left and right sole's frame [rad]."""
        self.d.qpos[self.qadr] = q * self.sign
        mujoco.mj_kinematics(self.m, self.d)
        imu = self.d.site_xmat[self.imu].reshape(3, 3)
        return np.array([_pitch(self.d.site_xmat[s].reshape(3, 3).T @ imu) for s in self.soles])


class SlopePolicy(TickPolicy):
    """The run's laws plus both ankle pitches trimmed by ``k`` × the estimated slope."""

    def __init__(self, ref, scale, laws, robot, seconds, gain, tau):
        super().__init__(ref, scale, laws, robot.joint_names, seconds)
        self.kin, self.gain, self.tau = Kinematics(robot), gain, tau
        self.ix = robot.indices(("l_ankle_pitch", "r_ankle_pitch"))
        q = robot.stand.copy()
        base = self.kin.rel_pitch(q)
        q[self.ix] += 0.01
        self.per_rad = float(np.mean(self.kin.rel_pitch(q) - base) / 0.01)  # dθ/dq
        self.alpha, self.log = 0.0, []

    def __call__(self, k, obs):
        q = super().__call__(k, obs)
        f = np.asarray(obs.foot_force, float).sum(axis=1)  # (2,) [N]
        if f.sum() > 1e-3:
            w = f / f.sum()
            rel = float(w @ self.kin.rel_pitch(np.asarray(obs.joints, float)))
            floor = self.estimator.pitch - rel  # the stance sole's pitch to gravity
            dt = self.estimator.dt
            self.alpha += dt / (self.tau + dt) * (floor - self.alpha)
        self.log.append(self.alpha)
        # body pitched by -gain·α against the sole: upright when the floor pitches by α
        q[self.ix] += -self.gain * self.alpha / self.per_rad
        return q


@dataclass(frozen=True)
class Job:
    run_dir: str
    robot: object
    options: object
    seconds: float
    gain: float
    tau: float


def walk(job: Job):
    from imitwalk.sim.metrics import walk_metrics
    from imitwalk.sim.mujoco import make_plant, run

    r = load_run(job.run_dir)
    pol = SlopePolicy(r.ref, r.scale, tuple(r.laws["learned"]), job.robot, job.seconds,
                      job.gain, job.tau)  # fmt: skip
    plant = make_plant(job.robot, r.ref.sim_options(job.options), "mujoco")
    ro = run(plant, pol, len(pol.q_ref))
    m = walk_metrics(ro, r.ref.expected_distance(r.scale, ro.seconds), pol.q_ref,
                     r.ref.track(r.scale, ro.seconds))  # fmt: skip
    est = float(np.mean(pol.log[-300:])) if pol.log else 0.0
    return m.fell, m.fall_time_s, m.forward_distance_m, est, job.options.slope_deg


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir")
    ap.add_argument("--robot", default="hoap2")
    ap.add_argument("--gains", default="0,1", help="k candidates, comma-separated")
    ap.add_argument("--tau", type=float, default=1.0, help="the estimate's time constant [s]")
    ap.add_argument("--protocol", default="hard")
    ap.add_argument("--factors", default="slope")
    ap.add_argument("--robots", type=int, default=20)
    ap.add_argument("--first", type=int, default=300_000)
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--no-all", action="store_true", help="skip all-but-kicks and hard")
    args = ap.parse_args()
    r, robot = load_run(args.run_dir), load_robot(args.robot)
    proto = load_protocol(args.protocol)
    variants = [proto.only((f,)) for f in args.factors.split(",") if f]
    if not args.no_all:
        variants.append(proto.only(tuple(f for f in proto.factors if f != "pushes")))
        variants.append(proto)
    variants.append(load_protocol("eval"))
    for g in args.gains.split(","):
        for p in variants:
            draws = [p.draw(args.first + s, robot, r.ref.sim_options(), args.seconds)
                     for s in range(args.robots)]  # fmt: skip
            jobs = [Job(args.run_dir, robot, d.options, args.seconds, float(g), args.tau)
                    for d in draws]  # fmt: skip
            res = run_parallel(walk, jobs)
            falls = [round(float(t or 0), 1) for f, t, *_ in res if f]
            err = [np.rad2deg(e) + s for _, _, _, e, s in res]  # estimate vs slope [deg]
            print(json.dumps({"k": float(g), "tau": args.tau, "protocol": p.name,
                              "falls": len(falls), "fall_times_s": sorted(falls),
                              "distance_m": round(float(np.mean([d for _, _, d, _, _ in res])), 2),
                              "slope_err_deg": [round(float(e), 2) for e in err],
                              "slope_deg_fall_s": [(round(sl, 2), t if f else None)
                                                   for f, t, _, _, sl in res]}),
                  flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
