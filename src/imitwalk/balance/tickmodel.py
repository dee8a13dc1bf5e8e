"""The paper's second-order sensory-motor model, per tick of the gait (eqs. 3–4; NumPy).

The model predicts the next measured state from the last two states and actions,

    s_{t+1} = F_ψ(s_t, s_{t−1}, a_t, a_{t−1}),                        (3), n = 2

with ``s`` the fed-back features (gyro, tilt ... less their nominal profile) and ``a``
the balance channels. ``F`` is the RBF network of eq. (4) over the gait phase ψ: one
Gaussian kernel centred on every loop tick, each with linear output weights on
``α = [s_t, s_{t−1}, a_t, a_{t−1}, 1]``, so that at phase ψ the prediction is a local
linear model, the kernel-weighted ridge fit of the samples near ψ. That linearity is
what lets :mod:`imitwalk.balance.lqr` turn it into gains. It follows scikit-learn's estimator
contract: hyperparameters in ``__init__``, ``fit`` sets the ``*_`` attributes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted

from imitwalk.balance.feedback import Episode, FeedbackLaw
from imitwalk.errors import ConfigError

__all__ = ["PhaseModel", "Prediction", "nominal_profile", "regressors"]


def nominal_profile(
    episodes: list[Episode], features: tuple[str, ...], n_phases: int
) -> np.ndarray:
    """``(N, d)`` the mean of each feature at each loop tick over ``episodes`` (the walk's
    own profile, which the learned law regulates the deviations from); 0 where a tick
    was never seen."""
    from imitwalk.balance.channels import FEATURES

    pick = [FEATURES.index(f) for f in features]
    total, count = np.zeros((n_phases, len(pick))), np.zeros(n_phases)
    for ep in episodes:
        i = ep.phase % n_phases
        np.add.at(total, i, ep.features[:, pick])
        np.add.at(count, i, 1.0)
    return total / np.maximum(count, 1.0)[:, None]


def regressors(
    episodes: list[Episode], law: FeedbackLaw
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Samples of eq. (3) for ``law``'s states and channels: phases ``(K,)`` of tick t,
    inputs ``(K, 2d + 2m)`` = [s_t, s_{t−1}, a_t, a_{t−1}] and targets ``(K, d)`` =
    s_{t+1}."""
    P, Z, Y = [], [], []
    for ep in episodes:
        if len(ep.phase) < 3:
            continue
        s, a = ep.states(law), ep.actions
        P.append(ep.phase[1:-1])
        Z.append(np.hstack([s[1:-1], s[:-2], a[1:-1], a[:-2]]))
        Y.append(s[2:])
    if not P:
        return np.zeros(0, dtype=int), np.zeros((0, 0)), np.zeros((0, 0))
    return np.concatenate(P), np.vstack(Z), np.vstack(Y)


@dataclass(frozen=True)
class Prediction:
    """A model's one-tick prediction error on episodes it was not fitted on.

    Attributes:
        samples: ticks predicted; mse: ``(d,)`` mean squared error per state;
        persistence_mse: ``(d,)`` that of "nothing changes" (s_{t+1} = s_t);
        ratio: their overall ratio (below 1: the model predicts better).
    """

    samples: int
    mse: np.ndarray
    persistence_mse: np.ndarray
    ratio: float

    def to_dict(self) -> dict:
        """Plain JSON."""
        return {
            "samples": self.samples,
            "mse": self.mse.tolist(),
            "persistence_mse": self.persistence_mse.tolist(),
            "ratio_to_persistence": self.ratio,
        }


class PhaseModel(BaseEstimator):
    """Eqs. (3)–(4) with a kernel per loop tick.

    Args:
        n_phases: loop ticks N (one kernel each); width: the kernels' standard deviation
            [ticks]; ridge: regularisation, relative to each kernel's sample weight.

    Attributes (after :meth:`fit`):
        coef_: ``(N, d, 2d + 2m + 1)`` each tick's linear map of [s_t, s_{t−1}, a_t,
            a_{t−1}, 1] to s_{t+1}; n_states_ (d), n_actions_ (m), n_samples_.
    """

    def __init__(self, n_phases: int = 100, width: float = 2.0, ridge: float = 1e-3):
        self.n_phases = n_phases
        self.width = width
        self.ridge = ridge

    def fit(self, episodes: list[Episode], law: FeedbackLaw) -> PhaseModel:
        """Fit on recorded episodes, with ``law``'s features (less its nominal profile)
        as the states and its channels as the actions."""
        if self.n_phases < 1 or not self.width > 0 or not self.ridge >= 0:
            raise ConfigError(
                f"PhaseModel(n_phases={self.n_phases}, width={self.width}, "
                f"ridge={self.ridge}): expected n_phases >= 1, width > 0, ridge >= 0"
            )
        P, Z, Y = regressors(episodes, law)
        if len(P) == 0:
            raise ValueError("PhaseModel.fit: no episode has 3 or more ticks")
        d = Y.shape[1]
        m = (Z.shape[1] - 2 * d) // 2
        Zc = np.hstack([Z, np.ones((len(Z), 1))])  # (K, D + 1)
        N = self.n_phases
        # sufficient statistics per loop tick, then smoothed around the circle of phases
        G = np.zeros((N, Zc.shape[1], Zc.shape[1]))
        H = np.zeros((N, Zc.shape[1], d))
        count = np.bincount(P % N, minlength=N).astype(float)
        for i in np.unique(P % N):
            sel = P % N == i
            G[i] = Zc[sel].T @ Zc[sel]
            H[i] = Zc[sel].T @ Y[sel]
        lag = (np.arange(N) + N // 2) % N - N // 2
        w = np.exp(-0.5 * (lag / self.width) ** 2)  # (N,) the kernel around tick 0
        W = np.stack([np.roll(w, i) for i in range(N)])  # (N, N) kernel of tick i at j
        Gs, Hs, cs = np.tensordot(W, G, 1), np.tensordot(W, H, 1), W @ count
        eye = np.eye(Zc.shape[1])
        eye[-1, -1] = 0.0  # the offset is not shrunk
        scale = np.trace(Gs, axis1=1, axis2=2) / Zc.shape[1]
        coef = np.zeros((N, d, Zc.shape[1]))
        for i in range(N):
            A = Gs[i] + self.ridge * max(scale[i], 1e-12) * eye
            coef[i] = np.linalg.lstsq(A, Hs[i], rcond=None)[0].T
        self.coef_ = coef
        self.n_states_, self.n_actions_, self.n_samples_ = d, m, len(P)
        self.kernel_samples_ = cs
        return self

    def predict(self, phase: np.ndarray, Z: np.ndarray) -> np.ndarray:
        """``(K, d)`` s_{t+1} for phases ``(K,)`` and inputs ``(K, 2d + 2m)``."""
        check_is_fitted(self, "coef_")
        Zc = np.hstack([Z, np.ones((len(Z), 1))])
        return np.einsum("kij,kj->ki", self.coef_[np.asarray(phase) % self.n_phases], Zc)

    def score_episodes(self, episodes: list[Episode], law: FeedbackLaw) -> Prediction | None:
        """The one-tick prediction error on ``episodes`` against "nothing changes"
        (``None`` if they hold no sample)."""
        P, Z, Y = regressors(episodes, law)
        if len(P) == 0:
            return None
        d = Y.shape[1]
        err = ((self.predict(P, Z) - Y) ** 2).mean(axis=0)
        base = ((Z[:, :d] - Y) ** 2).mean(axis=0)
        return Prediction(len(P), err, base, float(err.sum() / max(base.sum(), 1e-300)))

    def linear(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The per-tick maps of eq. (3): ``A1, A2 (N, d, d)`` on s_t, s_{t−1} and
        ``B1, B2 (N, d, m)`` on a_t, a_{t−1}."""
        check_is_fitted(self, "coef_")
        d, m, c = self.n_states_, self.n_actions_, self.coef_
        return c[:, :, :d], c[:, :, d : 2 * d], c[:, :, 2 * d : 2 * d + m], c[:, :, 2 * d + m : -1]
