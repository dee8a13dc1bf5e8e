"""SensoryMotorModel: 2nd-order sensory-motor prediction (paper §4, eqs. 3–4)."""

from __future__ import annotations

import numpy as np
import pytest

from imitwalk.errors import ConfigError
from imitwalk.paper.predictor import PredictionReport, SensoryMotorModel, encode_action


def drive(a: np.ndarray) -> np.ndarray:
    """How an action (φ, r, h) pushes the synthetic gyro: ``(T, 3) -> (T, 3)``."""
    return np.column_stack([a[:, 1] * np.cos(a[:, 0]), np.sin(a[:, 0]) * a[:, 2], a[:, 2] ** 2])


def episode(seed: int, T: int = 250) -> tuple[np.ndarray, np.ndarray]:
    """A known 2nd-order, linear-in-state system driven by actions along a gait-like loop:
    s_{t+1} = 1.6 s_t − 0.7 s_{t−1} + 0.3 u(a_t) − 0.2 u(a_{t−1}) + noise."""
    rng = np.random.default_rng(seed)
    phi = rng.uniform(0, 2 * np.pi) + np.cumsum(0.06 + 0.02 * rng.standard_normal(T))
    A = np.column_stack([phi, 1.0 + 0.2 * np.cos(phi), 0.3 * np.sin(2 * phi)])
    A[:, 1:] += 0.05 * rng.standard_normal((T, 2))
    u = drive(A)
    S = np.zeros((T, 3))
    for t in range(1, T - 1):
        S[t + 1] = 1.6 * S[t] - 0.7 * S[t - 1] + 0.3 * u[t] - 0.2 * u[t - 1]
        S[t + 1] += 0.005 * rng.standard_normal(3)
    return S, A


TRAIN = [episode(s) for s in range(6)]
TEST = [episode(100 + s) for s in range(2)]
_CACHE: dict[str, SensoryMotorModel] = {}


def model() -> SensoryMotorModel:
    if "m" not in _CACHE:
        _CACHE["m"] = SensoryMotorModel(n_centers=40).fit(TRAIN)
    return _CACHE["m"]


def test_encode_action_is_periodic_in_phi():
    a = np.array([[0.3, 1.0, -0.2], [0.3 + 2 * np.pi, 1.0, -0.2]])
    e = encode_action(a)
    assert e.shape == (2, 4)
    np.testing.assert_allclose(e[0], e[1], atol=1e-12)
    np.testing.assert_allclose(e[0, :2], [np.cos(0.3), np.sin(0.3)])


def test_learns_a_known_system_better_than_the_no_action_baseline():
    m = model()
    assert m.n_state_ == 3 and m.n_action_ == 3 and m.n_samples_ == 6 * 248
    rep = m.evaluate(TEST)
    assert isinstance(rep, PredictionReport)
    assert np.all(rep.ratio < 0.8)
    assert rep.overall_ratio < 0.7
    assert np.all(rep.r2 > rep.baseline_r2)


def test_report_fields_are_right():
    m = model()
    rep = m.evaluate(TEST)
    s_t, s_tm1, a_t, a_tm1, s_next = [], [], [], [], []
    for S, A in TEST:
        t = np.arange(1, len(S) - 1)
        s_t.append(S[t]), s_tm1.append(S[t - 1]), a_t.append(A[t]), a_tm1.append(A[t - 1])
        s_next.append(S[t + 1])
    s_t, s_tm1, a_t, a_tm1, s_next = map(np.vstack, (s_t, s_tm1, a_t, a_tm1, s_next))
    pred = m.predict(s_t, s_tm1, a_t, a_tm1)
    assert rep.n_samples == len(s_next) == 2 * 248
    np.testing.assert_allclose(rep.rmse, np.sqrt(np.mean((pred - s_next) ** 2, axis=0)))
    np.testing.assert_allclose(rep.baseline_rmse, np.sqrt(np.mean((s_t - s_next) ** 2, axis=0)))
    sst = np.sum((s_next - s_next.mean(axis=0)) ** 2, axis=0)
    np.testing.assert_allclose(rep.r2, 1 - np.sum((pred - s_next) ** 2, axis=0) / sst)
    np.testing.assert_allclose(rep.baseline_r2, 1 - np.sum((s_t - s_next) ** 2, axis=0) / sst)
    np.testing.assert_allclose(rep.ratio, rep.rmse / rep.baseline_rmse)
    overall = np.sqrt(np.mean((pred - s_next) ** 2)) / np.sqrt(np.mean((s_t - s_next) ** 2))
    assert rep.overall_ratio == pytest.approx(overall)
    d = rep.to_dict()
    assert d["n_samples"] == rep.n_samples and len(d["rmse"]) == 3


def test_predict_broadcasts_over_candidates():
    m = model()
    S, A = TEST[0]
    cands = A[50:57]  # (7, 3)
    out = m.predict(S[50], S[49], cands, A[49])
    assert out.shape == (7, 3)
    for i in range(7):
        single = m.predict(S[50], S[49], cands[i], A[49])
        assert single.shape == (3,)
        np.testing.assert_allclose(out[i], single, rtol=1e-12, atol=1e-14)
    shifted = cands + np.array([2 * np.pi, 0.0, 0.0])
    np.testing.assert_allclose(m.predict(S[50], S[49], shifted, A[49]), out, atol=1e-10)


def test_rollout_feeds_predictions_back():
    m = model()
    S, A = TEST[1]
    seqs = np.stack([A[60:64] + 0.01 * i for i in range(5)])  # (5, 4, 3)
    one = m.rollout(S[60], S[59], seqs[:, :1], A[59])
    assert one.shape == (5, 1, 3)
    np.testing.assert_array_equal(one[:, 0], m.predict(S[60], S[59], seqs[:, 0], A[59]))
    four = m.rollout(S[60], S[59], seqs, A[59])
    s, s_prev, a_prev = np.tile(S[60], (5, 1)), np.tile(S[59], (5, 1)), np.tile(A[59], (5, 1))
    for h in range(4):
        nxt = m.predict(s, s_prev, seqs[:, h], a_prev)
        np.testing.assert_allclose(four[:, h], nxt, rtol=1e-12, atol=1e-14)
        s, s_prev, a_prev = nxt, s, seqs[:, h]


def test_predict_delta_is_the_same_function_learned_differently():
    m = SensoryMotorModel(n_centers=40, predict_delta=False).fit(TRAIN)
    rep = m.evaluate(TEST)
    assert np.all(np.isfinite(rep.rmse))
    assert m.network_.n_outputs_ == 3


def test_first_order_and_errors():
    m = SensoryMotorModel(order=1, n_centers=20).fit(TRAIN)
    assert m.n_samples_ == 6 * 249 and m.n_action_ == 3
    assert m.network_.n_features_in_ == 3 + 4
    with pytest.raises(ConfigError, match="order must be 1 or 2"):
        SensoryMotorModel(order=3).fit(TRAIN)
    with pytest.raises(ValueError, match="time-aligned"):
        SensoryMotorModel().fit([(np.zeros((10, 3)), np.zeros((9, 3)))])
    with pytest.raises(ValueError, match="expected states"):
        model().predict(np.zeros(2), np.zeros(2), np.zeros(3), np.zeros(3))
