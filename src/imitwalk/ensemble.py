"""A bootstrap ensemble of sensory-motor models, for decisions that know what they don't know.

One RBF model F (eqs. 3–4) fitted to a few hundred steps predicts the next step state
about as well as "nothing changes" does for small channel values; a search that trusts
its every wiggle picks channel values that look best only because of the model's error,
and perturbs a walk that would have stood. An ensemble of models fitted to bootstrap
resamples of the recorded episodes (each with its own k-means centres) disagrees where
the data say little. The step search (:class:`imitwalk.balance.StepController`) scores a
candidate by its predicted improvement over the nominal (zero) channels in the *least*
favourable member, so it acts only where every member agrees that acting helps — and
the more data the learner records, the more the members agree and the more it acts.
Pure NumPy / scikit-learn.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted

from imitwalk.errors import ConfigError
from imitwalk.predictor import PredictionReport, SensoryMotorModel, prediction_report

__all__ = ["ModelEnsemble"]


class ModelEnsemble(BaseEstimator):
    """``n_members`` :class:`~imitwalk.predictor.SensoryMotorModel` s on bootstrap resamples.

    Args:
        n_members: ensemble size E (1: one model on all the data, no resampling).
        random_state: seed of the resampling and of each member's k-means.
        **model_params: passed to every :class:`~imitwalk.predictor.SensoryMotorModel`.

    Attributes (after :meth:`fit`):
        members_: the E fitted models; n_state_, n_action_, n_samples_: as a member's.
    """

    def __init__(self, n_members: int = 5, random_state: int | None = 0, **model_params):
        self.n_members = n_members
        self.random_state = random_state
        self.model_params = model_params

    def get_params(self, deep: bool = True) -> dict:
        return {
            "n_members": self.n_members,
            "random_state": self.random_state,
            **self.model_params,
        }

    def fit(self, episodes: Sequence[tuple[np.ndarray, np.ndarray]]) -> ModelEnsemble:
        """Fit every member on a bootstrap resample of ``episodes`` (whole episodes)."""
        if self.n_members < 1:
            raise ConfigError(f"n_members must be at least 1, got {self.n_members!r}")
        episodes = list(episodes)
        rng = np.random.default_rng(self.random_state)
        seed = 0 if self.random_state is None else int(self.random_state)
        self.members_ = []
        for e in range(self.n_members):
            if self.n_members == 1:
                sample = episodes
            else:
                sample = [episodes[i] for i in rng.integers(0, len(episodes), len(episodes))]
            model = SensoryMotorModel(random_state=seed + e, **self.model_params)
            self.members_.append(model.fit(sample))
        first = self.members_[0]
        self.n_state_, self.n_action_ = first.n_state_, first.n_action_
        self.n_samples_ = first.n_samples_
        return self

    def rollout_members(self, s_t, s_tm1, actions, a_tm1) -> np.ndarray:
        """Every member's :meth:`~imitwalk.predictor.SensoryMotorModel.rollout`:
        ``(E, M, H, ds)`` for ``actions`` ``(M, H, da)``."""
        check_is_fitted(self)
        return np.stack([m.rollout(s_t, s_tm1, actions, a_tm1) for m in self.members_])

    def rollout(self, s_t, s_tm1, actions, a_tm1) -> np.ndarray:
        """The members' mean rollout, ``(M, H, ds)``."""
        return self.rollout_members(s_t, s_tm1, actions, a_tm1).mean(axis=0)

    def evaluate(self, episodes) -> PredictionReport:
        """One-step errors of the mean prediction against the no-action baseline."""
        check_is_fitted(self)
        alpha, s_t, s_next, _ = self.members_[0]._tuples(episodes)  # α is the same for all
        pred = np.mean([m._predict_alpha(alpha, s_t) for m in self.members_], axis=0)
        return prediction_report(pred, s_t, s_next)
