"""The stepping gait: footsteps, their timing and the body's path re-planned every tick.

:class:`SteppingController` is a policy ``(tick, observation) -> joint targets`` that
walks a :class:`~imitwalk.step.style.GaitStyle` on its robot from the robot's own
sensors. Every control tick:

1. **Estimate** (:mod:`imitwalk.step.estimator`): the centre of mass, its velocity and
   the DCM ``ξ``, the swing sole and the centre of pressure, in the stance frame.
2. **Plan the step** (:mod:`imitwalk.step.planner`): where the swing foot lands and
   when, from the measured DCM (step location and timing adaptation).
3. **Plan the body**: the DCM reference ``ξ_ref`` runs backward from the chosen
   touchdown along the stance foot's ZMP plan (heel to toe); the desired ZMP is
   ``p = p_plan + k (ξ − ξ_ref)``, kept within the support (the ankles' share of the
   balance, Englsberger et al. 2015, eq. 11); the commanded centre of mass follows the
   pendulum under that ZMP (:func:`~imitwalk.step.lipm.lipm_step`), pulled towards the
   measured one by ``follow`` and commanded ``lead`` seconds ahead for the servos' lag.
4. **Swing the foot** along the style's path shape, re-aimed every tick at the landing
   chosen (the remaining fraction of the way), and set it down when its sole feels the
   floor (or lower it further when the floor is late).
5. **Solve the joints** (:class:`~imitwalk.step.kinematics.BodyModel`): both soles and
   the pelvis (its height from the style, level, turned with the feet), the arms and
   waist from the style's phase profiles; optionally the servos' static sag added.

Nothing here reads the simulator: only the :class:`~imitwalk.sim.types.Observation`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.robots import Robot
from imitwalk.step.estimator import BodyEstimate, BodyEstimator
from imitwalk.step.gains import StepGains
from imitwalk.step.kinematics import BodyModel, FootPose, rot_xyz, rot_z
from imitwalk.step.lipm import GRAVITY, NominalGait, dcm_before, lipm_step, omega_of
from imitwalk.step.planner import StepLimits, StepWeights, plan_step
from imitwalk.step.style import GaitStyle

import os
_NOPLAN = bool(os.environ.get("NOPLAN"))
_DEBUG = bool(os.environ.get("STEPDEBUG"))
__all__ = ["START_STEPS", "SteppingController", "TickLog"]

#: Steps over which the stride grows from nothing to the style's.
START_STEPS = 3
#: Settling from the standing posture to the walking one, and shifting the weight
#: onto the first stance foot, in step times.
SETTLE, SHIFT = 0.6, 1.0
#: A swing foot has landed when its sole carries this share of the robot's weight.
TOUCHDOWN_LOAD = 0.2
#: A late floor: the swing foot keeps descending for at most this share of a step.
LATE = 0.3


@dataclass(frozen=True)
class TickLog:
    """One tick of the controller, for plots and tests.

    Attributes:
        t: time [s]; stance: ``"l"``/``"r"``; single: single support; step: steps
        taken; dcm, dcm_ref, zmp, com_cmd: ``(2,)`` in the stance frame [m];
        landing: ``(2,)`` the planned touchdown [m]; ss: the planned single support [s].
    """

    t: float
    stance: str
    single: bool
    step: int
    dcm: np.ndarray
    dcm_ref: np.ndarray
    zmp: np.ndarray
    com_cmd: np.ndarray
    landing: np.ndarray
    ss: float


def _profile(p: np.ndarray, s: float) -> float:
    return float(np.interp(s, np.linspace(0.0, 1.0, len(p)), p))


def _smooth(x: float) -> float:
    x = min(max(x, 0.0), 1.0)
    return x * x * x * (x * (6.0 * x - 15.0) + 10.0)


class SteppingController:
    """A walking policy for ``robot`` (see the module doc).

    Args:
        robot: the robot; style: the walk to imitate; gains: the learned gains;
        dt: control period [s]; turn_deg: heading change per step commanded [deg];
        log: keep a :class:`TickLog` per tick (``self.ticks``).
    """

    def __init__(
        self,
        robot: Robot,
        style: GaitStyle,
        gains: StepGains,
        dt: float,
        turn_deg: float = 0.0,
        log: bool = False,
    ):
        self.robot, self.style, self.gains, self.dt = robot, style, gains, dt
        self.turn = np.radians(turn_deg)
        self.q0 = robot.stand.copy()
        self.fk = BodyModel(robot)
        self.ik = BodyModel(robot)
        geom = style.geometry
        self.half = np.array([geom.foot_length, geom.foot_width]) / 2
        self.pelvis_z = style.pelvis_height - gains.crouch * geom.leg
        self.kp = robot.kp.copy()
        self.ankle_zmp = np.zeros(2)
        self._upper_roles = {r: robot.index(r) for r in style.upper if r in robot.joint_names}
        # the walking posture: feet under the hips, the pelvis at its walking height
        z_c = self._walking_com_height()
        self.omega = omega_of(z_c)
        self.limits = self._limits()
        self.weights = StepWeights(
            10.0**gains.step_weight, 1.0, 10.0**gains.time_weight, 10.0**gains.zmp_weight
        )
        self._gaits: dict[int, NominalGait] = {}
        self._offsets: dict[tuple[int, float], np.ndarray] = {}
        self.log, self.ticks = log, []
        self._started = False

    # -- set-up -------------------------------------------------------------------
    def _walking_com_height(self) -> float:
        st = self.style
        feet = {
            "l": FootPose(np.array([0.0, st.step_width / 2, -self.pelvis_z]), 0.0),
            "r": FootPose(np.array([0.0, -st.step_width / 2, -self.pelvis_z]), 0.0),
        }
        q = self.q0.copy()
        for _ in range(5):
            q = self.ik.solve_legs(q, feet, np.eye(3), iterations=4)
        self.ik.set(q)
        return float(self.ik.com()[2] + self.pelvis_z)

    def _limits(self) -> StepLimits:
        st, g, geom = self.style, self.gains, self.style.geometry
        hip = self.pelvis_z - geom.hip_z - geom.ankle
        reach = geom.leg * 0.99
        far = 2 * np.sqrt(max(reach**2 - hip**2, 0.0))  # both legs reaching, hips midway
        return StepLimits(
            forward=max(far, st.step_length),
            backward=0.5 * far,
            inner=geom.foot_width + 0.1 * geom.foot_width,
            outer=st.step_width + 0.4 * geom.leg,
            ss_min=g.ss_min * st.single_support,
            ss_max=1.5 * st.single_support,
            swing_speed=4.0 * max(st.step_length, st.step_width) / st.single_support + 0.2,
        )

    def gait(self, step: int) -> NominalGait:
        """The nominal walk the planner aims step ``step`` (counted from 1) at: the
        stride grows over :data:`START_STEPS` steps."""
        k = min(step, START_STEPS)
        if k not in self._gaits:
            st, g = self.style, self.gains
            roll = g.zmp_roll * self.half[0]
            self._gaits[k] = NominalGait(
                step=st.step_length * k / START_STEPS,
                width=st.step_width,
                ss=st.single_support,
                ds=st.double_support,
                heel=roll,
                toe=roll,
                inward=-g.zmp_out * self.half[1],
                omega=self.omega,
            )
        return self._gaits[k]

    def _offset(self, step: int, side: float) -> np.ndarray:
        """The nominal DCM offset at touchdown of a foot landing on ``side`` (cached)."""
        key = (min(step, START_STEPS), side)
        if key not in self._offsets:
            self._offsets[key] = self.gait(step).offset(side)
        return self._offsets[key]

    # -- the tick ------------------------------------------------------------------
    def _start(self, obs) -> None:
        st = self.style
        self.est = BodyEstimator(self.fk, self.dt, self.omega)
        self.est.reset("r")
        e = self.est.update(obs, np.zeros(2))
        self.stance = "r"
        self.single = False
        self.t_phase = 0.0
        self.ds_time = (SETTLE + SHIFT) * st.step_time
        self.steps = 0
        self.trail = FootPose(e.swing.pos.copy(), e.swing.yaw)  # the left foot, down
        self.swing = FootPose(e.swing.pos.copy(), e.swing.yaw)
        self.landing = np.array([0.0, st.step_width])
        self.land_yaw = 0.0
        self.ss = st.single_support
        self.c_ref = e.com[:2].copy()
        self.v_ref = np.zeros(2)
        self.zmp = e.com[:2].copy()
        self.q = obs.joints.copy()
        self.ik.set(self.q)
        self.com_off = self.ik.com()[:2]  # the centre of mass ahead of the pelvis
        self.z0 = float(e.com[2] - self.ik.com()[2])  # the pelvis above the stance sole
        self.heading_goal = 0.0
        self.sigma = 0.0
        self._started = True

    def _zmp_plan(self, e: BodyEstimate) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """The planned ZMP now, the heel and toe points, and (in double support) the
        time left before lift-off."""
        side = 1.0 if self.stance == "l" else -1.0
        gait = self.gait(self.steps + 1)
        _, heel, toe = gait.zmp_points(side)
        if self.single:
            s = min(self.t_phase / max(self.ss, 1e-3), 1.0)
            return heel + (toe - heel) * s, heel, toe, 0.0
        start = self.trail.pos[:2] + rot_z(self.trail.yaw)[:2, :2] @ np.array([gait.toe, 0.0])
        if self.steps == 0:  # the start: both feet down, the weight shifts over
            settle = SETTLE * self.style.step_time
            start = 0.5 * self.trail.pos[:2]
            if self.t_phase < settle:
                return start, heel, toe, self.ds_time - self.t_phase
            s = (self.t_phase - settle) / (self.ds_time - settle)
        else:
            s = self.t_phase / self.ds_time
        return start + (heel - start) * min(s, 1.0), heel, toe, max(self.ds_time - self.t_phase, 0.0)

    def __call__(self, k: int, obs) -> np.ndarray:
        if k == 0 or not self._started:
            self._start(obs)
        dt, st, g = self.dt, self.style, self.gains
        e = self.est.update(obs, self.zmp)
        self._last_cop, self._sw_meas, self._roll, self._pitch = e.cop, e.swing.pos, e.roll, e.pitch
        side = 1.0 if self.stance == "l" else -1.0
        gait = self.gait(self.steps + 1)
        zmp_plan, heel, toe, ds_left = self._zmp_plan(e)
        nominal = np.array([gait.step, -side * gait.width])
        offset = self._offset(self.steps + 1, -side)
        if self.single and not _NOPLAN:
            choice = plan_step(
                e.dcm, side, gait, self.limits, self.weights,
                elapsed=self.t_phase, zmp_now=zmp_plan, swing_at=self.swing.pos[:2],
                nominal_step=nominal, offset=offset, zmp_box=self._zmp_box(zmp_plan, toe),
            )  # fmt: skip
            self.landing, self.ss = choice.landing, self.t_phase + choice.remaining
            zmp_plan = zmp_plan + choice.zmp_shift
            toe = toe + choice.zmp_shift
            xi_ref = dcm_before(self.landing + offset, zmp_plan, toe, choice.remaining, self.omega)
        elif self.single:
            self.landing, self.ss = nominal, gait.ss
            rem = max(self.ss - self.t_phase, 0.01)
            xi_ref = dcm_before(self.landing + offset, zmp_plan, toe, rem, self.omega)
        else:  # double support: the nominal step, the DCM kept on its way by the ZMP
            self.landing, self.ss = nominal, gait.ss
            xi_td = dcm_before(self.landing + offset, heel, toe, self.ss, self.omega)
            xi_ref = dcm_before(xi_td, zmp_plan, heel, ds_left, self.omega) if ds_left > 0 else xi_td
        # the commanded body: a pendulum kept on the DCM reference by its ZMP ...
        xi_cmd = self.c_ref + self.v_ref / self.omega
        self.zmp = self._support(zmp_plan + g.dcm * (xi_cmd - xi_ref))
        self.c_ref, self.v_ref = lipm_step(self.c_ref, self.v_ref, self.zmp, dt, self.omega)
        self.c_ref = self.c_ref + g.follow * (e.com[:2] - self.c_ref)
        self.v_ref = self.v_ref + g.follow * (e.com_vel - self.v_ref)
        # ... and the measured DCM's error from it shifts the ZMP through the ankles
        self.ankle_zmp = g.ankle * (e.dcm - xi_cmd)
        # the next foot's heading: the heading error turned back, and the turn commanded
        err = self.heading_goal - e.heading
        self.land_yaw = float(np.clip(g.heading * err + self.turn, -0.35, 0.35))
        self._swing_foot(e)
        q = self._joints(e)
        if self.log:
            self.ticks.append(
                TickLog(k * dt, self.stance, self.single, self.steps, e.dcm.copy(), xi_ref.copy(),
                        self.zmp.copy(), self.c_ref.copy(), self.landing.copy(), self.ss)
            )  # fmt: skip
        self.t_phase += dt
        self._advance(e)
        return q

    def _zmp_box(self, now: np.ndarray, end: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The ZMP shifts that keep the rest of the single support's ZMP plan (from ``now``
        to ``end``) within the stance sole shrunk by ``support``."""
        lim = self.half * self.gains.support
        lo = -lim - np.minimum(now, end)
        hi = lim - np.maximum(now, end)
        return np.minimum(lo, 0.0), np.maximum(hi, 0.0)

    def _support(self, p: np.ndarray) -> np.ndarray:
        """``p`` kept within the support: the stance sole shrunk by ``support``, or in
        double support the box spanning both soles."""
        lim = self.half * self.gains.support
        if self.single:
            return np.clip(p, -lim, lim)
        other = self.trail.pos[:2]
        lo = np.minimum(-lim, other - lim)
        hi = np.maximum(lim, other + lim)
        return np.clip(p, lo, hi)

    def _swing_foot(self, e: BodyEstimate) -> None:
        if not self.single:
            return
        st = self.style
        s_prev = self.sigma
        s = min(self.t_phase / max(self.ss, 1e-3), 1.0)
        x_prev, x_now = _profile(st.swing_x, s_prev), _profile(st.swing_x, s)
        frac = 1.0 if 1.0 - x_prev < 1e-6 else (x_now - x_prev) / (1.0 - x_prev)
        frac = min(max(frac, 0.0), 1.0)
        pos = self.swing.pos.copy()
        pos[:2] += frac * (self.landing - pos[:2])
        yaw = self.swing.yaw + frac * (self.land_yaw - self.swing.yaw)
        if s < 1.0:
            pos[2] = st.clearance * _profile(st.swing_z, s)
        else:  # the floor is late: keep descending
            pos[2] = max(pos[2] - 0.5 * st.clearance * self.dt / (LATE * st.step_time), -0.5 * st.clearance)
        self.swing = FootPose(pos, yaw)
        self.sigma = s

    def _joints(self, e: BodyEstimate) -> np.ndarray:
        st, g, r = self.style, self.gains, self.robot
        c_cmd = self.c_ref + g.lead * self.v_ref
        if self.steps == 0 and not self.single:
            a = _smooth(self.t_phase / (SETTLE * st.step_time))
            z = (1 - a) * self.z0 + a * self.pelvis_z
        else:
            z = self.pelvis_z
        pelvis = np.array([*(c_cmd - self.com_off), z])
        other = self.swing if self.single else self.trail
        yaw = 0.5 * other.yaw
        rot = rot_xyz(0.0, 0.0, yaw)
        sw = "l" if self.stance == "r" else "r"
        feet = {
            self.stance: FootPose(-pelvis, 0.0),
            sw: FootPose(other.pos - pelvis, other.yaw),
        }
        q = self.ik.solve_legs(self.q, feet, rot, iterations=2)
        if _DEBUG:
            self.ik.set(q, rot)
            self._ik_err = {s: np.linalg.norm(self.ik.sole_pos(s) - f.pos) for s, f in feet.items()}
        phase = self._phase()
        offsets = st.upper_at(phase)
        for role, j in self._upper_roles.items():
            q[j] = r.stand[j] + offsets[role]
        self.ik.set(q, rot)
        self.com_off = self.ik.com()[:2]
        self.q = q
        out = q.copy()
        shares = self._shares()
        if g.feedforward:
            loads = {self.stance: (shares[self.stance], self._press(self.stance, pelvis))}
            if not self.single:
                loads[sw] = (shares[sw], self._press(sw, pelvis))
            out += g.feedforward * self.ik.static_torques(loads) / self.kp
        weight = self.fk.mass * GRAVITY
        for side, share in shares.items():
            legs = self.ik.legs[side]
            if share <= 0.0 or len(legs) < 6:
                continue
            # a ZMP shift Δp asks the ankle for m g Δp of torque: Δθ = m g Δp / kp
            dp = np.clip(self.ankle_zmp, -self.half, self.half) * share * weight
            out[legs[4]] += dp[0] / self.kp[legs[4]]
            out[legs[5]] -= dp[1] / self.kp[legs[5]]
        if g.torso:  # the stance hip turns the torso back upright
            legs = self.ik.legs[self.stance]
            out[legs[1]] -= g.torso * e.roll
            out[legs[2]] -= g.torso * e.pitch
        return out

    def _press(self, side: str, pelvis: np.ndarray) -> np.ndarray:
        """Where ``side``'s sole presses, in the model's frame (the pelvis at the origin):
        the stance sole at the commanded ZMP in single support, each sole's centre in
        double support."""
        if side == self.stance:
            at = np.array([*self.zmp, 0.0]) if self.single else np.zeros(3)
        else:
            at = self.trail.pos.copy()
        return at - pelvis

    def _shares(self) -> dict[str, float]:
        """The robot's weight on each sole, as planned: all on the stance sole in single
        support; in double support shared by where the commanded ZMP lies between them."""
        other = "l" if self.stance == "r" else "r"
        if self.single:
            return {self.stance: 1.0, other: 0.0}
        d = self.trail.pos[:2]
        w = float(np.clip(np.dot(self.zmp, d) / max(np.dot(d, d), 1e-9), 0.0, 1.0))
        return {self.stance: 1.0 - w, other: w}

    def _phase(self) -> float:
        """The gait phase ψ ∈ [0, 1) (0 at the left touchdown) for the arms and waist."""
        st = self.style
        t = self.t_phase if not self.single else self.ds_time + self.t_phase
        frac = min(t / max(self.ds_time + self.ss, 1e-3), 1.0) if self.steps else 0.0
        return (0.0 if self.stance == "l" else 0.5) + 0.5 * frac + 0.0 * st.step_time

    def _advance(self, e: BodyEstimate) -> None:
        """Lift-off at the end of double support; touchdown when the swing sole feels
        the floor (or has waited too long for it)."""
        st = self.style
        if not self.single:
            tr = 0 if self.stance == "r" else 1
            share = e.load[tr] / max(float(e.load.sum()), 1e-6)
            waited = self.t_phase >= self.ds_time + LATE * st.step_time
            if self.t_phase >= self.ds_time - 1e-9 and (share <= self.gains.unload or waited):
                self.single, self.t_phase, self.sigma = True, 0.0, 0.0
                self.swing = FootPose(self.trail.pos.copy(), self.trail.yaw)
            return
        sw = 0 if self.stance == "r" else 1  # the swing sole's column of the loads
        weight = self.fk.mass * GRAVITY
        landed = self.sigma > 0.6 and e.load[sw] > TOUCHDOWN_LOAD * weight
        late = self.t_phase > self.ss + LATE * st.step_time
        if not (landed or late):
            return
        new = "l" if self.stance == "r" else "r"
        land = FootPose(e.swing.pos.copy(), e.swing.yaw)
        rot = rot_z(-land.yaw)
        # the old stance foot, seen from the new one
        self.trail = FootPose(rot @ (np.zeros(3) - land.pos), -land.yaw)
        self.trail.pos[2] = 0.0
        r2 = rot[:2, :2]
        self.c_ref = r2 @ (self.c_ref - land.pos[:2])
        self.v_ref = r2 @ self.v_ref
        self.com_off = r2 @ self.com_off
        self.est.switch(new, land)
        self.heading_goal = self.heading_goal + self.turn
        self.stance, self.single, self.t_phase = new, False, 0.0
        self.ds_time = st.double_support
        self.steps += 1
