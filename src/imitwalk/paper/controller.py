"""Model-predictive action selection in the embedded action space (paper §5, eqs. 5–13).

Each tick picks the action χ_t = (φ_s, r_s, h_s) that minimises the stability objective
Γ (eq. 6) of the sensory-motor model's prediction F(ω_t, ω_{t−1}, χ_t, χ_{t−1}) (eqs. 5, 7),
over a local box around the gait loop (eqs. 8–13):

    φ_{t−1} < φ_s ≤ φ_{t−1} + ε_φ,  0 < ε_φ < 2π              (9), (12)
    r_a − ε_r ≤ r_s ≤ r_a + ε_r,  h_a − ε_h ≤ h_s ≤ h_a + ε_h   (10), (11)
    [r_a, h_a] = g(φ_s)                                        (13)

The box is searched exhaustively on candidates: a grid of n_φ × n_r × n_h cell midpoints, or
N seeded uniform samples, all inside it. Following "build the problem, then solve it",
:meth:`ActionSelector.build` returns the :class:`SearchProblem` (candidates, their bounds,
predicted states and costs) and :meth:`ActionSelector.solve` takes its minimum. φ is kept
continuous (not wrapped): it enters the model as (cos φ, sin φ) and g is 2π-periodic.
Pure NumPy.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np
from sklearn.exceptions import NotFittedError
from sklearn.utils.validation import check_is_fitted

from imitwalk.errors import ConfigError

if TYPE_CHECKING:
    from imitwalk.paper.embedding import GaitEmbedding

__all__ = ["ActionSelector", "Decision", "SearchProblem", "stability_cost"]


def stability_cost(states: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Γ(ω) = λx ωx² + λy ωy² + λz ωz², eq. (6), one weight per state dim: ``(…, ds) -> (…,)``."""
    return np.asarray(states, dtype=float) ** 2 @ np.asarray(weights, dtype=float)


@dataclass(frozen=True)
class SearchProblem:
    """One tick's search, built but not solved.

    Attributes:
        s_t, s_tm1: ``(ds,)`` current and previous state (e.g. gyro ω [rad/s]).
        a_tm1: ``(3,)`` previous action (φ_{t−1} [rad], r, h).
        actions: ``(M, 3)`` candidates (φ_s, r_s, h_s), eq. (8).
        lower, upper: ``(M, 3)`` each candidate's box: (φ_{t−1}, r_a − ε_r, h_a − ε_h) and
            (φ_{t−1} + ε_φ, r_a + ε_r, h_a + ε_h); φ's lower bound is exclusive (eq. 9).
        nominal: ``(M, 2)`` [r_a, h_a] = g(φ_s), eq. (13), at each candidate's φ_s.
        sequences: ``(M, H, 3)`` action sequences scored over the horizon (first = actions).
        predicted: ``(M, H, ds)`` predicted states s_{t+1} … s_{t+H}.
        costs: ``(M,)`` Σ over the horizon of Γ (eq. 6) of the predicted states.
        weights: ``(ds,)`` the λ of eq. (6).
    """

    s_t: np.ndarray
    s_tm1: np.ndarray
    a_tm1: np.ndarray
    actions: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    nominal: np.ndarray
    sequences: np.ndarray
    predicted: np.ndarray
    costs: np.ndarray
    weights: np.ndarray


@dataclass(frozen=True)
class Decision:
    """The chosen action, eq. (7).

    Attributes:
        action: ``(3,)`` χ*_t = (φ [rad], r, h); predicted: ``(ds,)`` its predicted s_{t+1};
        cost: its objective; index: its row in the problem; n_candidates: M.
    """

    action: np.ndarray
    predicted: np.ndarray
    cost: float
    index: int
    n_candidates: int


def _midpoints(n: int) -> np.ndarray:
    """``(n,)`` centres of n equal cells of (−1, 1); 0 is among them when n is odd."""
    return (2.0 * np.arange(n) + 1.0) / n - 1.0


class _Model(Protocol):
    """What the search needs of a sensory-motor model: a fitted
    :class:`~imitwalk.paper.predictor.SensoryMotorModel`, or anything alike."""

    @property
    def n_state_(self) -> int: ...

    @property
    def n_action_(self) -> int: ...

    def rollout(
        self, s_t: np.ndarray, s_tm1: np.ndarray, actions: np.ndarray, a_tm1: np.ndarray
    ) -> np.ndarray: ...


class ActionSelector:
    """Model-predictive action search, eqs. (5)–(13).

    Args:
        embedding: a fitted :class:`~imitwalk.paper.embedding.GaitEmbedding` (gives g, eq. 13).
        model: a fitted :class:`~imitwalk.paper.predictor.SensoryMotorModel` with 3-D actions (or
            anything with its ``n_state_``, ``n_action_`` and ``rollout``).
        weights: λ of eq. (6), one per state dimension.
        eps_phi: ε_φ [rad], 0 < ε_φ < 2π (eq. 12); eps_r, eps_h: ε_r, ε_h ≥ 0 [subspace units].
        n_phi, n_r, n_h: grid size (M = n_φ n_r n_h), used when ``samples`` is None.
        samples: if set, that many uniform random candidates in the box instead of the grid.
        horizon: H ≥ 1; beyond the first tick each candidate keeps its phase step and its
            offset from the loop: φ_{t+j} = φ_s + j (φ_s − φ_{t−1}), [r, h] = g(φ_{t+j}) + offset.
        random_state: seed of the sampler.
    """

    def __init__(
        self,
        embedding: GaitEmbedding,
        model: _Model,
        *,
        weights: Sequence[float] = (1.0, 1.0, 1.0),
        eps_phi: float,
        eps_r: float,
        eps_h: float,
        n_phi: int = 5,
        n_r: int = 5,
        n_h: int = 5,
        samples: int | None = None,
        horizon: int = 1,
        random_state: int | None = 0,
    ):
        check_is_fitted(embedding)
        if not all(hasattr(model, a) for a in ("n_state_", "n_action_", "rollout")):
            raise NotFittedError("model must be fitted: it needs n_state_, n_action_ and rollout")
        self.embedding, self.model = embedding, model
        self.weights = np.asarray(weights, dtype=float).ravel()
        if self.weights.size != model.n_state_ or np.any(self.weights < 0):
            raise ConfigError(
                f"weights must be {model.n_state_} non-negative numbers (one per state dim)"
            )
        if model.n_action_ != 3:
            raise ConfigError(f"the model's actions must be (φ, r, h), it has {model.n_action_}")
        if not 0.0 < eps_phi < 2.0 * np.pi:
            raise ConfigError(f"eps_phi must be in (0, 2π) (eq. 12), got {eps_phi!r}")
        if not (eps_r >= 0.0 and eps_h >= 0.0):
            raise ConfigError(f"eps_r and eps_h must be >= 0, got {eps_r!r}, {eps_h!r}")
        for name, n in (("n_phi", n_phi), ("n_r", n_r), ("n_h", n_h), ("horizon", horizon)):
            if not isinstance(n, int | np.integer) or n < 1:
                raise ConfigError(f"{name} must be a positive integer, got {n!r}")
        if samples is not None and (not isinstance(samples, int | np.integer) or samples < 1):
            raise ConfigError(f"samples must be None or a positive integer, got {samples!r}")
        self.eps_phi, self.eps_r, self.eps_h = float(eps_phi), float(eps_r), float(eps_h)
        self.n_phi, self.n_r, self.n_h = n_phi, n_r, n_h
        self.samples, self.horizon = samples, horizon
        self._rng = np.random.default_rng(random_state)
        # Grid, φ-major: candidate m = (i, j, l) has φ step dphi[i], offsets (ur[j], uh[l]).
        i, j, l = np.meshgrid(np.arange(n_phi), np.arange(n_r), np.arange(n_h), indexing="ij")
        self._gi = i.ravel()  # (M,)
        self._dphi = self.eps_phi * (np.arange(n_phi) + 0.5) / n_phi  # (n_φ,) in (0, ε_φ)
        self._off = np.column_stack(  # (M, 2) offsets from [r_a, h_a]
            [self.eps_r * _midpoints(n_r)[j.ravel()], self.eps_h * _midpoints(n_h)[l.ravel()]]
        )

    def _candidates(self, phi_prev: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Phase steps ``(M,)``, nominal [r_a, h_a] ``(M, 2)`` and offsets ``(M, 2)``."""
        g = self.embedding.g
        if self.samples is None:
            return self._dphi[self._gi], g(phi_prev + self._dphi)[self._gi], self._off
        u = self._rng.random((self.samples, 3))  # [0, 1)
        dphi = self.eps_phi * (1.0 - u[:, 0])  # (0, ε_φ]
        off = (2.0 * u[:, 1:] - 1.0) * (self.eps_r, self.eps_h)  # [−ε, ε)
        return dphi, g(phi_prev + dphi), off

    def build(self, s_t: np.ndarray, s_tm1: np.ndarray, a_tm1: np.ndarray) -> SearchProblem:
        """Candidates in the box of eqs. (9)–(13), their predicted states and Γ costs.

        Args:
            s_t, s_tm1: ``(ds,)`` current and previous state; a_tm1: ``(3,)`` previous
                action (φ_{t−1} [rad], r, h).
        """
        s_t, s_tm1 = np.asarray(s_t, dtype=float), np.asarray(s_tm1, dtype=float)
        a_tm1 = np.asarray(a_tm1, dtype=float)
        phi_prev = float(a_tm1[0])
        dphi, nominal, off = self._candidates(phi_prev)
        phi = np.maximum(phi_prev + dphi, np.nextafter(phi_prev, np.inf))  # (M,) > φ_{t−1}
        actions = np.column_stack([phi, nominal + off])  # (M, 3)
        M = len(phi)
        eps = np.array([self.eps_r, self.eps_h])
        lower = np.column_stack([np.full(M, phi_prev), nominal - eps])
        upper = np.column_stack([np.full(M, phi_prev + self.eps_phi), nominal + eps])
        if self.horizon == 1:
            seq = actions[:, None, :]  # (M, 1, 3)
        else:
            steps = np.arange(self.horizon)
            phis = phi[:, None] + steps * dphi[:, None]  # (M, H)
            rh = self.embedding.g(phis) + off[:, None, :]  # (M, H, 2)
            seq = np.concatenate([phis[..., None], rh], axis=-1)  # (M, H, 3)
            seq[:, 0] = actions
        predicted = self.model.rollout(s_t, s_tm1, seq, a_tm1)  # (M, H, ds)
        costs = stability_cost(predicted, self.weights).sum(axis=1)  # (M,)
        return SearchProblem(
            s_t=s_t,
            s_tm1=s_tm1,
            a_tm1=a_tm1,
            actions=actions,
            lower=lower,
            upper=upper,
            nominal=nominal,
            sequences=seq,
            predicted=predicted,
            costs=costs,
            weights=self.weights,
        )

    def solve(self, problem: SearchProblem) -> Decision:
        """The candidate of least cost, eq. (7) (the first one on ties)."""
        costs = problem.costs
        finite = np.isfinite(costs)
        if not finite.any():
            raise ValueError("every candidate's predicted cost is NaN or inf")
        i = int(np.argmin(np.where(finite, costs, np.inf)))
        return Decision(
            action=problem.actions[i].copy(),
            predicted=problem.predicted[i, 0].copy(),
            cost=float(costs[i]),
            index=i,
            n_candidates=len(costs),
        )

    def select(self, s_t: np.ndarray, s_tm1: np.ndarray, a_tm1: np.ndarray) -> Decision:
        """:meth:`build` then :meth:`solve`."""
        return self.solve(self.build(s_t, s_tm1, a_tm1))

    def to_posture(self, action: np.ndarray) -> np.ndarray:
        """Action (φ, r, h) to its ``(k,)`` posture-subspace point through the embedding;
        :meth:`~imitwalk.paper.subspace.PostureSubspace.inverse_transform` (C⁺) then gives the
        joint targets [rad]."""
        return self.embedding.from_cylinder(np.asarray(action, dtype=float)[:3])
