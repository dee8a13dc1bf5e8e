"""Fitting the paper's gyro model from recorded episodes, and assembling its controller.

Pure NumPy: the per-tick gyro model of the paper (actions (φ, r, h)) is a
:class:`~imitwalk.paper.predictor.SensoryMotorModel`, refitted deterministically from
everything recorded so far. Episodes are stored as concatenated arrays plus lengths,
so a run folder holds everything needed to rebuild the controller.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from imitwalk.paper.controller import ActionSelector
from imitwalk.paper.gait import GaitModel
from imitwalk.paper.learnconfig import LearnConfig
from imitwalk.paper.policy import WalkPolicy
from imitwalk.paper.predictor import SensoryMotorModel

__all__ = ["MAX_TICK_SAMPLES", "build_policy", "fit_model", "stack_episodes", "unstack_episodes"]

#: At most this many of the latest tick samples train the gyro model.
MAX_TICK_SAMPLES = 40000


def _latest(episodes: list, cap: int) -> list:
    out, total = [], 0
    for ep in reversed(episodes):
        out.append(ep)
        total += len(ep[0])
        if total >= cap:
            break
    return out[::-1]


def fit_model(episodes: list, config: LearnConfig) -> SensoryMotorModel | None:
    """The gyro model fitted on the latest recorded ``(states, actions)`` episodes
    (``None`` before any episode of more than three ticks)."""
    eps = [e for e in episodes if len(e[0]) > 3]
    if not eps:
        return None
    t = config.tick
    model = SensoryMotorModel(n_centers=t.n_centers, ridge=t.ridge, random_state=config.seed)
    return model.fit(_latest(eps, MAX_TICK_SAMPLES))


def build_policy(
    gait: GaitModel,
    scale: float,
    config: LearnConfig,
    model: SensoryMotorModel | None,
    explore: float = 0.0,
    rng_seed: int | Sequence[int] | None = None,
) -> WalkPolicy:
    """The paper's controller at ``scale`` (the nominal actions until there is a model)."""
    rng = np.random.default_rng(rng_seed) if explore > 0 else None
    r_mean = float(np.mean(gait.nominal[gait.key(scale)][:, 1]))
    t = config.tick
    selector = None
    if model is not None:
        selector = ActionSelector(
            gait.embedding(scale),
            model,
            weights=t.weights,
            eps_phi=t.eps_phi * gait.phase_step(scale),
            eps_r=t.eps_r * r_mean,
            eps_h=t.eps_h * r_mean,
            n_phi=t.grid[0],
            n_r=t.grid[1],
            n_h=t.grid[2],
            horizon=t.horizon,
        )
    noise = (t.explore * explore * t.eps_r * r_mean, t.explore * explore * t.eps_h * r_mean)
    return WalkPolicy(gait, scale, tick_selector=selector, explore=noise, rng=rng)


def stack_episodes(episodes: list) -> dict[str, np.ndarray]:
    """Episodes → arrays for ``data.npz`` (``tick_S``, ``tick_A``, ``tick_len``)."""
    if not episodes:
        return {}
    return {
        "tick_S": np.vstack([e[0] for e in episodes]),
        "tick_A": np.vstack([e[1] for e in episodes]),
        "tick_len": np.array([len(e[0]) for e in episodes]),
    }


def unstack_episodes(arrays: dict[str, np.ndarray]) -> list:
    """Inverse of :func:`stack_episodes`."""
    if "tick_len" not in arrays:
        return []
    cut = np.cumsum(arrays["tick_len"])[:-1]
    return list(zip(np.split(arrays["tick_S"], cut), np.split(arrays["tick_A"], cut), strict=True))
