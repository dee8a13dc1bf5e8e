"""The per-tick model of eqs. 3–4 on synthetic walks whose dynamics are known (NumPy)."""

from __future__ import annotations

import numpy as np
import pytest
from sklearn.exceptions import NotFittedError

from imitwalk.balance.channels import FEATURES
from imitwalk.balance.feedback import Episode, FeedbackLaw
from imitwalk.balance.tickmodel import PhaseModel, nominal_profile, regressors
from imitwalk.errors import ConfigError

#: The synthetic walk: loop ticks, its states (features) and actions (channels).
N = 12
STATES = ("gyro_x", "pitch")
CHANNELS = ("ankle_pitch", "ankle_roll")


def _system(seed: int, per_phase: bool = True):
    """(A1, A2, B1, B2, c) of a stable second-order system, one per phase (or shared)."""
    rng = np.random.default_rng(seed)
    d, m, P = len(STATES), len(CHANNELS), N if per_phase else 1
    A1 = 0.5 * rng.uniform(-1, 1, (P, d, d))
    A2 = 0.2 * rng.uniform(-1, 1, (P, d, d))
    B1 = rng.uniform(-1, 1, (P, d, m))
    B2 = 0.3 * rng.uniform(-1, 1, (P, d, m))
    c = 0.1 * rng.uniform(-1, 1, (P, d))
    return tuple(np.repeat(x, N // P, axis=0) for x in (A1, A2, B1, B2, c))


def _law(nominal=None) -> FeedbackLaw:
    law = FeedbackLaw.zero(CHANNELS, STATES, 0.1, n_ticks=N, memory=True)
    if nominal is not None:
        from dataclasses import replace

        law = replace(law, nominal=nominal)
    return law


def _episodes(system, seed: int, count=4, ticks=300, noise=0.0, nominal=None, first=0):
    """Episodes of ``system``: s_{t+1} = A1 s_t + A2 s_{t−1} + B1 a_t + B2 a_{t−1} + c at the
    phase of tick t, random actions; the features are the states plus ``nominal``."""
    A1, A2, B1, B2, c = system
    rng = np.random.default_rng(seed)
    d, m = len(STATES), len(CHANNELS)
    nominal = np.zeros((N, d)) if nominal is None else nominal
    cols = [FEATURES.index(f) for f in STATES]
    out = []
    for _ in range(count):
        phase = (first + np.arange(ticks)) % N
        a = rng.uniform(-0.1, 0.1, (ticks, m))
        s = np.zeros((ticks, d))
        s[:2] = rng.normal(0, 0.1, (2, d))
        for t in range(1, ticks - 1):
            i = phase[t]
            s[t + 1] = A1[i] @ s[t] + A2[i] @ s[t - 1] + B1[i] @ a[t] + B2[i] @ a[t - 1] + c[i]
            s[t + 1] += rng.normal(0, noise, d) if noise else 0.0
        f = rng.normal(size=(ticks, len(FEATURES)))  # the features the law does not read
        f[:, cols] = s + nominal[phase]
        out.append(Episode(phase, f, a))
    return out


def test_regressors_are_the_second_order_samples_of_eq_3():
    eps = _episodes(_system(0), 1, count=2, ticks=20)
    P, Z, Y = regressors(eps, _law())
    assert P.shape == (36,) and Z.shape == (36, 8) and Y.shape == (36, 2)
    s, a = eps[0].states(_law()), eps[0].actions
    np.testing.assert_array_equal(Z[0], np.r_[s[1], s[0], a[1], a[0]])
    np.testing.assert_array_equal(Y[0], s[2])
    assert P[0] == eps[0].phase[1]
    empty = regressors([Episode(np.zeros(2, int), np.zeros((2, 6)), np.zeros((2, 2)))], _law())
    assert all(len(x) == 0 for x in empty)


def test_a_known_per_phase_linear_system_is_fitted_exactly():
    system = _system(2)
    nominal = np.random.default_rng(3).normal(size=(N, len(STATES)))
    law = _law(nominal)
    eps = _episodes(system, 4, nominal=nominal)
    # narrow kernels: each tick's model is fitted on its own tick's samples
    model = PhaseModel(n_phases=N, width=0.1, ridge=0.0).fit(eps, law)
    assert model.coef_.shape == (N, 2, 2 * 2 + 2 * 2 + 1) and model.n_samples_ == 4 * 298
    assert (model.n_states_, model.n_actions_) == (2, 2)
    for got, true in zip(model.linear(), system[:4], strict=True):
        np.testing.assert_allclose(got, true, atol=1e-8)
    np.testing.assert_allclose(model.coef_[:, :, -1], system[4], atol=1e-8)
    P, Z, Y = regressors(_episodes(system, 5, count=1, nominal=nominal), law)
    np.testing.assert_allclose(model.predict(P, Z), Y, atol=1e-8)
    assert model.score_episodes(_episodes(system, 6, nominal=nominal), law).ratio < 1e-12


def test_a_system_the_same_at_every_phase_is_fitted_exactly_with_wide_kernels():
    system = _system(7, per_phase=False)
    model = PhaseModel(n_phases=N, width=5.0, ridge=0.0).fit(_episodes(system, 8), _law())
    for got, true in zip(model.linear(), system[:4], strict=True):
        np.testing.assert_allclose(got, true, atol=1e-8)


def test_the_model_beats_persistence_on_episodes_it_has_not_seen():
    system = _system(9)
    train = _episodes(system, 10, noise=0.01)
    model = PhaseModel(n_phases=N).fit(train, _law())
    pred = model.score_episodes(_episodes(system, 11, count=2, noise=0.01), _law())
    assert pred.samples == 2 * 298
    assert pred.ratio < 0.5 and np.all(pred.mse < pred.persistence_mse)
    d = pred.to_dict()
    assert set(d) == {"samples", "mse", "persistence_mse", "ratio_to_persistence"}
    assert d["ratio_to_persistence"] == pred.ratio and len(d["mse"]) == 2
    # more noise, a worse fit; never below the noise itself
    noisy = model.score_episodes(_episodes(system, 11, count=2, noise=0.05), _law())
    assert noisy.ratio > pred.ratio and np.all(noisy.mse > 0.9 * 0.05**2)


def test_the_estimator_contract():
    model = PhaseModel(n_phases=5, width=1.5, ridge=0.1)
    assert model.get_params() == {"n_phases": 5, "width": 1.5, "ridge": 0.1}
    with pytest.raises(NotFittedError):
        model.linear()
    with pytest.raises(NotFittedError):
        model.predict(np.zeros(1, int), np.zeros((1, 8)))
    for bad in ({"n_phases": 0}, {"width": 0.0}, {"ridge": -1.0}):
        with pytest.raises(ConfigError, match="expected n_phases >= 1, width > 0, ridge >= 0"):
            PhaseModel(**bad).fit(_episodes(_system(0), 0, count=1, ticks=10), _law())
    short = [Episode(np.zeros(2, int), np.zeros((2, 6)), np.zeros((2, 2)))]
    with pytest.raises(ValueError, match="no episode has 3 or more ticks"):
        PhaseModel().fit(short, _law())
    assert PhaseModel().score_episodes(short, _law()) is None
    assert PhaseModel(n_phases=N).fit(_episodes(_system(0), 0), _law()) is not None


def test_the_nominal_profile_is_each_features_mean_at_each_loop_tick():
    rng = np.random.default_rng(12)
    eps = []
    for first in (0, 5):
        phase = (first + np.arange(17)) % N
        eps.append(Episode(phase, rng.normal(size=(17, len(FEATURES))), np.zeros((17, 1))))
    eps.append(Episode(np.array([3, 3]), rng.normal(size=(2, len(FEATURES))), np.zeros((2, 1))))
    features = ("pitch", "gyro_y")
    prof = nominal_profile(eps, features, N)
    assert prof.shape == (N, 2)
    cols = [FEATURES.index(f) for f in features]
    for i in range(N):
        seen = [e.features[e.phase == i][:, cols] for e in eps]
        np.testing.assert_allclose(prof[i], np.vstack(seen).mean(axis=0))
    # a tick no episode reached is 0; phases beyond the loop wrap around it
    assert not nominal_profile(eps[2:], features, N)[np.arange(N) != 3].any()
    half = nominal_profile(eps, features, N // 2)
    for i in range(N // 2):
        seen = [e.features[e.phase % (N // 2) == i][:, cols] for e in eps]
        np.testing.assert_allclose(half[i], np.vstack(seen).mean(axis=0))
