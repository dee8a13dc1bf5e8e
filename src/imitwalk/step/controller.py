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
4. **Swing the foot** (:mod:`imitwalk.step.swing`) along the style's path shape,
   re-aimed every tick at the landing chosen, and set it down when its sole feels the
   floor (or lower it further when the floor is late); lift the trailing foot once it
   has unloaded.
5. **Solve the joints** (:mod:`imitwalk.step.joints`): both soles, the pelvis, the arms
   and waist (their swing ramped in over the start's double support: set to its first
   phase at once, Unitree G1's arms yawed its torso at 5 rad/s), and the servos'
   feedforward and the ankles' share of the balance. The
   soles are laid onto the floor's slope across the walk, as the stance sole's attitude
   gives it over :data:`~imitwalk.step.estimator.SETTLED_TAU` (a level sole on a floor
   tilted across stands on its edge: 12 of 40 ``cross`` robots fell at 3° without it).
   Along the walk the soles stay level: the ZMP rolls heel to toe anyway, and tilting
   them there fell more training robots of ``slope``. The axis and the time constant
   were picked by trials on 40 training robots (seeds 1001-1040) of ``cross``, ``hard``
   and ``slope``: ``python bench/paired.py RUN:learned --protocol P --first 1001``.

Nothing here reads the simulator: only the :class:`~imitwalk.sim.types.Observation`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.errors import ConfigError
from imitwalk.robots import Robot
from imitwalk.sim.types import Observation
from imitwalk.step.estimator import BodyEstimate, BodyEstimator, ObserverNoise
from imitwalk.step.gains import StepGains
from imitwalk.step.joints import JointSolver
from imitwalk.step.kinematics import BodyModel, FootPose, floor_mat, rot_z
from imitwalk.step.lipm import GRAVITY, dcm_before, lipm_step, omega_of
from imitwalk.step.nominal import NominalWalk, turning_step
from imitwalk.step.odometry import LegOdometry, Pose2D, StepCommand
from imitwalk.step.planner import plan_step
from imitwalk.step.schedule import LATE, MAX_STEP_YAW, SETTLE, SHIFT
from imitwalk.step.style import GaitStyle
from imitwalk.step.support import (
    other_side,
    press_point,
    weight_shares,
    within_support,
    zmp_box,
)
from imitwalk.step.swing import SwingFoot

__all__ = ["TOUCHDOWN_LOAD", "SteppingController", "TickLog"]

#: A swing foot has landed when its sole carries this share of the robot's weight.
TOUCHDOWN_LOAD = 0.1
#: ... and has covered at least this share of its swing.
TOUCHDOWN_SWING = 0.5


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


def _smooth(x: float) -> float:
    x = min(max(x, 0.0), 1.0)
    return x * x * x * (x * (6.0 * x - 15.0) + 10.0)


class SteppingController:
    """A walking policy for ``robot`` (see the module doc).

    Args:
        robot: the robot; style: the walk to imitate; gains: the learned gains;
        dt: control period [s]; log: keep a :class:`TickLog` per tick (``self.ticks``).

    Attributes:
        q0: the posture it starts from (the robot standing); steps: touchdowns so far;
        command: the :class:`~imitwalk.step.odometry.StepCommand` it walks (straight
        ahead at the style's stride unless :meth:`steer` says otherwise).
    """

    def __init__(
        self, robot: Robot, style: GaitStyle, gains: StepGains, dt: float, log: bool = False
    ):
        if not isinstance(style, GaitStyle):
            raise ConfigError(
                "style must be a GaitStyle (the .style of a StepGait, as "
                f"imitwalk.gait_from_motion returns), not {type(style).__name__}"
            )
        self.robot, self.style, self.gains, self.dt = robot, style, gains, dt
        self.q0 = robot.stand.copy()
        self.fk = BodyModel(robot)
        self.joints = JointSolver(robot, style, gains, dt)
        geom = style.geometry
        self.half = np.array([geom.foot_length, geom.foot_width]) / 2
        self.pelvis_z = style.pelvis_height - gains.crouch * geom.leg  # [m] over the soles
        self.omega = omega_of(self.joints.walking_com_height(self.pelvis_z, style.step_width))
        self.nominal = NominalWalk(style, gains, self.omega, self.pelvis_z)
        self.log = log
        self.ticks: list[TickLog] = []
        self.command = StepCommand(turn=style.turn / 2)
        self._started = False

    def steer(self, command: StepCommand) -> None:
        """Walk ``command`` from the next tick on (its stride rounded to a twentieth)."""
        self.command = command

    @property
    def started(self) -> bool:
        """Whether it has taken its first tick (and so knows where it stands)."""
        return self._started

    @property
    def pose(self) -> Pose2D:
        """Where the robot is by its own sensors (:mod:`imitwalk.step.odometry`): the
        centre of mass and the stance sole's heading in the start frame."""
        if not self._started:
            return Pose2D(0.0, 0.0, 0.0)
        return self.odometry.pose(self._com, self._heading)

    # -- the tick ------------------------------------------------------------------
    def _start(self, obs: Observation) -> None:
        st, g = self.style, self.gains
        noise = ObserverNoise(accel=10.0**g.observer)
        self.est = BodyEstimator(self.fk, self.dt, self.omega, noise)
        self.est.reset("r")
        e = self.est.update(obs, np.zeros(2))
        self.stance, self.single, self.t_phase, self.steps = "r", False, 0.0, 0
        self.ds_time = (SETTLE + SHIFT) * st.step_time
        self.trail = FootPose(e.swing.pos.copy(), e.swing.yaw)  # the left foot, down
        self.swing = SwingFoot(
            st.swing_x,
            st.swing_z,
            st.clearance,
            LATE * st.step_time,
            g.swing_fix,
            0.1 * st.geometry.leg,
        )
        self.landing, self.land_yaw = np.array([0.0, st.step_width]), 0.0
        self.ss = st.single_support
        self.c_ref, self.v_ref = e.com[:2].copy(), np.zeros(2)
        self.zmp, self.ankle_zmp = e.com[:2].copy(), np.zeros(2)
        self.joints.reset(obs.joints)
        self.z0 = float(e.com[2] - self.joints.com_above_pelvis())  # the pelvis over the sole
        self.odometry = LegOdometry()
        self.odometry.reset(e.swing.pos[:2], e.heading)
        self._com, self._heading = e.com[:2].copy(), e.heading
        self._started = True

    def _zmp_plan(self, e: BodyEstimate) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """The planned ZMP now, the heel and toe points, and (in double support) the
        time left before lift-off."""
        side = 1.0 if self.stance == "l" else -1.0
        gait = self.nominal.gait(self.steps + 1, self.command.stride)
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
        return (
            start + (heel - start) * min(s, 1.0),
            heel,
            toe,
            max(self.ds_time - self.t_phase, 0.0),
        )

    def __call__(self, k: int, obs: Observation) -> np.ndarray:
        """The joint targets ``(n,)`` [rad] for tick ``k`` (the steps of the module doc)."""
        if k == 0 or not self._started:
            self._start(obs)
        e = self.est.update(obs, self.zmp)
        self._com, self._heading = e.com[:2], e.heading
        zmp_plan, xi_ref = self._plan_step(e)
        self._command_body(e, zmp_plan, xi_ref)
        self.land_yaw = self._landing_yaw(e)
        if self.single:
            self.swing.advance(
                self.t_phase, self.ss, self.landing, self.land_yaw, e.swing.pos, self.dt, e.slope
            )
        q = self._joints(e)
        if self.log:
            self._record(k, e, xi_ref)
        self.t_phase += self.dt
        self._advance(e)
        return q

    def _plan_step(self, e: BodyEstimate) -> tuple[np.ndarray, np.ndarray]:
        """Step 2: where and when the swing foot lands (``self.landing``, ``self.ss``), and
        the planned ZMP now and the DCM reference ``ξ_ref``, each ``(2,)`` [m]."""
        g = self.gains
        side = 1.0 if self.stance == "l" else -1.0
        gait = self.nominal.gait(self.steps + 1, self.command.stride)
        zmp_plan, heel, toe, ds_left = self._zmp_plan(e)
        nominal = np.array([gait.step, -side * gait.width])
        offset = self.nominal.offset(self.steps + 1, -side, self.command.stride)
        if self.command.turn:  # a turning gait: the step and its DCM offset turn with it
            nominal, offset = turning_step(gait.step, gait.width, side, self.command.turn, offset)
        if self.single:
            choice = plan_step(
                e.dcm,
                side,
                gait,
                self.nominal.limits,
                self.nominal.weights,
                elapsed=self.t_phase,
                zmp_now=zmp_plan,
                swing_at=self.swing.pose.pos[:2],
                nominal_step=nominal,
                offset=offset,
                zmp_box=zmp_box(self.half, g.support, g.plan_support, zmp_plan, toe),
            )
            self.landing, self.ss = choice.landing, self.t_phase + choice.remaining
            zmp_plan = zmp_plan + choice.zmp_shift
            toe = toe + choice.zmp_shift
            xi_ref = dcm_before(self.landing + offset, zmp_plan, toe, choice.remaining, self.omega)
        else:  # double support: the nominal step, the DCM kept on its way by the ZMP
            self.landing, self.ss = nominal, gait.ss
            xi_td = dcm_before(self.landing + offset, heel, toe, self.ss, self.omega)
            xi_ref = (
                dcm_before(xi_td, zmp_plan, heel, ds_left, self.omega) if ds_left > 0 else xi_td
            )
        return zmp_plan, xi_ref

    def _command_body(self, e: BodyEstimate, zmp_plan: np.ndarray, xi_ref: np.ndarray) -> None:
        """Step 3: the commanded body, a pendulum kept on the DCM reference ``xi_ref`` by its
        ZMP, and the ankles' share of the balance."""
        dt, g = self.dt, self.gains
        xi_cmd = self.c_ref + self.v_ref / self.omega
        self.zmp = within_support(
            zmp_plan + g.dcm * (xi_cmd - xi_ref),
            self.half,
            g.support,
            self.single,
            self.trail.pos[:2],
        )
        self.c_ref, self.v_ref = lipm_step(self.c_ref, self.v_ref, self.zmp, dt, self.omega)
        self.c_ref = self.c_ref + g.follow * (e.com[:2] - self.c_ref)
        self.v_ref = self.v_ref + g.follow * (e.com_vel - self.v_ref)
        # ... and the measured DCM's error from it shifts the ZMP through the ankles
        self.ankle_zmp = g.ankle * (e.dcm - xi_cmd)

    def _landing_yaw(self, e: BodyEstimate) -> float:
        """The next foot's heading [rad]: the heading error turned back, and the turn
        commanded fed forward, within :data:`~imitwalk.step.schedule.MAX_STEP_YAW`."""
        g = self.gains
        err = self.command.heading - e.heading
        if abs(err) > np.pi:  # the measured heading is wrapped to (-pi, pi]
            err = (err + np.pi) % (2 * np.pi) - np.pi
        turn = g.heading * err + (1.0 - g.heading) * self.command.turn
        return float(min(max(turn, -MAX_STEP_YAW), MAX_STEP_YAW))

    def _record(self, k: int, e: BodyEstimate, xi_ref: np.ndarray) -> None:
        """Keep tick ``k``'s :class:`TickLog`."""
        self.ticks.append(
            TickLog(
                k * self.dt,
                self.stance,
                self.single,
                self.steps,
                e.dcm.copy(),
                xi_ref.copy(),
                self.zmp.copy(),
                self.c_ref.copy(),
                self.landing.copy(),
                self.ss,
            )
        )

    def _joints(self, e: BodyEstimate) -> np.ndarray:
        st, g = self.style, self.gains
        upper = 1.0
        if self.steps == 0 and not self.single:  # settling: the pelvis lowers to its height
            a = _smooth(self.t_phase / (SETTLE * st.step_time))
            height = (1 - a) * self.z0 + a * self.pelvis_z
            upper = _smooth(self.t_phase / self.ds_time)  # the arms swing in by lift-off
        else:
            height = self.pelvis_z
        other = self.swing.command() if self.single else self.trail
        shares = weight_shares(self.stance, self.single, self.zmp, self.trail.pos[:2])
        loads = {
            side: (w, press_point(side, self.stance, self.single, self.zmp, self.trail.pos))
            for side, w in shares.items()
            if w > 0.0
        }
        com = self.c_ref + g.lead * self.v_ref
        across = floor_mat(np.array([0.0, e.settled_slope[1]]))
        return self.joints.solve(
            self.stance, com, height, other, self._phase(), loads, self.ankle_zmp, across, upper
        )

    @property
    def phase(self) -> float:
        """The gait phase ψ ∈ [0, 1) the controller is at (0 before its first tick)."""
        return self._phase() if self._started else 0.0

    def _phase(self) -> float:
        """The gait phase ψ ∈ [0, 1) (0 at the left touchdown) for the arms and waist."""
        t = self.t_phase if not self.single else self.ds_time + self.t_phase
        frac = min(t / max(self.ds_time + self.ss, 1e-3), 1.0) if self.steps else 0.0
        return (0.0 if self.stance == "l" else 0.5) + 0.5 * frac

    def _advance(self, e: BodyEstimate) -> None:
        """Lift-off at the end of double support; touchdown when the swing sole feels
        the floor (or has waited too long for it)."""
        st = self.style
        if not self.single:
            tr = 0 if self.stance == "r" else 1
            share = e.load[tr] / max(float(e.load.sum()), 1e-6)
            waited = self.t_phase >= self.ds_time + LATE * st.step_time
            if self.t_phase >= self.ds_time - 1e-9 and (share <= self.gains.unload or waited):
                self.single, self.t_phase = True, 0.0
                self.swing.lift_off(self.trail)
                if self.command.turn:  # a turning gait: this step lands turned
                    c = self.command
                    self.command = StepCommand(c.heading + c.turn, c.stride, c.turn)
            return
        sw = 0 if self.stance == "r" else 1  # the swing sole's column of the loads
        weight = self.fk.mass * GRAVITY
        landed = self.swing.sigma > TOUCHDOWN_SWING and e.load[sw] > TOUCHDOWN_LOAD * weight
        late = self.t_phase > self.ss + LATE * st.step_time
        if not (landed or late):
            return
        new = other_side(self.stance)
        land = FootPose(e.swing.pos.copy(), e.swing.yaw)
        self.odometry.touchdown(land.pos[:2], e.heading)
        rot = rot_z(-land.yaw)
        # the old stance foot, seen from the new one
        self.trail = FootPose(rot @ (np.zeros(3) - land.pos), -land.yaw)
        self.trail.pos[2] = 0.0
        r2 = rot[:2, :2]
        self._com = r2 @ (self._com - land.pos[:2])  # the pose, seen from the new foot
        self._heading = e.heading + land.yaw
        self.c_ref = r2 @ (self.c_ref - land.pos[:2])
        self.v_ref = r2 @ self.v_ref
        self.joints.rebase(r2)
        self.est.switch(new, land)
        self.stance, self.single, self.t_phase = new, False, 0.0
        self.ds_time = st.double_support
        self.steps += 1
