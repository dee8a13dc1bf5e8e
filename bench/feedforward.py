"""A lead, not a product option: the servos' sag taken out of the reference by inverse dynamics.

A position servo holds its joint only where its torque ``kp·(q_target − q) − kv·q̇`` is
what the motion needs, so a robot played its reference sags and lags: in single support
G1's stance hip roll carries about m·g·(half the stance width) ≈ 39 Nm, 4.5° at kp 500.
This bench adds to every joint target the offset ``(τ + kv·q̇_ref)/kp`` (Craig's
computed-torque feedforward, through a position servo), where ``τ`` is the joint torque
the reference needs on the *nominal* model (no sensor, no state of the simulation):

- the floating base is placed every tick so that the planned stance sole stays flat and
  still (its velocity from the sole's Jacobian, its acceleration by finite differences);
- ``mj_inverse`` gives the generalised forces of that motion, contacts off;
- the soles' wrenches are what the base's six rows need (one sole: solved; both:
  least norm weighted by each sole's share of the plan's load), and ``τ`` the rest.

``--fractions`` scale the offset (0: the reference as it is); ``--hold`` adds the phase
hold of ``bench/phase_hold.py``. The walk is the run's controller, or open loop on a
reference plus the learner's law with the gains of ``--gains pitch=G,roll=G,heading=G``
(a missing one is 0), on training robots
(variant ``train``) or validation robots of hard's variants, eval's and bullet's (on
Bullet). Prints
one JSON line per (variant, fraction): falls, their times, the mean distance [m] (ground
truth, for the figure only) and the largest offset [rad]. With ``--sway``, instead, how
the nominal robot's centre of mass follows the plan's sway in the first cycle.

Usage: ``python bench/feedforward.py REF.npz --robot g1.json --scale 0.3 --robots 4
--seconds 10 --variants train --fractions 0,0.5,1 [--gains pitch=0.05]``,
or ``python bench/feedforward.py RUN --variants friction,nokicks,eval``, or ``... --sway``.
"""

from __future__ import annotations

import argparse
import json

import mujoco
import numpy as np
from scipy.ndimage import gaussian_filter1d

from imitwalk.balance.feedback import TickPolicy
from imitwalk.balance.tickconfig import TickLearnConfig
from imitwalk.balance.tickstore import TRIAL_GAINS, feedback_law
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import OPEN_LOOP, load_run
from imitwalk.parallel import run_parallel
from imitwalk.retarget import Reference
from imitwalk.robots import load_robot
from imitwalk.sim.perturb import perturbed, train_seeds

#: Accelerations are smoothed over this many ticks (σ), offsets clipped to this [rad].
SMOOTH, CLIP = 2.0, 0.2


def servo_offsets(robot, q_ref: np.ndarray, stance: np.ndarray, share: np.ndarray, dt: float):
    """``(T, n)`` target offsets [rad] so the nominal servos give the reference's torques.

    Args:
        robot: the robot; q_ref: ``(T, n)`` canonical joint targets [rad]; stance:
            ``(T, 2)`` planned feet down (left, right); share: ``(T,)`` the left sole's
            share of the load; dt: the control period [s].
    """
    m = robot.compile()
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    d = mujoco.MjData(m)
    jid = [m.joint(j).id for j in robot.mj_joints]
    qadr, dadr = m.jnt_qposadr[jid], m.jnt_dofadr[jid]
    kp, kv = np.zeros(len(jid)), np.zeros(len(jid))
    for a in range(m.nu):
        if m.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT and m.actuator_trnid[a, 0] in jid:
            i = jid.index(m.actuator_trnid[a, 0])
            kp[i], kv[i] = m.actuator_gainprm[a, 0], -m.actuator_biasprm[a, 2]
    soles = [m.site(robot.soles[s]).id for s in ("l", "r")]
    T, nv = len(q_ref), m.nv
    qdot = np.gradient(q_ref * robot.signs, dt, axis=0)  # (T, n) mj joint rates [rad/s]
    qpos, qvel = np.zeros((T, m.nq)), np.zeros((T, nv))
    jacs = np.zeros((T, 2, 6, nv))  # each sole's Jacobian, position rows then rotation
    for t in range(T):
        st = soles[0] if share[t] >= 0.5 else soles[1]
        d.qpos[:] = robot.stand_qpos
        d.qpos[:3], d.qpos[3:7] = (0.0, 0.0, 5.0), (1, 0, 0, 0)
        d.qpos[qadr] = q_ref[t] * robot.signs
        mujoco.mj_kinematics(m, d)
        quat = np.zeros(4)  # the base turned so the stance sole is level (and faces +x)
        mujoco.mju_mat2Quat(quat, d.site_xmat[st].reshape(3, 3).T.copy().ravel())
        d.qpos[3:7] = quat
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        for j, s in enumerate(soles):
            mujoco.mj_jacSite(m, d, jacs[t, j, :3], jacs[t, j, 3:], s)
        # the soles planned down stay still (least squares with both down)
        J = np.vstack([jacs[t, j] for j, s in enumerate(soles) if stance[t, j] or s == st])
        qvel[t, dadr] = qdot[t]
        qvel[t, :6] = np.linalg.lstsq(J[:, :6], -J[:, dadr] @ qdot[t], rcond=None)[0]
        qpos[t] = d.qpos
    qacc = gaussian_filter1d(np.gradient(qvel, dt, axis=0), SMOOTH, axis=0, mode="nearest")
    out = np.zeros_like(q_ref)
    for t in range(T):
        d.qpos[:], d.qvel[:], d.qacc[:] = qpos[t], qvel[t], qacc[t]
        mujoco.mj_inverse(m, d)
        b, J = d.qfrc_inverse.copy(), jacs[t].reshape(12, nv)
        w = np.array([share[t], 1.0 - share[t]]) * stance[t] + 1e-6
        A = J[:, :6].T  # (6, 12): the base's rows of Jᵀ
        Winv = np.repeat(w, 6)
        f = Winv * (A.T @ np.linalg.solve((A * Winv) @ A.T, b[:6]))
        tau = b[dadr] - (J.T @ f)[dadr]
        out[t] = (tau + kv * qvel[t, dadr]) / np.where(kp > 0, kp, np.inf) * robot.signs
    return np.clip(out, -CLIP, CLIP)


def plan_load(ref: Reference, scale: float, T: int) -> tuple[np.ndarray, np.ndarray]:
    """``(T, 2)`` planned feet down and ``(T,)`` the left sole's share of the load."""
    plan = ref.plan_at(scale)
    rows = ref.loop_index(np.arange(T))[0]
    down = np.stack([plan["l_sole"][rows, 2], plan["r_sole"][rows, 2]], 1) <= 1e-4
    yl, yr, yc = plan["l_sole"][rows, 1], plan["r_sole"][rows, 1], plan["com"][rows, 1]
    share = np.clip((yc - yr) / np.maximum(yl - yr, 1e-6), 0.0, 1.0)
    share = np.where(down[:, 0] & ~down[:, 1], 1.0, np.where(down[:, 1] & ~down[:, 0], 0.0, share))
    return down, share


def reference_offsets(ref: Reference, robot, scale: float, seconds: float) -> np.ndarray:
    """``(T, n)`` :func:`servo_offsets` of the reference at ``scale`` for ``2 × seconds``
    (the ticks a :class:`FeedforwardPolicy` may reach while its phase holds)."""
    q = ref.trajectory(scale, 2 * seconds)
    down, share = plan_load(ref, scale, len(q))
    return servo_offsets(robot, q, down, share, ref.dt)


class FeedforwardPolicy:
    """A run's :class:`TickPolicy` with ``offsets`` ``(T, n)`` [rad] added to its targets
    (``T`` the ticks of ``2 × seconds``) and the optional phase hold."""

    def __init__(self, ref, scale, laws, robot, seconds, offsets, hold=(1.0, 0.0)):
        self.inner = TickPolicy(ref, scale, laws, robot.joint_names, 2 * seconds)
        self.down = plan_load(ref, scale, len(self.inner.q_ref))[0]
        self.inner.q_ref = self.inner.q_ref + offsets
        self.hold, self.max_hold = hold[0], round(hold[1] / ref.dt)
        self.i = self.held = 0

    @property
    def q0(self) -> np.ndarray:
        return self.inner.q0

    def __call__(self, k: int, obs) -> np.ndarray:
        """The phase hold of ``bench/phase_hold.py``: before a planned lift-off the
        reference waits while the lifting sole carries more than ``hold[0]`` of the load
        (at most ``hold[1]`` s)."""
        if k:
            load = obs.foot_force.sum(axis=1)
            share = load / max(float(load.sum()), 1e-9)
            j = min(self.i, len(self.down) - 2)
            lifting = self.down[j] & ~self.down[j + 1]
            if np.any(lifting & (share > self.hold)) and self.held < self.max_hold:
                self.held += 1
            else:
                self.held, self.i = 0, self.i + 1
        return self.inner(self.i, obs)


def _walk(job) -> tuple[bool, float | None, float, float]:
    path, robot_name, scale, laws, options, seconds, offsets, hold, engine = job
    from imitwalk.sim.mujoco import make_plant, run

    ref, robot = Reference.load(path), load_robot(robot_name)
    policy = FeedforwardPolicy(ref, scale, laws, robot, seconds, offsets, hold)
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
    policy = FeedforwardPolicy(ref, scale, (), robot, n * ref.dt, offsets[: 2 * n])
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
    ap.add_argument("--hold", default="1,0", help="phase hold threshold,max seconds (1,0: none)")
    args = ap.parse_args()
    robot = load_robot(args.robot)
    hold = tuple(float(x) for x in args.hold.split(","))
    if args.source.endswith(".npz"):
        path, ref, scale = args.source, Reference.load(args.source), args.scale
        gains = dict(x.split("=") for x in args.gains.split(",")) if args.gains else None
        valid = [name for name, *_ in TRIAL_GAINS]
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
    offsets = reference_offsets(ref, robot, scale, args.seconds)  # at fraction 1
    summary = {}
    for name in args.variants.split(","):
        engine = "mujoco" if name == "train" else protos[name].engine
        if name == "train":
            options = [perturbed(s, ref.sim_options()) for s in train_seeds(args.robots)]
        else:
            p = protos[name]
            options = [p.draw(args.first + s, robot, ref.sim_options(), args.seconds).options
                       for s in range(args.robots)]  # fmt: skip
        for text in args.fractions.split(","):
            off = float(text) * offsets
            jobs = [(path, args.robot, scale, laws, o, args.seconds, off, hold, engine)
                    for o in options]  # fmt: skip
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
