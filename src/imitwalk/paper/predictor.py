"""Second-order sensory-motor model s_{t+1} = F(s_t, s_{t−1}, a_t, a_{t−1}) (paper §4, eqs. 3–4).

The state s is any sensor vector (the paper: the 3-axis torso gyro ω [rad/s]); the action
a = (φ, r, h, *extra) is a point of the cylindrical action space (§3.2), φ [rad] an angle.
φ enters the RBF network (eq. 4) as (cos φ, sin φ), so the model is 2π-periodic in it.
With ``predict_delta`` the network learns the change s_{t+1} − s_t and adds s_t back: the
same function F, a different split of the work between the network and the identity.
Pure NumPy / scikit-learn.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted

from imitwalk.errors import ConfigError
from imitwalk.paper.rbf import RBFNetwork

__all__ = ["PredictionReport", "SensoryMotorModel", "encode_action", "prediction_report"]

Episode = tuple[np.ndarray, np.ndarray]


def encode_action(A: np.ndarray) -> np.ndarray:
    """(φ, r, h, *extra) → (cos φ, sin φ, r, h, *extra): ``(…, da) -> (…, da + 1)``."""
    A = np.asarray(A, dtype=float)
    return np.concatenate([np.cos(A[..., :1]), np.sin(A[..., :1]), A[..., 1:]], axis=-1)


@dataclass(frozen=True)
class PredictionReport:
    """One-step prediction quality on a set of episodes (held out, for an honest figure).

    Attributes:
        n_samples: number of (s_t, s_{t−1}, a_t, a_{t−1}) → s_{t+1} tuples.
        rmse: ``(ds,)`` RMS error of the model per state dimension [state units].
        baseline_rmse: ``(ds,)`` RMS error of the no-action baseline s_{t+1} ≈ s_t.
        r2, baseline_r2: ``(ds,)`` coefficient of determination of each about the mean of
            s_{t+1}; a smooth gyro signal gives the baseline a high R² by autocorrelation.
        ratio: ``(ds,)`` rmse / baseline_rmse; below 1 is authority beyond persistence.
        overall_ratio: the same over all dimensions (RMS over dims of both errors).
    """

    n_samples: int
    rmse: np.ndarray
    baseline_rmse: np.ndarray
    r2: np.ndarray
    baseline_r2: np.ndarray
    ratio: np.ndarray
    overall_ratio: float

    def to_dict(self) -> dict:
        """Plain-JSON dictionary (arrays as lists)."""
        return {k: v.tolist() if isinstance(v, np.ndarray) else v for k, v in asdict(self).items()}


class SensoryMotorModel(BaseEstimator):
    """F: (s_t, s_{t−1}, a_t, a_{t−1}) → s_{t+1}, an RBF network (eqs. 3–4).

    Args:
        order: n of eq. (3); 2 (the paper) or 1 (s_{t−1}, a_{t−1} ignored).
        n_centers, width, ridge, random_state: of the :class:`~imitwalk.paper.rbf.RBFNetwork`.
        predict_delta: learn s_{t+1} − s_t instead of s_{t+1} (same F).
        angle_action: the action's first component is the angle φ, encoded (cos φ, sin φ);
            False for actions without an angle (e.g. the step-level balance channels).
        linear: add linear terms in α to the network (beside the kernels of eq. 4).

    Attributes (after :meth:`fit`):
        network_: the fitted :class:`~imitwalk.paper.rbf.RBFNetwork` on α = [s_t, s_{t−1},
            e(a_t), e(a_{t−1})] with e = :func:`encode_action`.
        n_state_: ds; n_action_: da (raw, φ first); n_samples_: training tuples.
    """

    def __init__(
        self,
        order: int = 2,
        n_centers: int = 40,
        width: float = 1.0,
        ridge: float = 1e-3,
        predict_delta: bool = True,
        random_state: int | None = 0,
        angle_action: bool = True,
        linear: bool = False,
    ):
        self.order = order
        self.angle_action = angle_action
        self.linear = linear
        self.n_centers = n_centers
        self.width = width
        self.ridge = ridge
        self.predict_delta = predict_delta
        self.random_state = random_state

    def _tuples(
        self, episodes: Sequence[Episode]
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[int, int]]:
        """α ``(N, p)``, s_t ``(N, ds)``, s_{t+1} ``(N, ds)`` over all episodes, and (ds, da)."""
        if self.order not in (1, 2):
            raise ConfigError(f"order must be 1 or 2, got {self.order!r}")
        n = self.order
        alphas, cur, nxt, dims = [], [], [], set()
        for S, A in episodes:
            S, A = np.asarray(S, float), np.asarray(A, float)
            S, A = (x[:, None] if x.ndim == 1 else x for x in (S, A))
            if len(S) != len(A) or S.ndim != 2:
                raise ValueError(f"episode S {S.shape} and A {A.shape} must be time-aligned")
            dims.add((S.shape[1], A.shape[1]))
            if len(S) <= n:
                continue
            t = np.arange(n - 1, len(S) - 1)  # ticks with a history and a successor
            alphas.append(self._alpha(S[t], S[t - 1], A[t], A[t - 1]))
            cur.append(S[t])
            nxt.append(S[t + 1])
        if len(dims) > 1:
            raise ValueError(f"episodes differ in state/action sizes: {sorted(dims)}")
        if not alphas:
            raise ValueError(f"no episode is longer than order={n} ticks")
        return np.vstack(alphas), np.vstack(cur), np.vstack(nxt), dims.pop()

    def _alpha(
        self, s_t: np.ndarray, s_tm1: np.ndarray, a_t: np.ndarray, a_tm1: np.ndarray
    ) -> np.ndarray:
        """Network input α, eq. (4): ``(M, 2 ds + 2 (da + 1))`` (order 1: half of it)."""
        enc = encode_action if self.angle_action else (lambda a: np.asarray(a, dtype=float))
        if self.order == 1:
            return np.concatenate([s_t, enc(a_t)], axis=-1)
        return np.concatenate([s_t, s_tm1, enc(a_t), enc(a_tm1)], axis=-1)

    def fit(self, episodes: Sequence[Episode]) -> SensoryMotorModel:
        """Fit F on recorded episodes.

        Args:
            episodes: list of ``(S (T, ds), A (T, da))``: S[t] the state measured at tick t,
                A[t] = (φ, r, h, …) the action applied at tick t, so S[t+1] followed it.
        """
        alpha, s_t, s_next, dims = self._tuples(episodes)
        target = s_next - s_t if self.predict_delta else s_next
        self.network_ = RBFNetwork(
            n_centers=self.n_centers,
            width=self.width,
            ridge=self.ridge,
            linear=self.linear,
            random_state=self.random_state,
        ).fit(alpha, target)
        self.n_state_, self.n_action_ = dims
        self.n_samples_ = len(alpha)
        return self

    def _f(
        self, s_t: np.ndarray, s_tm1: np.ndarray, a_t: np.ndarray, a_tm1: np.ndarray
    ) -> np.ndarray:
        out = self.network_.predict(self._alpha(s_t, s_tm1, a_t, a_tm1))  # (M, ds)
        return out + s_t if self.predict_delta else out

    def predict(
        self, s_t: np.ndarray, s_tm1: np.ndarray, a_t: np.ndarray, a_tm1: np.ndarray
    ) -> np.ndarray:
        """s_{t+1} = F(s_t, s_{t−1}, a_t, a_{t−1}), eq. (3), vectorised over candidates.

        Args:
            s_t, s_tm1: ``(ds,)`` or ``(M, ds)`` states; a_t, a_tm1: ``(da,)`` or
                ``(M, da)`` actions (φ [rad], r, h, …); the leading axes broadcast.
        Returns:
            ``(M, ds)`` predicted next states, or ``(ds,)`` if every input is 1-D.
        """
        check_is_fitted(self)
        args = [np.asarray(x, dtype=float) for x in (s_t, s_tm1, a_t, a_tm1)]
        one = all(x.ndim == 1 for x in args)
        M = max(len(x) if x.ndim == 2 else 1 for x in args)
        s_t, s_tm1, a_t, a_tm1 = (np.broadcast_to(x, (M, x.shape[-1])) for x in args)
        if s_t.shape[1] != self.n_state_ or a_t.shape[1] != self.n_action_:
            raise ValueError(f"expected states of {self.n_state_} and actions of {self.n_action_}")
        out = self._f(s_t, s_tm1, a_t, a_tm1)
        return out[0] if one else out

    def rollout(
        self, s_t: np.ndarray, s_tm1: np.ndarray, actions: np.ndarray, a_tm1: np.ndarray
    ) -> np.ndarray:
        """Multi-step prediction feeding each prediction back as the next state.

        Args:
            s_t, s_tm1: ``(ds,)`` or ``(M, ds)``; a_tm1: ``(da,)`` or ``(M, da)``;
            actions: ``(M, H, da)`` action sequences a_t … a_{t+H−1}.
        Returns:
            ``(M, H, ds)`` predicted states s_{t+1} … s_{t+H}.
        """
        check_is_fitted(self)
        actions = np.asarray(actions, dtype=float)
        M, H, _ = actions.shape
        s, s_prev = (
            np.broadcast_to(np.asarray(x, float), (M, self.n_state_)) for x in (s_t, s_tm1)
        )
        a_prev = np.broadcast_to(np.asarray(a_tm1, float), (M, actions.shape[2]))
        out = np.empty((M, H, self.n_state_))
        for h in range(H):
            out[:, h] = self._f(s, s_prev, actions[:, h], a_prev)
            s, s_prev, a_prev = out[:, h], s, actions[:, h]
        return out

    def rollout_members(
        self, s_t: np.ndarray, s_tm1: np.ndarray, actions: np.ndarray, a_tm1: np.ndarray
    ) -> np.ndarray:
        """:meth:`rollout` as a one-member ensemble: ``(1, M, H, ds)``
        (the interface of :class:`~imitwalk.ensemble.ModelEnsemble`)."""
        return self.rollout(s_t, s_tm1, actions, a_tm1)[None]

    def evaluate(self, episodes: Sequence[Episode]) -> PredictionReport:
        """One-step errors on ``episodes`` against the no-action baseline s_{t+1} ≈ s_t."""
        check_is_fitted(self)
        alpha, s_t, s_next, dims = self._tuples(episodes)
        if dims != (self.n_state_, self.n_action_):
            raise ValueError(
                f"episodes have (ds, da) = {dims}, the model {self.n_state_, self.n_action_}"
            )
        return prediction_report(self._predict_alpha(alpha, s_t), s_t, s_next)

    def _predict_alpha(self, alpha: np.ndarray, s_t: np.ndarray) -> np.ndarray:
        """s_{t+1} from network inputs α ``(N, p)`` (as built by :meth:`_tuples`)."""
        return self.network_.predict(alpha) + (s_t if self.predict_delta else 0.0)


def prediction_report(pred: np.ndarray, s_t: np.ndarray, s_next: np.ndarray) -> PredictionReport:
    """Errors of predictions ``pred`` ``(N, ds)`` of ``s_next`` against s_{t+1} ≈ s_t."""
    err, base = pred - s_next, s_t - s_next  # (N, ds)
    sst = np.sum((s_next - s_next.mean(axis=0)) ** 2, axis=0)
    sst = np.where(sst > 0, sst, np.nan)
    rmse = np.sqrt(np.mean(err**2, axis=0))
    brmse = np.sqrt(np.mean(base**2, axis=0))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = rmse / brmse
        overall = float(np.sqrt(np.mean(err**2)) / np.sqrt(np.mean(base**2)))
    return PredictionReport(
        n_samples=len(pred),
        rmse=rmse,
        baseline_rmse=brmse,
        r2=1.0 - np.sum(err**2, axis=0) / sst,
        baseline_r2=1.0 - np.sum(base**2, axis=0) / sst,
        ratio=ratio,
        overall_ratio=overall,
    )
