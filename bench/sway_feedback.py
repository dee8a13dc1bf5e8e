"""A lead, not a product option: the sideways sway closed on what the robot measures.

On G1 this law made the body follow its first weight shift (docs/RESULTS.md, "Other
robots"). hoap2's grippy-floor start-up falls look alike: the start-up rocks the robot onto
one sole's edge before the plan lifts a foot (docs/RESULTS.md, "The hard robots"). This
bench adds the law to a run's controller and walks validation robots of protocol
variants (seeds from ``--first``; neither training nor evaluation robots):

- **Measured:** the centre of mass relative to the middle of the soles, from forward
  kinematics of the *encoders* on the nominal model, turned into the gravity frame by
  the torso's tilt from a complementary filter (gyro + accelerometer, τ 2 s); its planned
  value is the same on the reference's posture, feet flat. ``e`` [m] is measured −
  planned, sideways, and ``ė`` [m/s] its first difference low-passed over 30 ms.
- **Action:** ``Δ = kp·e + kd·ė`` [m], clipped to ±``--clip``, moves the pelvis sideways
  over the soles on both hip and ankle rolls (torso and soles keep their tilt; a Jacobian
  solved once on the first posture). With ``--double-only`` it acts only while the plan
  has both feet down, with ``--startup-only`` only in the reference's start-up.
- **Clock:** with ``K`` > 0 the reference's clock is coupled to the body's measured
  sideways oscillation (eq. 9's phase advance driven by the sensors, as Morimoto et al.,
  ICRA 2006, couple a sinusoidal pattern to the measured centre of pressure). The phases
  are φ = atan2(−ẏ/ω, y) of the measured and the planned sideways centre of mass (ω the
  gait's angular frequency), and the clock runs at ``1 + (K/ω)·sin(φ_meas − φ_plan)``
  (never backwards): it waits for a body that lags and hurries after one that leads.
  ``--lag`` [rad] is subtracted from that phase difference (the body's nominal lag; each
  row prints the mean lag measured in the steady loop).

A law is ``kp,kd,K``. With a reference (``.npz``) instead of a run, the reference is
walked open loop at ``--scale`` on training robots (variant ``train``). Prints one JSON
line per (variant, law): falls, their times, the mean distance [m] (ground truth, for the
figure only) and the least reference time reached [s]; then a summary.

Usage: ``python bench/sway_feedback.py RUN [--controller learned] [--robots 40]
[--first 300000] [--seconds 30] [--variants friction,nokicks,hard,eval]
[--laws '0,0,0;-1,-0.1,0;0,0,2'] [--double-only] [--startup-only]``, or ``python
bench/sway_feedback.py REF.npz --robot g1.json --scale 0.3 --robots 4 --seconds 10
--variants train --clip 0.04 --laws ...``.
"""

from __future__ import annotations

import argparse
import json

import mujoco
import numpy as np

from imitwalk.balance.estimator import StateEstimator
from imitwalk.balance.feedback import TickPolicy
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import OPEN_LOOP, load_run
from imitwalk.parallel import run_parallel
from imitwalk.retarget import Reference
from imitwalk.robots import load_robot
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

    def pose(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Centre of mass less the soles' middle [m], torso and left-sole rotations."""
        m, d = self.m, self.d
        d.qpos[:] = self.r.stand_qpos
        d.qpos[:3], d.qpos[3:7] = 0.0, (1, 0, 0, 0)
        d.qpos[self.qadr] = q * self.r.signs
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        com = d.subtree_com[0] - d.site_xpos[self.soles].mean(axis=0)
        return (
            com,
            d.xmat[self.torso].reshape(3, 3).copy(),
            d.site_xmat[self.soles[0]].reshape(3, 3).copy(),
        )

    def features(self, q: np.ndarray) -> np.ndarray:
        """(com_y, right sole roll, torso roll), in the left sole's frame."""
        com, tor, left = self.pose(q)
        right = left.T @ self.d.site_xmat[self.soles[1]].reshape(3, 3)
        tor = left.T @ tor
        return np.array(
            [
                (left.T @ com)[1],
                np.arctan2(right[2, 1], right[2, 2]),
                np.arctan2(tor[2, 1], tor[2, 2]),
            ]
        )

    def shift_direction(self, q0: np.ndarray) -> np.ndarray:
        """``(n,)`` joint change per metre of sideways pelvis shift [rad/m] (least norm)."""
        idx = [self.r.joint_names.index(j) for j in ROLLS]
        f0, J = self.features(q0), np.zeros((3, 4))
        for i, j in enumerate(idx):
            dq = q0.copy()
            dq[j] += 1e-4
            J[:, i] = (self.features(dq) - f0) / 1e-4
        out = np.zeros(len(q0))
        out[idx] = np.linalg.lstsq(J, np.array([1.0, 0.0, 0.0]), rcond=None)[0]
        return out


def _rot(roll: float, pitch: float) -> np.ndarray:
    cr, sr, cp, sp = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch)
    return np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]]) @ np.array(
        [[1, 0, 0], [0, cr, -sr], [0, sr, cr]]
    )


class SwayPolicy:
    """A run's :class:`TickPolicy` plus the sideways law and the coupled clock."""

    def __init__(
        self, ref, scale, laws, robot, seconds, law, clip, double_only, startup_only, lag=0.0
    ):
        self.inner = TickPolicy(ref, scale, laws, robot.joint_names, 2 * seconds)
        self.kin, (self.kp, self.kd, self.K), self.clip = Kinematics(robot), law, clip
        self.u = self.kin.shift_direction(self.inner.q0)
        self.est = StateEstimator(ref.dt, tau=2.0)
        self.a, self.dt = ref.dt / (ref.dt + 0.03), ref.dt
        self.w = 2 * np.pi / (ref.loops.shape[1] * ref.dt)  # gait frequency [rad/s]
        y = []
        for q in self.inner.q_ref:
            com, _, left = self.kin.pose(q)
            y.append((left.T @ com)[1])
        self.y_plan = np.array(y)  # (T,) planned sideways centre of mass [m]
        self.z_plan = np.stack([self.y_plan, -np.gradient(self.y_plan, ref.dt) / self.w], 1)
        plan = ref.plan_at(scale)
        self.lifted = (np.stack([plan["l_sole"][:, 2], plan["r_sole"][:, 2]], 1) > 1e-4).any(1)
        self.double_only, self.startup_only = double_only, startup_only
        self.y_prev: float | None = None
        self.lag, self.lags = lag, []
        self.e_prev = self.rate = self.e_rate = self.clock = 0.0

    @property
    def q0(self) -> np.ndarray:
        return self.inner.q0

    def __call__(self, k: int, obs) -> np.ndarray:
        s = self.est.update(obs.gyro, obs.accel, obs.foot_force)
        com, tor, _ = self.kin.pose(obs.joints)
        y = float((_rot(s.roll, s.pitch) @ tor.T @ com)[1])
        self.y_prev = y if self.y_prev is None else self.y_prev
        self.rate = (1 - self.a) * self.rate + self.a * (y - self.y_prev) / self.dt
        self.y_prev = y
        i = min(int(self.clock + 1e-9), len(self.y_plan) - 1)  # the reference's tick
        zr, zc = np.array([y, -self.rate / self.w]), self.z_plan[i]
        cross, dot = zc[0] * zr[1] - zc[1] * zr[0], zc[0] * zr[0] + zc[1] * zr[1]
        if i >= self.inner.start:  # the steady loop: the body's phase less the plan's
            self.lags.append(np.arctan2(cross, dot))
        c, sl = np.cos(self.lag), np.sin(self.lag)  # less the nominal lag
        sin = (c * cross - sl * dot) / (np.linalg.norm(zc) * np.linalg.norm(zr) + 1e-4)
        self.clock += max(0.0, 1.0 + self.K / self.w * sin)
        q = self.inner(i, obs)
        e = y - float(self.y_plan[i])
        self.e_rate = (1 - self.a) * self.e_rate + self.a * (e - self.e_prev) / self.dt
        self.e_prev = e
        n0, nl = self.inner.start, self.inner.n_loop
        if self.startup_only and i >= n0:
            return q
        if self.double_only:
            j = i if i < n0 else n0 + (i - n0) % nl
            if self.lifted[min(j, len(self.lifted) - 1)]:
                return q
        return (
            q + float(np.clip(self.kp * e + self.kd * self.e_rate, -self.clip, self.clip)) * self.u
        )


def _walk(job) -> tuple[bool, float | None, float, float, float]:
    path, robot_name, scale, laws, options, seconds, law, clip, double_only, startup_only, lag = job
    from imitwalk.sim.mujoco import make_plant, run

    ref, robot = Reference.load(path), load_robot(robot_name)
    policy = SwayPolicy(ref, scale, laws, robot, seconds, law, clip, double_only, startup_only, lag)
    ro = run(make_plant(robot, ref.sim_options(options)), policy, round(seconds / ref.dt))
    distance = float(ro.torso_pos[-1, 0] - ro.torso_pos[0, 0]) if len(ro.t) else 0.0
    lag = float(np.angle(np.mean(np.exp(1j * np.array(policy.lags))))) if policy.lags else 0.0
    return bool(ro.fell), ro.fall_time, distance, policy.clock * ref.dt, lag


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
    ap.add_argument("--laws", default="0,0,0;-1,-0.1,0", help="kp,kd,K triples, ';'-separated")
    ap.add_argument("--clip", type=float, default=0.02, help="largest shift [m]")
    ap.add_argument("--double-only", action="store_true")
    ap.add_argument("--startup-only", action="store_true", help="act in the start-up alone")
    ap.add_argument("--lag", type=float, default=0.0, help="the body's nominal phase lag [rad]")
    args = ap.parse_args()
    robot = load_robot(args.robot)
    if args.source.endswith(".npz"):
        path, ref, scale, laws = args.source, Reference.load(args.source), args.scale, ()
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
    }
    summary = {}
    for name in args.variants.split(","):
        if name == "train":
            options = [perturbed(s, ref.sim_options()) for s in train_seeds(args.robots)]
        else:
            p = protos[name]
            options = [p.draw(args.first + s, robot, ref.sim_options(), args.seconds).options
                       for s in range(args.robots)]  # fmt: skip
        for text in args.laws.split(";"):
            law = tuple(float(x) for x in text.split(","))
            jobs = [(path, args.robot, scale, laws, o, args.seconds, law, args.clip,
                     args.double_only, args.startup_only, args.lag) for o in options]  # fmt: skip
            res = run_parallel(_walk, jobs)
            times = sorted(round(t, 2) for f, t, *_ in res if f)
            row = {
                "variant": name,
                "law": dict(zip(("kp", "kd", "K"), law, strict=True)),
                "falls": len(times),
                "fall_times_s": times,
                "distance_m": round(float(np.mean([r[2] for r in res])), 2),
                "least_reference_s": round(min(r[3] for r in res), 2),
                "mean_lag_rad": round(
                    float(np.angle(np.mean(np.exp(1j * np.array([r[4] for r in res]))))), 3
                ),
            }
            summary[f"{name} {text}"] = len(times)
            print(json.dumps(row), flush=True)
    print(json.dumps({"source": args.source, "clip_m": args.clip, "double_only": args.double_only,
                      "startup_only": args.startup_only, "falls": summary}))  # fmt: skip


if __name__ == "__main__":
    main()
