"""Balance channels beside the posture subspace, decided once per step (pure NumPy).

The paper's action (φ, r, h) moves stride and sway together. These channels give the
learner its own handles on balance, decided at each step boundary (heel strike) by the
paper's machinery one level up: a 2nd-order sensory-motor model of *step* states
F(s_k, s_{k−1}, c_k, c_{k−1}) → s_{k+1} (an RBF network, eqs. 3–4) and a predictive
search over a box of candidate channel values (eqs. 5–7), over a horizon of steps.

Channels (mirrored so that one model serves left and right steps):

* ``dx``: the swing foot lands further forward [m];
* ``dy``: the swing foot lands further out, away from the stance foot [m];
* ``yaw``: the swing foot lands turned [rad] (the body follows it during the next stance);
* ``sway``: an extra lateral shift of the centre of mass towards the stance foot [m];
* ``lean``: the centre of mass further forward over the feet [m], held from step to step
  (it moves linearly from the previous step's value to this step's over the step);
* ``time``: the step takes longer (> 0) or shorter (< 0) by this fraction of its nominal
  duration: the whole task-space plan, swing, sway and all, is played slower or faster
  over that step (:class:`imitwalk.policy.WalkPolicy` keeps the plan's clock). Off by
  default (``step.channels`` names the channels in use);
* ``lift``: the swing foot rises higher (> 0) or lower (< 0) by this much at mid-swing
  [m], a half-sine bump over the plan's swing window, so the sole is where the plan puts
  it at lift-off and touch-down. Off by default.

They act in task space: the landing offsets grow smoothly over the swing and decay over
the foot's next stance, the sway is a half-sine bump over the step; the robot's IK
re-solves the reference's task-space plan with these offsets
(:class:`imitwalk.retarget.online.OnlineIK`). The step state (mirrored) is torso roll,
pitch, heading, the mean gyro over the step, the stance foot's share of the load and the
mean front/rear balance of the sole forces over the step — all from the robot's own
sensors; with ``step.servo_state``, also each ankle-pitch servo's mean tracking error over
the last gait cycle, from the joint encoders (measured by
:class:`imitwalk.policy.WalkPolicy`). The settings, and the names of the channels and
states, are in :mod:`imitwalk.stepconfig`.
"""

from __future__ import annotations

import numpy as np

from imitwalk.controller import stability_cost
from imitwalk.ensemble import ModelEnsemble
from imitwalk.predictor import SensoryMotorModel
from imitwalk.stepconfig import (
    ALWAYS_DRAWN,
    LATERAL,
    LIFT,
    STEP_CHANNELS,
    STEP_STATE,
    TASK_OFFSETS,
    TIME,
    StepConfig,
)

__all__ = [
    "STEP_CHANNELS",
    "STEP_STATE",
    "StepConfig",
    "StepController",
    "mirror_state",
    "step_target",
    "upgrade_step_actions",
]


def step_target(
    states: list[np.ndarray], actions: list[np.ndarray], scale: float, dim: int = len(STEP_STATE)
) -> np.ndarray:
    """The state the step objective aims for: the mean recorded (mirrored) step state of
    steps taken at scales within 0.1 of ``scale`` (all steps if none), heading 0.

    A walking robot's torso never settles at zero tilt; aiming for zero would make the
    search fight the gait itself. Heading is the exception: the walk should go straight.
    ``dim``: the state's size when nothing is recorded.
    """
    if not states:
        return np.zeros(dim)
    S = np.vstack(states)
    A = np.vstack(actions)
    near = np.abs(A[:, -1] - scale) <= 0.1 + 1e-9
    out = (S[near] if near.any() else S).mean(axis=0)
    out[2] = 0.0
    return out


def upgrade_step_actions(A: np.ndarray) -> np.ndarray:
    """Recorded step actions of a run written before the ``time`` channel ``(K, 6)`` or
    before the ``lift`` channel ``(K, 7)`` → ``(K, len(STEP_CHANNELS) + 1)``, with the
    missing channels 0 (they were nominal throughout); actions of this release are
    returned as they are."""
    if A.shape[1] == ALWAYS_DRAWN + 1:
        A = np.insert(A, TIME, 0.0, axis=1)
    if A.shape[1] == LIFT + 1:
        A = np.insert(A, LIFT, 0.0, axis=1)
    return A


def mirror_state(s: np.ndarray, m: float) -> np.ndarray:
    """A step state seen from the stance side: lateral parts × m (+1 left, −1 right).

    ``load_left`` (raw) becomes the stance foot's share, and the :data:`SERVO_STATE`
    entries, if any (raw: left, right), the stance leg's first.
    """
    out = np.array(s, dtype=float)
    out[..., : len(LATERAL)][..., LATERAL] *= m
    if m < 0:
        out[..., 6] = 1.0 - out[..., 6]
        if out.shape[-1] > len(STEP_STATE):
            out[..., [-2, -1]] = out[..., [-1, -2]]
    return out


class StepController:
    """Decides the channel values of each step and turns them into task offsets.

    Args:
        config: settings; n_ticks: ticks per gait cycle N; ds: double-support fraction.
        model: a fitted step model (``None``: nominal channels, plus exploration).
        rng: exploration noise source (``None``: no exploration).
        explore: noise amplitude, a fraction of ``c_max``; scale: the stride scale (an
            input of the step model); target: ``(d,)`` mirrored step state the objective
            pulls towards (see :func:`step_target`).
        ramp: ``(K,)`` the first K steps' strides, a fraction of a steady one (the
            start-up's; later steps: 1). The step model sees ``scale × ramp[k]`` as step
            k's stride scale (``None``: ``scale`` for every step).
    """

    def __init__(
        self,
        config: StepConfig,
        n_ticks: int,
        ds: float,
        model: ModelEnsemble | SensoryMotorModel | None = None,
        rng: np.random.Generator | None = None,
        explore: float = 0.0,
        scale: float = 1.0,
        target: np.ndarray | None = None,
        limits: np.ndarray | None = None,
        ramp: np.ndarray | None = None,
    ):
        self.config, self.n, self.ds, self.scale = config, n_ticks, ds, scale
        self.ramp = np.ones(0) if ramp is None else np.asarray(ramp, dtype=float)
        dim = len(config.state_names)
        self.target = np.zeros(dim) if target is None else np.asarray(target, float)
        self.model, self.rng, self.explore = model, rng, explore
        self.mask = np.array([c in config.channels for c in STEP_CHANNELS], dtype=float)
        self.c_max = np.asarray(config.c_max, dtype=float) * self.mask
        self.c_min = -self.c_max * (np.array(STEP_CHANNELS) != "dy")  # dy: outwards only
        # the search stays where the model has seen data; exploration may go to the limits
        self.box = self.c_max if limits is None else np.minimum(self.c_max, limits)
        self._drawn = (np.arange(len(STEP_CHANNELS)) < ALWAYS_DRAWN) | (self.mask > 0)
        self.offset = config.offset_vector * self.mask  # the nominal channel values
        self.states: list[np.ndarray] = []  # mirrored step states s_k
        self.actions: list[np.ndarray] = []  # channel values c_k (mirrored coordinates)
        self.predicted: list[float] = []
        self._land = {0: np.zeros(3), 1: np.zeros(3)}  # landing offsets (x, y, yaw) per foot
        self._last_k = -1

    # -- decisions ------------------------------------------------------------
    def decide(self, state_raw: np.ndarray, k: int) -> np.ndarray:
        """Channel values for step ``k`` given the raw step state at its start."""
        m = 1.0 if k % 2 == 0 else -1.0  # even steps: left stance (ψ ∈ [0, ½))
        s = mirror_state(state_raw, m)
        self.states.append(s)
        base = self.offset
        c = base.copy()
        if self.model is not None and len(self.states) >= 2 and len(self.actions) >= 1:
            c_prev = np.r_[self.actions[-1], self.scale_of(k - 1)]
            c, pred = self._search(s, self.states[-2], c_prev, k)
            c = base + self.config.gain * (c - base)
            self.predicted.append(pred)
        if self.rng is not None and self.explore > 0:
            noise = np.zeros(len(c))
            noise[self._drawn] = self.rng.uniform(-1.0, 1.0, int(self._drawn.sum()))
            c = c + self.explore * self.c_max * noise
        c = np.clip(c, self.c_min, self.c_max)
        self.actions.append(c)
        return c

    def _search(self, s, s_prev, c_prev, k: int) -> tuple[np.ndarray, float]:
        cfg = self.config
        rng = np.random.default_rng(len(self.states))
        lo = np.maximum(-self.box, self.c_min)
        cand = np.zeros((cfg.candidates, len(STEP_CHANNELS)))
        d = self._drawn
        cand[:, d] = rng.uniform(lo[d], self.box[d], (cfg.candidates, int(d.sum())))
        base = self.offset
        if base.any():  # the box is centred on the offset, within the channels' limits
            cand = np.clip(base + cand, self.c_min, self.c_max)
        cand = np.vstack([base, cand])  # (M, channels); the first: the nominal
        seq = np.zeros((len(cand), cfg.horizon, len(STEP_CHANNELS) + 1))
        seq[:, 0, :-1] = cand
        seq[:, 1:, :-1] = base  # later steps: the nominal channels
        seq[:, :, -1] = [self.scale_of(k + h) for h in range(cfg.horizon)]  # stride scale
        pred = self.model.rollout_members(s, s_prev, seq, c_prev)  # (E, M, H, ds)
        w = cfg.state_weights
        scale = np.where(self.c_max > 0, self.c_max, 1.0)
        cost = stability_cost(pred - self.target, w).sum(axis=-1)  # (E, M)
        cost = cost + cfg.effort * np.sum(((cand - base) / scale) ** 2, 1)
        # each member's predicted gain over the nominal channels; the worst decides
        worst = (cost - cost[:, :1]).max(axis=0)
        best = int(np.argmin(worst))
        if worst[best] > -cfg.margin * cost[:, 0].mean():  # not a clear enough gain
            best = 0
        return cand[best], float(cost[:, best].mean())

    def scale_of(self, k: int) -> float:
        """The stride scale step ``k`` is labelled with: ``scale`` × its ramp fraction."""
        return self.scale * (float(self.ramp[k]) if 0 <= k < len(self.ramp) else 1.0)

    def rate(self, k: int) -> float:
        """How fast step ``k`` plays the plan: 1 / (1 + ``time``) loop ticks per control
        tick (1 before the step is decided)."""
        if k >= len(self.actions):
            return 1.0
        return 1.0 / (1.0 + float(self.actions[k][TIME]))

    # -- task offsets ---------------------------------------------------------
    def episode(self) -> tuple[np.ndarray, np.ndarray]:
        """The recorded steps for training: states ``(K, len(config.state_names))`` and actions
        ``(K, len(STEP_CHANNELS) + 1)`` (channels and the scale); K may be 0."""
        k = min(len(self.states), len(self.actions))
        if k == 0:  # the robot fell before its first step decision
            dim = len(self.config.state_names)
            return np.zeros((0, dim)), np.zeros((0, len(STEP_CHANNELS) + 1))
        scales = [self.scale_of(i) for i in range(k)]
        acts = np.c_[np.asarray(self.actions[:k]).reshape(k, -1), scales]
        return np.asarray(self.states[:k]).reshape(k, -1), acts

    def offsets(self, i: int) -> np.ndarray:
        """``(len(TASK_OFFSETS),)`` task offsets at loop tick ``i`` (≥ 0), in
        :data:`~imitwalk.stepconfig.TASK_OFFSETS` order.

        Call :meth:`decide` for step ``k = i // (N/2)`` before its first tick.
        """
        half = self.n / 2.0
        k = int(i // half)
        for done in range(max(self._last_k, 0), k):  # steps finished since the last call:
            self._land[1 - done % 2] = self._landing(done)  # their swing feet have landed
        self._last_k = max(self._last_k, k)
        u = (i - k * half) / half  # progress through the step, 0 → 1
        stance, swing = (0, 1) if k % 2 == 0 else (1, 0)
        m = 1.0 if stance == 0 else -1.0
        c = self.actions[k] if k < len(self.actions) else np.zeros(len(STEP_CHANNELS))
        out = np.zeros(len(TASK_OFFSETS))
        # the stance foot's landing offset (from the previous step) decays over this step
        decay = 1.0 - _smooth(u)
        out[3 * stance : 3 * stance + 3] = self._land[stance] * decay
        # the swing foot grows its landing offset over its swing window [ds, 1) of the step
        sigma = np.clip((u - 2 * self.ds) / (1.0 - 2 * self.ds), 0.0, 1.0)
        out[3 * swing : 3 * swing + 3] = self._landing(k) * _smooth(sigma)
        out[6] = m * c[3] * np.sin(np.pi * u)
        prev = self.actions[k - 1][4] if 0 < k <= len(self.actions) else 0.0
        out[7] = prev + (c[4] - prev) * u
        out[8 + swing] = c[LIFT] * np.sin(np.pi * sigma)  # 0 at lift-off and touch-down
        return out

    def _landing(self, k: int) -> np.ndarray:
        """World-frame landing offset (x, y, yaw) of step ``k``'s swing foot."""
        if k >= len(self.actions):
            return np.zeros(3)
        c = self.actions[k]
        m = 1.0 if k % 2 == 0 else -1.0
        return np.array([c[0], -m * c[1], m * c[2]])


def _smooth(x: float) -> float:
    x = min(max(x, 0.0), 1.0)
    return x * x * (3.0 - 2.0 * x)
