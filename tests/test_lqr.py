"""Receding-horizon eq.-6 gains from the per-tick model, checked against a hand Riccati
recursion on scalar systems (NumPy)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import solve_discrete_are

from imitwalk.balance.lqr import Costs, horizon_gains, state_space
from imitwalk.balance.tickmodel import PhaseModel
from imitwalk.errors import ConfigError


def _model(A1, A2, B1, B2) -> PhaseModel:
    """A fitted PhaseModel with these per-phase maps ``(N, d, ·)`` (offset 0)."""
    A1, A2, B1, B2 = (np.asarray(x, dtype=float) for x in (A1, A2, B1, B2))
    N, d, m = B1.shape
    model = PhaseModel(n_phases=N)
    model.coef_ = np.concatenate([A1, A2, B1, B2, np.zeros((N, d, 1))], axis=2)
    model.n_states_, model.n_actions_, model.n_samples_ = d, m, 0
    return model


def _scalar(a: float, b: float, n: int = 1) -> PhaseModel:
    """s_{t+1} = a s_t + b a_t at every one of ``n`` phases."""
    return _model(
        np.full((n, 1, 1), a), np.zeros((n, 1, 1)), np.full((n, 1, 1), b), np.zeros((n, 1, 1))
    )


def _hand_riccati(a: float, b: float, q: float, r: float, horizon: int) -> float:
    """The first gain k (a_t = −k s_t) of min Σ q s² + r a² over ``horizon`` steps, the
    cost-to-go starting from the terminal weight q."""
    p = q
    for _ in range(horizon):
        k = b * p * a / (r + b * b * p)
        p = q + a * a * p - a * b * p * k
    return k


@pytest.mark.parametrize(("a", "b"), [(0.9, 0.5), (0.5, -1.0), (0.99, 0.1)])
@pytest.mark.parametrize("horizon", [1, 5, 40])
def test_a_scalar_stable_systems_gain_is_the_hand_riccatis(a, b, horizon):
    q, r = 2.0, 0.3
    K = horizon_gains(_scalar(a, b, n=3), Costs((q,), r, 0.0, horizon))
    assert K.shape == (3, 1, 3)  # a on z = [s_t, s_{t−1}, a_{t−1}]
    np.testing.assert_allclose(K[:, 0, 0], -_hand_riccati(a, b, q, r, horizon), rtol=1e-10)
    np.testing.assert_allclose(K[:, 0, 1:], 0.0, atol=1e-12)  # nothing on the memory


def test_a_long_horizon_is_the_infinite_horizon_gain_and_stabilises():
    for a, b in ((0.9, 0.5), (1.3, 0.4)):  # stable, and unstable
        q, r = 1.0, 0.5
        p = float(solve_discrete_are(np.array([[a]]), np.array([[b]]), [[q]], [[r]])[0, 0])
        k_inf = b * p * a / (r + b * b * p)
        K = horizon_gains(_scalar(a, b), Costs((q,), r, 0.0, 300))
        assert K[0, 0, 0] == pytest.approx(-k_inf, rel=1e-9)
        assert abs(a + b * K[0, 0, 0]) < 1.0  # the closed loop decays


def test_costs_move_the_gain_the_way_they_should():
    model = _scalar(0.95, 0.5)

    def k(state=1.0, action=1.0, change=0.0):
        return horizon_gains(model, Costs((state,), action, change, 20))[0, 0]

    gains = [abs(k(action=r)[0]) for r in (0.1, 1.0, 10.0, 1e6)]
    assert gains == sorted(gains, reverse=True) and gains[-1] < 1e-5  # dearer action: less
    gains = [abs(k(state=q)[0]) for q in (0.0, 0.1, 1.0, 10.0)]
    assert gains == sorted(gains) and gains[0] == 0.0  # dearer state: more; free state: none
    # a cost on changing the action: a smaller gain on the state, and part of the last action
    smooth = k(change=5.0)
    assert abs(smooth[0]) < abs(k()[0]) and 0.0 < smooth[2] < 1.0
    assert smooth[1] == pytest.approx(0.0, abs=1e-12)  # the model has no s_{t−1} term


def test_each_phases_gain_looks_ahead_at_the_next_ticks_models():
    rng = np.random.default_rng(0)
    N, d, m = 8, 2, 2
    A1, A2 = 0.5 * rng.uniform(-1, 1, (N, d, d)), 0.2 * rng.uniform(-1, 1, (N, d, d))
    B1, B2 = rng.uniform(-1, 1, (N, d, m)), 0.2 * rng.uniform(-1, 1, (N, d, m))
    costs = Costs((1.0, 3.0), 0.5, 0.2, 4)
    K = horizon_gains(_model(A1, A2, B1, B2), costs)
    assert K.shape == (N, m, 2 * d + m)
    shifted = horizon_gains(_model(*(np.roll(x, -3, axis=0) for x in (A1, A2, B1, B2))), costs)
    np.testing.assert_allclose(shifted, np.roll(K, -3, axis=0), atol=1e-12)
    # a phase whose next H ticks have no authority gets no gain on the state; what is
    # left is the change cost's pull towards the last action
    B0 = B1.copy()
    B0[2:6] = 0.0
    K0 = horizon_gains(_model(A1, A2, B0, np.zeros_like(B2)), costs)
    np.testing.assert_allclose(K0[2, :, : 2 * d], 0.0, atol=1e-12)
    pull = K0[2, :, 2 * d :]
    np.testing.assert_allclose(pull, pull[0, 0] * np.eye(m), atol=1e-12)
    assert 0.0 < pull[0, 0] < costs.change / (costs.change + costs.action) + 1e-12
    assert np.abs(K0[6, :, : 2 * d]).max() > 1e-3


def test_the_state_space_carries_the_last_state_and_action():
    rng = np.random.default_rng(1)
    A1, A2 = rng.normal(size=(3, 2, 2)), rng.normal(size=(3, 2, 2))
    B1, B2 = rng.normal(size=(3, 2, 1)), rng.normal(size=(3, 2, 1))
    A, B = state_space(_model(A1, A2, B1, B2))
    s, s_prev, a_prev, a = rng.normal(size=2), rng.normal(size=2), rng.normal(size=1), 0.7
    z = np.r_[s, s_prev, a_prev]
    nxt = A[1] @ z + B[1] @ [a]
    np.testing.assert_allclose(nxt[:2], A1[1] @ s + A2[1] @ s_prev + B1[1] @ [a] + B2[1] @ a_prev)
    np.testing.assert_allclose(nxt[2:4], s)
    np.testing.assert_allclose(nxt[4:], [a])


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"state": (1.0, -1.0)}, r"costs.state \(1.0, -1.0\): expected finite weights >= 0"),
        ({"state": (np.nan,)}, "expected finite weights >= 0"),
        ({"action": 0.0}, "costs action=0.0, change=0.0: expected > 0 and >= 0"),
        ({"change": -1.0}, "change=-1.0: expected > 0 and >= 0"),
        ({"horizon": 0}, r"costs.horizon=0: expected 1..1000 ticks"),
        ({"horizon": 1001}, r"costs.horizon=1001: expected 1..1000 ticks"),
    ],
)
def test_bad_costs_are_refused_in_one_line(kwargs, message):
    args = {"state": (1.0,), "action": 1.0, "change": 0.0, **kwargs}
    with pytest.raises(ConfigError, match=message) as err:
        Costs(**args)
    assert len(str(err.value).splitlines()) == 1


def test_one_state_weight_per_model_state():
    with pytest.raises(ConfigError, match=r"costs\.state has 2 weights; the model has 1 states"):
        horizon_gains(_scalar(0.9, 0.5), Costs((1.0, 1.0), 1.0, 0.0))


def test_gains_of_a_fitted_model_are_those_of_the_system_it_was_fitted_on():
    """The learner's path: record, fit the per-tick model, derive the gains."""
    from imitwalk.balance.channels import FEATURES
    from imitwalk.balance.feedback import Episode, FeedbackLaw

    a1, a2, b1, b2, N = 0.9, -0.2, 0.4, 0.1, 10  # a second-order system: no collinear inputs
    rng = np.random.default_rng(3)
    episodes = []
    for _ in range(3):
        act = rng.uniform(-0.1, 0.1, (200, 1))
        s = np.zeros(200)
        s[:2] = 0.1
        for t in range(1, 199):
            s[t + 1] = a1 * s[t] + a2 * s[t - 1] + b1 * act[t, 0] + b2 * act[t - 1, 0]
        f = np.zeros((200, len(FEATURES)))
        f[:, FEATURES.index("gyro_y")] = s
        episodes.append(Episode(np.arange(200) % N, f, act))
    law = FeedbackLaw.zero(("ankle_pitch",), ("gyro_y",), 0.1, n_ticks=N, memory=True)
    fitted = PhaseModel(n_phases=N, ridge=0.0).fit(episodes, law)
    true = _model(*(np.full((N, 1, 1), x) for x in (a1, a2, b1, b2)))
    costs = Costs((1.0,), 0.5, 0.1, 20)
    np.testing.assert_allclose(horizon_gains(fitted, costs), horizon_gains(true, costs), atol=1e-8)
    # without the memory terms the gain on s_t is the hand Riccati's
    plain = _model(*(np.full((N, 1, 1), x) for x in (a1, 0.0, b1, 0.0)))
    K = horizon_gains(plain, Costs((1.0,), 0.5, 0.0, 20))
    np.testing.assert_allclose(K[:, 0, 0], -_hand_riccati(a1, b1, 1.0, 0.5, 20), rtol=1e-10)
