"""The environment's reward: named, weighted terms, each returned in ``info``.

DeepMimic's tracking terms (Peng et al. 2018, eqs. 6–10) with their kernels, plus an
alive bonus and an action-rate penalty, in the manner of MuJoCo Playground's named
reward scales. Each term is a function of one :class:`TickState`; the reward is
``Σ weight[name] · term[name]``.

=============  ================================================================  ======
term           value                                                             range
=============  ================================================================  ======
pose           exp(−2 Σ (q − q_ref)²)                                            [0, 1]
velocity       exp(−0.1 Σ (q̇ − q̇_ref)²)                                          [0, 1]
end_effector   exp(−40 Σ_soles ‖e − e_ref‖²), e: sole relative to the CoM         [0, 1]
com            exp(−10 ‖v − v_ref‖²), v: the CoM's ground velocity [m/s]          [0, 1]
alive          1 on every tick the robot has not fallen                           1
action_rate    −Σ (a − a_prev)² ÷ the action box's half-width²                    ≤ 0
=============  ================================================================  ======

The references: in ``joints`` mode, the clip retargeted to the robot, by the clock
(:mod:`imitwalk.envs.tracking`); in ``residual`` mode the pose reference is the
stepping gait's own command (it sets its own timing, so the clock's pose would fight
it) and the CoM reference is the style's speed. The rewards read the simulator's ground
truth (CoM, soles), as DeepMimic's do; the policy never sees it.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields

import numpy as np

from imitwalk.errors import ConfigError, unknown_name
from imitwalk.rl.observation import ACTIONS

__all__ = ["TERMS", "RewardWeights", "TickState", "reward_terms", "total"]

#: The reward terms, in the order of the module doc's table.
TERMS = ("pose", "velocity", "end_effector", "com", "alive", "action_rate")


@dataclass(frozen=True)
class TickState:
    """What one tick's reward is computed from.

    Attributes:
        q, q_ref: ``(n,)`` measured and reference joint angles [rad]; dq, dq_ref: ``(n,)``
        their rates [rad/s]; soles, soles_ref: ``(2, 3)`` each sole relative to the CoM
        (:func:`~imitwalk.envs.tracking.sole_offsets`) [m]; com_vel, com_vel_ref: ``(2,)``
        the CoM's ground velocity [m/s]; action, previous: ``(n,)`` this tick's and the
        last tick's action, divided by the box's half-width.
    """

    q: np.ndarray
    q_ref: np.ndarray
    dq: np.ndarray
    dq_ref: np.ndarray
    soles: np.ndarray
    soles_ref: np.ndarray
    com_vel: np.ndarray
    com_vel_ref: np.ndarray
    action: np.ndarray
    previous: np.ndarray


@dataclass(frozen=True)
class RewardWeights:
    """The weight of each term of :data:`TERMS` (see the module doc).

    The defaults are DeepMimic's (pose 0.65, velocity 0.1, end effector 0.15, CoM 0.1),
    which track the clip; :meth:`for_action` gives the residual mode's.
    """

    pose: float = 0.65
    velocity: float = 0.1
    end_effector: float = 0.15
    com: float = 0.1
    alive: float = 0.0
    action_rate: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            bad = isinstance(v, bool) or not isinstance(v, int | float)
            if bad or not np.isfinite(v) or v < 0:
                raise ConfigError(f"reward weight {f.name}={v!r}: must be a finite number ≥ 0")

    @classmethod
    def for_action(cls, action: str) -> RewardWeights:
        """The default weights of ``action`` mode: DeepMimic's for ``joints``; for
        ``residual``, staying up and walking at the style's speed near the stepping
        gait's own command (pose 0.3, CoM 0.4, alive 0.3, action rate 0.05)."""
        if action == "joints":
            return cls()
        if action == "residual":
            return cls(
                pose=0.3, velocity=0.0, end_effector=0.0, com=0.4, alive=0.3, action_rate=0.05
            )
        raise unknown_name("action", action, ACTIONS, ConfigError)

    @classmethod
    def from_dict(cls, d: dict) -> RewardWeights:
        """From ``{term: weight}`` (a one-line :class:`ConfigError` naming the terms for
        an unknown one, or for a weight that is not a number)."""
        if not isinstance(d, dict):
            raise ConfigError(
                f"reward weights {d!r}: expected a {{term: weight}} dictionary "
                f"(terms: {', '.join(TERMS)})"
            )
        for k, v in d.items():
            if k not in TERMS:
                raise unknown_name("reward term", str(k), TERMS, ConfigError)
            if isinstance(v, bool) or not isinstance(v, int | float | np.integer | np.floating):
                raise ConfigError(f"reward weight {k}={v!r}: must be a finite number ≥ 0")
        return cls(**{k: float(v) for k, v in d.items()})

    def to_dict(self) -> dict[str, float]:
        """``{term: weight}``."""
        return asdict(self)


def reward_terms(s: TickState) -> dict[str, float]:
    """Each term of :data:`TERMS` for one tick (unweighted)."""
    return {
        "pose": float(np.exp(-2.0 * np.sum((s.q - s.q_ref) ** 2))),
        "velocity": float(np.exp(-0.1 * np.sum((s.dq - s.dq_ref) ** 2))),
        "end_effector": float(np.exp(-40.0 * np.sum((s.soles - s.soles_ref) ** 2))),
        "com": float(np.exp(-10.0 * np.sum((s.com_vel - s.com_vel_ref) ** 2))),
        "alive": 1.0,
        "action_rate": -float(np.sum((s.action - s.previous) ** 2)),
    }


def total(terms: dict[str, float], weights: RewardWeights) -> float:
    """``Σ weight · term``."""
    w = weights.to_dict()
    return float(sum(w[k] * v for k, v in terms.items()))
