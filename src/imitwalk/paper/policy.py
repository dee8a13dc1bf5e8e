"""The paper's walking controller, run at every control tick (pure NumPy).

It plays the reference's start-up from standing, then walks the gait loop in the
paper's representation: each tick an action χ_t = (φ, r, h) — the nominal one, or the
one the model-predictive search of eqs. 5–13 picks — goes to joint targets through g
and C⁺. Over the last start-up cycle the output is cross-faded from the start-up
trajectory to the controller's. It records what the learner trains on (the gyro
states and the actions).
"""

from __future__ import annotations

import numpy as np

from imitwalk.paper.controller import ActionSelector
from imitwalk.paper.gait import GaitModel
from imitwalk.sim.types import Observation

__all__ = ["WalkPolicy"]


class WalkPolicy:
    """Per-tick controller; call it as ``policy(tick, observation) -> (n,) targets``.

    Args:
        gait: the gait representation; scale: a schedule scale.
        tick_selector: the paper's per-tick MPC (``None``: follow the nominal actions).
        explore: uniform noise on (r, h), a fraction of the tick box, during training.
        rng: noise source.
    """

    def __init__(
        self,
        gait: GaitModel,
        scale: float,
        tick_selector: ActionSelector | None = None,
        explore: tuple[float, float] = (0.0, 0.0),
        rng: np.random.Generator | None = None,
    ):
        self.gait, self.scale = gait, scale
        self.selector = tick_selector
        self.explore, self.rng = np.asarray(explore, dtype=float), rng
        self.start, self.loop, _ = gait.ref.at_scale(scale)
        self.n = gait.n_ticks
        self.tick_states: list[np.ndarray] = []
        self.tick_actions: list[np.ndarray] = []
        self.tick_predicted: list[float] = []
        self._a_prev: np.ndarray | None = None

    @property
    def first_loop_tick(self) -> int:
        """The first tick at which the paper's controller acts (its actions are recorded
        from here on): the start of the cross-fade cycle, or the end of the start-up."""
        return len(self.start) - (0 if self.gait.config.residual else self.n)

    @property
    def q0(self) -> np.ndarray:
        """``(n,)`` the posture the controller starts from (the start-up's first);
        :func:`imitwalk.sim.mujoco.run` resets the robot to it."""
        return self.start[0]

    def __call__(self, k: int, obs: Observation) -> np.ndarray:
        m, n = len(self.start), self.n
        if k < self.first_loop_tick:
            return self.start[k].copy()
        i = k - m  # loop tick; negative during the cross-fade cycle
        q = self._tick(i, np.asarray(obs.gyro, dtype=float))
        if i < 0:  # cross-fade from the start-up into the controller over one cycle
            w = (i + n) / n
            q = (1.0 - w) * self.start[k] + w * q
        return q

    def _tick(self, i: int, s: np.ndarray) -> np.ndarray:
        """The paper's part: action χ_t (nominal or searched) → joint targets via g, C⁺."""
        nominal = self.gait.nominal_action(self.scale, i)
        if self.selector is not None and self._a_prev is not None and self.tick_states:
            dec = self.selector.select(s, self.tick_states[-1], self._a_prev)
            action = dec.action
            self.tick_predicted.append(dec.cost)
        else:
            action = nominal
        if self.rng is not None and self.explore.any():
            action = action + np.r_[0.0, self.explore * self.rng.uniform(-1, 1, 2)]
        self.tick_states.append(s.copy())
        self.tick_actions.append(action)
        self._a_prev = action
        return self.gait.joints(self.scale, action, i)
