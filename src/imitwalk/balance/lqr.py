"""Feedback gains from the learned model: the eq.-6 objective over a receding horizon.

The paper picks each action by searching a local box for the least predicted gyro
cost Γ (eqs. 5–7). With the per-tick model of :mod:`imitwalk.balance.tickmodel`, which is
linear in (s, a) at each phase, that search has a closed form. Over a horizon of ``H``
ticks it minimises

    Σ_h  λ·s²_{t+h}  +  ρ·a²_{t+h}  +  σ·(a_{t+h} − a_{t+h−1})²            (6) + costs

(``λ``: the eq.-6 weights on the gyro and the tilt weights, named in :class:`Costs`;
``ρ``: the action cost; ``σ``: a cost on changing the action), subject to the model.
The first action of the optimal sequence is a linear function of the model's state
``z = [s_t, s_{t−1}, a_{t−1}]``: ``a_t = K_ψ z``, one gain matrix per loop tick, found
by a Riccati recursion backwards over the next ``H`` ticks' models (the finite-horizon
LQR). The controller applies it, clipped to the box (:mod:`imitwalk.balance.feedback`). The
horizon is short on purpose: the one-tick model is accurate over tens of ticks, not
over a whole cycle (its product over a cycle is not the robot's).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.balance.tickmodel import PhaseModel
from imitwalk.errors import ConfigError

__all__ = ["Costs", "horizon_gains", "state_space"]


@dataclass(frozen=True)
class Costs:
    """The named cost terms (each logged; weights per unit squared).

    Attributes:
        state: ``(d,)`` λ per model state (the gyro's are eq. 6's λx, λy, λz).
        action: ρ, per channel, on a² [per rad²].
        change: σ, per channel, on (a_t − a_{t−1})² [per rad²].
        horizon: H, ticks looked ahead.
    """

    state: tuple[float, ...]
    action: float
    change: float
    horizon: int = 20

    def __post_init__(self) -> None:
        if not all(np.isfinite(self.state)) or min(self.state, default=0.0) < 0:
            raise ConfigError(f"costs.state {self.state}: expected finite weights >= 0")
        if not (self.action > 0 and self.change >= 0):
            raise ConfigError(
                f"costs action={self.action}, change={self.change}: expected > 0 and >= 0"
            )
        if not 1 <= self.horizon <= 1000:
            raise ConfigError(f"costs.horizon={self.horizon}: expected 1..1000 ticks")


def state_space(model: PhaseModel) -> tuple[np.ndarray, np.ndarray]:
    """The model as ``z_{t+1} = A_ψ z_t + B_ψ a_t`` with ``z = [s_t, s_{t−1}, a_{t−1}]``:
    ``A (N, D, D)``, ``B (N, D, m)``, D = 2d + m (the offset is left out: the state is a
    deviation from the nominal walk)."""
    A1, A2, B1, B2 = model.linear()
    N, d, m = A1.shape[0], model.n_states_, model.n_actions_
    D = 2 * d + m
    A = np.zeros((N, D, D))
    A[:, :d, :d], A[:, :d, d : 2 * d], A[:, :d, 2 * d :] = A1, A2, B2
    A[:, d : 2 * d, :d] = np.eye(d)
    B = np.zeros((N, D, m))
    B[:, :d], B[:, 2 * d :] = B1, np.eye(m)
    return A, B


def horizon_gains(model: PhaseModel, costs: Costs) -> np.ndarray:
    """``(N, m, D)`` the gains ``K_ψ`` (``a = K_ψ z``) of the receding-horizon problem.

    Raises:
        ConfigError: ``costs.state`` does not have one weight per model state.
    """
    A, B = state_space(model)
    N, D, m = B.shape
    d = model.n_states_
    if len(costs.state) != d:
        raise ConfigError(f"costs.state has {len(costs.state)} weights; the model has {d} states")
    Q = np.zeros((D, D))
    Q[:d, :d] = np.diag(costs.state)
    S = costs.change * np.eye(m)
    Q[2 * d :, 2 * d :] = S  # σ a_{t-1}² of the change term
    R = (costs.action + costs.change) * np.eye(m)
    cross = np.zeros((D, m))
    cross[2 * d :] = -S  # the −2σ a_{t−1}·a_t of the change term
    K = np.zeros((N, m, D))
    for i in range(N):
        P = Q.copy()
        for h in reversed(range(costs.horizon)):
            j = (i + h) % N
            BtP = B[j].T @ P
            G = BtP @ A[j] + cross.T
            Kj = np.linalg.solve(R + BtP @ B[j], G)
            P = Q + A[j].T @ P @ A[j] - G.T @ Kj
            P = 0.5 * (P + P.T)
        K[i] = -Kj
    return K
