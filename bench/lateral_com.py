"""A lead, not a product option: G1's sideways motion closed on what it measures.

G1 falls sideways in the start-up: its body sways about twice the plan, lags it, and tips
over a sole's edge (docs/RESULTS.md, "Other robots"). This bench closes the sideways
centre of mass on the robot's own sensors, every tick, on training robots only:

- **Measured:** the centre of mass relative to the middle of the soles, from forward
  kinematics of the *encoders* on the nominal model (no simulator state), turned into the
  gravity frame by the torso's tilt from the complementary filter (gyro + accelerometer,
  tau 2 s).
  Its planned value is the same computation on the reference's posture, feet flat. The
  error ``e`` [m] (measured − planned, sideways) and its rate ``ė`` [m/s] (first
  difference, low-passed over 30 ms) are all the law reads.
- **Action:** ``Δ = kp·e + kd·ė`` [m], clipped to ±4 cm, applied through a Jacobian solved
  once at the first posture: ``shift`` moves the pelvis sideways over the soles with both
  hip and ankle rolls (torso and soles keep their tilt, the soles their heights);
  ``tilt`` rolls the torso by ``Δ / torso height`` [rad] on the hip rolls alone (the hip
  strategy).
- Optionally the phase hold of ``bench/phase_hold.py`` (``--hold 0.3,0.5``), and a swing
  foot placed sideways by ``fp·e + fd·ė`` [m], clipped to ±8 cm, on the swing leg's hip
  roll while the plan has that foot up (``--place fp,fd``).

Prints, per (mode, kp, kd), each robot's fall time (``null``: up for ``--seconds``) and how
far into the reference it got [s].

Usage: ``python bench/lateral_com.py REF.npz --robot g1.json [--scale 0.3] [--robots 4]
[--seconds 10] [--mode shift] [--kp 0,-0.5,-1] [--kd 0,-0.1] [--hold 1,0] [--place 0,0]``;
prints JSON.
"""

from __future__ import annotations

import argparse
import itertools
import json

import mujoco
import numpy as np

from imitwalk.balance.estimator import StateEstimator
from imitwalk.parallel import run_parallel
from imitwalk.retarget import Reference
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import MujocoPlant
from imitwalk.sim.perturb import perturbed, train_seeds

ROLLS = ("l_hip_roll", "r_hip_roll", "l_ankle_roll", "r_ankle_roll")


class Kinematics:
    """Forward kinematics of the nominal model from canonical joint angles."""

    def __init__(self, robot):
        self.r, self.m = robot, robot.compile()
        self.d = mujoco.MjData(self.m)
        self.qadr = self.m.jnt_qposadr[[self.m.joint(j).id for j in robot.mj_joints]]
        self.torso = self.m.body(robot.torso).id
        self.soles = [self.m.site(robot.soles[s]).id for s in ("l", "r")]

    def pose(self, q: np.ndarray) -> dict:
        m, d = self.m, self.d
        d.qpos[:] = self.r.stand_qpos
        d.qpos[:3], d.qpos[3:7] = 0.0, (1, 0, 0, 0)
        d.qpos[self.qadr] = q * self.r.signs
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        mid = d.site_xpos[self.soles].mean(axis=0)
        return {
            "com": d.subtree_com[0] - mid,  # base frame [m]
            "torso": d.xmat[self.torso].reshape(3, 3).copy(),
            "soles": [d.site_xmat[s].reshape(3, 3).copy() for s in self.soles],
            "sole_z": d.site_xpos[self.soles][:, 2].copy(),
        }


def _rot(roll: float, pitch: float) -> np.ndarray:
    cr, sr, cp, sp = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    return ry @ rx


def _features(kin: Kinematics, q: np.ndarray, idx: list[int]) -> np.ndarray:
    """(com_y, 0, right sole roll, sole height gap, torso roll), in the left sole's frame."""
    p = kin.pose(q)
    base = p["soles"][0]  # frame of the left sole
    com = base.T @ p["com"]
    rel = [base.T @ s for s in p["soles"]]
    tor = base.T @ p["torso"]
    right_roll = np.arctan2(rel[1][2, 1], rel[1][2, 2])
    torso_roll = np.arctan2(tor[2, 1], tor[2, 2])
    return np.array([com[1], 0.0, right_roll, p["sole_z"][0] - p["sole_z"][1], torso_roll])


def action_direction(kin: Kinematics, q0: np.ndarray, mode: str) -> np.ndarray:
    """``(n,)`` joint change per metre of commanded sideways shift [rad/m]."""
    idx = [kin.r.joint_names.index(j) for j in ROLLS]
    eps, f0 = 1e-4, _features(kin, q0, idx)
    J = np.zeros((5, 4))
    for i, j in enumerate(idx):
        dq = q0.copy()
        dq[j] += eps
        J[:, i] = (_features(kin, dq, idx) - f0) / eps
    out = np.zeros(len(q0))
    if mode == "shift":  # com_y = 1 m, right sole and torso keep their roll (least norm)
        rows, rhs, cols = [0, 2, 4], np.array([1.0, 0, 0]), [0, 1, 2, 3]
    else:  # torso rolls 1/h rad on the hip rolls, the soles keep their relative roll
        h = float(np.linalg.norm(kin.pose(q0)["com"]))
        rows, rhs, cols = [4, 2], np.array([1.0 / h, 0]), [0, 1]
    x = np.linalg.lstsq(J[np.ix_(rows, cols)], rhs, rcond=None)[0]
    out[[idx[c] for c in cols]] = x
    return out


def _foot_gain(kin: Kinematics, q0: np.ndarray, side: int, j: int) -> float:
    """How far a sole moves sideways per radian of its hip roll [m/rad]."""

    def foot_y(q: np.ndarray) -> float:
        kin.pose(q)
        return float(kin.d.site_xpos[kin.soles[side]][1])

    dq = q0.copy()
    dq[j] += 1e-4
    return (foot_y(dq) - foot_y(q0)) / 1e-4


def _walk(job) -> dict:
    path, robot_name, scale, seconds, seed, mode, kp, kd, hold, place = job
    ref, robot = Reference.load(path), load_robot(robot_name)
    kin = Kinematics(robot)
    q = ref.trajectory(scale, 2 * seconds)
    plan = ref.plan_at(scale)
    lifted = np.stack([plan["l_sole"][:, 2], plan["r_sole"][:, 2]], axis=1) > 1e-4
    n0, nl = ref.starts.shape[1], ref.loops.shape[1]

    def up(k: int) -> np.ndarray:
        return lifted[min(k if k < n0 else n0 + (k - n0) % nl, len(lifted) - 1)]

    u = action_direction(kin, q[0], mode)
    hl, hr = robot.joint_names.index("l_hip_roll"), robot.joint_names.index("r_hip_roll")
    cl, cr = (_foot_gain(kin, q[0], side, j) for side, j in ((0, hl), (1, hr)))
    plant = MujocoPlant(robot, perturbed(seed, ref.sim_options()))
    obs = plant.reset(q[0])
    est = StateEstimator(ref.dt, tau=2.0)  # the sway's accelerations bias the accelerometer
    k = held = 0
    e_prev = rate = 0.0
    a = ref.dt / (ref.dt + 0.03)
    for _ in range(round(seconds / ref.dt)):
        s = est.update(obs.gyro, obs.accel, obs.foot_force)
        load = obs.foot_force.sum(axis=1)
        share = load / max(float(load.sum()), 1e-9)
        lifting = up(k + 1) & ~up(k)
        if np.any(lifting & (share > hold[0])) and held < hold[1] / ref.dt:
            held += 1
        else:
            held, k = 0, k + 1
        target = q[min(k, len(q) - 1)].copy()
        pm, pp = kin.pose(obs.joints), kin.pose(target)
        meas = _rot(s.roll, s.pitch) @ pm["torso"].T @ pm["com"]
        want = pp["soles"][0].T @ pp["com"]
        e = float(meas[1] - want[1])
        rate = (1 - a) * rate + a * (e - e_prev) / ref.dt
        e_prev = e
        shift = float(np.clip(kp * e + kd * rate, -0.04, 0.04))
        cmd = target + shift * u
        foot = float(np.clip(place[0] * e + place[1] * rate, -0.08, 0.08))
        for side, j, c in ((0, hl, cl), (1, hr, cr)):
            if up(k)[side]:
                cmd[j] += foot / c
        plant.command(cmd)
        obs = plant.step()
        if plant.fell:
            break
    return {"seed": seed, "fall_time_s": plant.fall_time, "reached_s": round(k * ref.dt, 2)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("reference")
    ap.add_argument("--robot", default=None)
    ap.add_argument("--scale", type=float, default=0.3)
    ap.add_argument("--robots", type=int, default=4)
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--mode", default="shift", choices=("shift", "tilt"))
    ap.add_argument("--kp", default="0,-0.5,-1", help="gains [m per m], comma-separated")
    ap.add_argument("--kd", default="0", help="gains [m per m/s], comma-separated")
    ap.add_argument("--hold", default="1,0", help="phase hold threshold,max_hold (1,0: none)")
    ap.add_argument("--place", default="0,0", help="swing foot placement fp,fd (0,0: none)")
    args = ap.parse_args()
    ref = Reference.load(args.reference)
    robot = args.robot or ref.settings.get("robot") or "hoap2"
    hold = tuple(float(x) for x in args.hold.split(","))
    seeds = train_seeds(args.robots)
    grid = list(itertools.product([float(x) for x in args.kp.split(",")],
                                  [float(x) for x in args.kd.split(",")]))  # fmt: skip
    place = tuple(float(x) for x in args.place.split(","))
    jobs = [(args.reference, robot, args.scale, args.seconds, s, args.mode, kp, kd, hold, place)
            for kp, kd in grid for s in seeds]  # fmt: skip
    res = run_parallel(_walk, jobs)
    n = len(seeds)
    out = {
        "scale": args.scale,
        "mode": args.mode,
        "hold": hold,
        "place": place,
        "laws": [
            {"kp": kp, "kd": kd, "robots": res[i * n : (i + 1) * n]}
            for i, (kp, kd) in enumerate(grid)
        ],
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
