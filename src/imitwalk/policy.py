"""The walking controller that runs at every control tick (pure NumPy).

It plays the reference's start-up from standing, then walks the gait loop in the
paper's representation: each tick an action χ_t = (φ, r, h) — the nominal one, or the
one the model-predictive search of eqs. 5–13 picks — goes to joint targets through g
and C⁺; on top, the step-level balance channels (:mod:`imitwalk.balance`) add task-space
offsets, solved exactly by the robot's IK (an injected ``channel_ik(tick, offsets)``,
e.g. :class:`imitwalk.retarget.online.OnlineIK`), from the first step of the start-up
on; the joint change it makes is added to the controller's output. Over the last
start-up cycle the output is cross-faded from the start-up trajectory to the
controller's, unless the gait adds its residual back (then the controller's nominal
output is the reference, which continues the start-up exactly, and the start-up is
played to its end). Once the feet step, the plan runs on its own clock, which the
``time`` channel slows or speeds over a step (between ticks, targets are interpolated
linearly). It records what the learner trains on.
"""

from __future__ import annotations

from itertools import pairwise

import numpy as np

from imitwalk.balance import StepController
from imitwalk.controller import ActionSelector
from imitwalk.errors import ConfigError, unknown_name
from imitwalk.estimator import StateEstimator
from imitwalk.gait import GaitModel
from imitwalk.stepconfig import LAG_JOINTS

__all__ = ["WalkPolicy", "startup_ramp", "step_clock0"]


def step_clock0(gait: GaitModel) -> int:
    """The plan tick of the balance channels' first step: the start-up's first step when
    the start-up steps at the loop's cadence, else (a reference at another cadence) the
    loop's first tick."""
    m, n = gait.ref.starts.shape[1], gait.n_ticks
    same = float(gait.ref.settings.get("cadence", 1.0)) == 1.0
    return m % n + n if same else m


def startup_ramp(gait: GaitModel, scale: float) -> np.ndarray:
    """``(K,)`` each step's stride while the start-up's stride grows, a fraction of a
    steady step's: the mean speed of the reference plan's walking frame over the step
    over its mean speed along the loop (K: the steps that begin in the start-up; ones if
    the frame does not travel, e.g. turning on the spot)."""
    path = gait.ref.plan_at(scale)["path"]
    n, half = gait.n_ticks, gait.n_ticks / 2.0
    speed = np.hypot(np.diff(path[:, 3]), np.diff(path[:, 4]))  # [m / tick]
    steady = speed[-n:].mean()
    c0, m = step_clock0(gait), gait.ref.starts.shape[1]
    n_steps = max(int(np.ceil((m - c0) / half)), 0)
    if steady <= 1e-9:
        return np.ones(n_steps)
    edges = c0 + half * np.arange(n_steps + 1)
    fractions = [speed[int(a) : int(b)].mean() / steady for a, b in pairwise(edges)]
    return np.clip(fractions, 0.0, 1.0)


class WalkPolicy:
    """Per-tick controller; call it as ``policy(tick, observation) -> (n,) targets``.

    Args:
        gait: the gait representation; scale: a schedule scale.
        tick_selector: the paper's per-tick MPC (``None``: follow the nominal actions).
        tick_state: ``"gyro"`` (the paper) or ``"full"`` (gyro, roll, pitch) for its model.
        steps: the step-level channel controller (``None``: no channels).
        channel_ik: ``(tick, offsets (10,)) -> (n,)`` joint angles of the reference plan with
            task offsets (zero offsets: the reference itself).
        explore: uniform noise on (r, h), a fraction of the tick box, during training.
        rng: noise source.
    """

    def __init__(
        self,
        gait: GaitModel,
        scale: float,
        tick_selector: ActionSelector | None = None,
        tick_state: str = "gyro",
        steps: StepController | None = None,
        channel_ik=None,
        explore: tuple[float, float] = (0.0, 0.0),
        rng: np.random.Generator | None = None,
    ):
        self.gait, self.scale = gait, scale
        self.selector, self.tick_state = tick_selector, tick_state
        self.steps, self.channel_ik = steps, channel_ik
        self.explore, self.rng = np.asarray(explore, dtype=float), rng
        self.start, self.loop, _ = gait.ref.at_scale(scale)
        self.n = gait.n_ticks
        self._clock0 = step_clock0(gait)  # the balance channels' step clock starts here
        self.estimator = StateEstimator(gait.ref.dt)
        nom = gait.nominal[gait._key(scale)]
        self._phi_table = nom[:, 0]
        self._dphi = gait.phase_step(scale)
        # records
        self.tick_states: list[np.ndarray] = []
        self.tick_actions: list[np.ndarray] = []
        self.tick_predicted: list[float] = []
        self._a_prev: np.ndarray | None = None
        self._step_k = 0
        self._v: float | None = None  # the plan's clock once the feet step [ticks]
        self._gyro_sum, self._gyro_n = np.zeros(4), 0
        # a turning reference: the channels see the heading and yaw rate beyond its turn
        ref = gait.ref
        turning = bool(ref.plan) and abs(ref.motion_at(scale)[2]) > 0.0
        self._cmd_heading = ref.plan_at(scale)["path"][:, 2] if turning else None
        self._cmd_turn = float(ref.motion_at(scale)[2]) if turning else 0.0
        # the servo state: ankle-pitch tracking errors, per step, of the last two steps
        self._lag = None
        if steps is not None and steps.config.servo_state:
            names = tuple(ref.joint_names)
            for j in LAG_JOINTS:
                if j not in names:
                    raise unknown_name("joint (for step.servo_state)", j, names, ConfigError)
            self._lag = [names.index(j) for j in LAG_JOINTS]
        self._lag_now, self._lag_sum, self._lag_steps = np.zeros(2), np.zeros(2), [np.zeros(2)]
        self._last: np.ndarray | None = None  # the targets last commanded

    @property
    def first_loop_tick(self) -> int:
        """The first tick at which the paper's controller acts (its actions are recorded
        from here on): the start of the cross-fade cycle, or the end of the start-up."""
        return len(self.start) - (0 if self.gait.config.residual else self.n)

    @property
    def q0(self) -> np.ndarray:
        """``(n,)`` the posture the controller starts from (the start-up's first);
        :func:`imitwalk.sim.run` resets the robot to it."""
        return self.start[0]

    def _tick_state(self, est) -> np.ndarray:
        if self.tick_state == "full":
            return np.array([*est.gyro, est.roll, est.pitch])
        return est.gyro.copy()

    def __call__(self, k: int, obs) -> np.ndarray:
        if self._lag is not None and self._last is not None:  # the servos' lag, measured
            self._lag_now = self._last[self._lag] - np.asarray(obs.joints)[self._lag]
        q = self._targets(k, obs)
        self._last = q
        return q

    def _targets(self, k: int, obs) -> np.ndarray:
        est = self.estimator.update(obs.gyro, obs.accel, obs.foot_force)
        if self.steps is None or k < self._clock0:
            return self._at(k, est)
        # once the feet step, the plan runs on its own clock v: one loop tick per control
        # tick, slower or faster over a step whose ``time`` channel is not 0
        v = float(k) if self._v is None else self._v
        q = self._base(v, est)
        offsets = self._channels(v - self._clock0, est, v)
        if np.any(offsets):
            q = q + self.channel_ik(v, offsets) - self._base(v, None, reference=True)
        else:
            self.channel_ik(v, offsets)  # keep the solver's warm start on track
        self._v = v + self.steps.rate(self._step_k - 1)
        return q

    def _at(self, k: int, est, record: bool = True) -> np.ndarray:
        """The joint targets at plan tick ``k`` without the channels."""
        m, n = len(self.start), self.n
        if k < self.first_loop_tick:
            return self.start[k].copy()
        i = k - m  # loop tick; negative during the cross-fade cycle
        q = (
            self._tick(i, est)
            if record
            else self.gait.joints(self.scale, self.gait.nominal_action(self.scale, i), i)
        )
        if i < 0:  # cross-fade from the start-up into the controller over one cycle
            w = (i + n) / n
            q = (1.0 - w) * self.start[k] + w * q
        return q

    def _base(self, v: float, est, reference: bool = False) -> np.ndarray:
        """Joint targets at plan time ``v`` [ticks] (linear between ticks): the
        controller's (``reference=False``, recording its tick) or the reference's."""
        k0 = int(np.floor(v))
        a = v - k0
        q = self._reference(k0) if reference else self._at(k0, est)
        if a > 0.0:
            q1 = self._reference(k0 + 1) if reference else self._at(k0 + 1, None, record=False)
            q = (1.0 - a) * q + a * q1
        return q

    def _reference(self, k: int) -> np.ndarray:
        m = len(self.start)
        return self.start[k] if k < m else self.loop[(k - m) % self.n]

    def _tick(self, i: int, est) -> np.ndarray:
        """The paper's part: action χ_t (nominal or searched) → joint targets via g, C⁺."""
        nominal = self.gait.nominal_action(self.scale, i)
        s = self._tick_state(est)
        if self.selector is not None and self._a_prev is not None and self.tick_states:
            dec = self.selector.select(s, self.tick_states[-1], self._a_prev)
            action = dec.action
            self.tick_predicted.append(dec.cost)
        else:
            action = nominal
        if self.rng is not None and self.explore.any():
            action = action + np.r_[0.0, self.explore * self.rng.uniform(-1, 1, 2)]
        self.tick_states.append(s)
        self.tick_actions.append(action)
        self._a_prev = action
        return self.gait.joints(self.scale, action, i)

    def commanded_heading(self, v: float) -> float:
        """The reference's own heading [rad] at plan tick ``v`` (0 unless it turns)."""
        if self._cmd_heading is None:
            return 0.0
        i, c = self.gait.ref.loop_index(int(np.floor(v)))
        return float(self._cmd_heading[i] + c * self._cmd_turn)

    def _channels(self, j: float, est, v: float) -> np.ndarray:
        """Step-level balance channels at stepping tick ``j`` (the plan's clock ``v``;
        0 = first step). Heading and yaw rate are taken relative to the reference's
        own turn."""
        h0 = self.commanded_heading(v)
        rate = (self.commanded_heading(v + 1) - h0) / self.gait.ref.dt
        self._gyro_sum += np.r_[est.gyro - [0.0, 0.0, rate], est.cop_x]
        self._lag_sum += self._lag_now
        self._gyro_n += 1
        half = self.n / 2.0
        while j >= self._step_k * half:  # a step boundary (heel strike): decide
            mean = self._gyro_sum / max(self._gyro_n, 1)  # gyro (3) and cop_x over the step
            heading = est.heading - h0
            state = np.array([est.roll, est.pitch, heading, *mean[:3], est.load_left, mean[3]])
            if self._lag is not None:  # mean over the last two steps: one gait cycle
                self._lag_steps = [self._lag_steps[-1], self._lag_sum / max(self._gyro_n, 1)]
                state = np.r_[state, 0.5 * (self._lag_steps[0] + self._lag_steps[1])]
                self._lag_sum = np.zeros(2)
            self.steps.decide(state, self._step_k)
            self._step_k += 1
            self._gyro_sum, self._gyro_n = np.zeros(4), 0
        return self.steps.offsets(j)
