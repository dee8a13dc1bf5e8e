"""ActionSelector: model-predictive action search in the embedded action space (§5, eqs. 5–13)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.errors import ConfigError
from imitwalk.paper.controller import ActionSelector, Decision, SearchProblem, stability_cost
from imitwalk.paper.embedding import GaitEmbedding
from imitwalk.paper.predictor import SensoryMotorModel
from imitwalk.paper.subspace import PostureSubspace

TWO_PI = 2.0 * np.pi
_CACHE: dict = {}


def latent_loop(phi: np.ndarray) -> np.ndarray:
    """``(T, 3)`` a gait-like loop in the posture subspace."""
    return np.column_stack([1.4 * np.cos(phi), np.sin(phi), 0.3 * np.sin(2 * phi)])


def embedding() -> GaitEmbedding:
    if "emb" not in _CACHE:
        _CACHE["emb"] = GaitEmbedding().fit(latent_loop(TWO_PI * np.arange(150) / 150))
    return _CACHE["emb"]


def model() -> SensoryMotorModel:
    """A model fitted on a synthetic gyro driven by actions near the loop."""
    if "model" not in _CACHE:
        emb, episodes = embedding(), []
        for seed in range(3):
            rng = np.random.default_rng(seed)
            phi = np.cumsum(0.07 + 0.02 * rng.standard_normal(200))
            A = np.column_stack([phi, emb.g(phi) + 0.04 * rng.standard_normal((200, 2))])
            u = np.column_stack([A[:, 1] * np.cos(phi), A[:, 2], np.sin(phi)])
            S = np.zeros((200, 3))
            for t in range(1, 199):
                S[t + 1] = 1.5 * S[t] - 0.6 * S[t - 1] + 0.2 * u[t] - 0.1 * u[t - 1]
            episodes.append((S, A))
        _CACHE["model"] = SensoryMotorModel(n_centers=20).fit(episodes)
    return _CACHE["model"]


class KnownModel:
    """A stand-in model whose predicted ω is a known function of the action: zero at
    φ_s = φ_{t−1} + 0.7 ε_φ, r_s = r_a + 0.4 ε_r, h_s = h_a − 0.8 ε_h."""

    def __init__(self, emb: GaitEmbedding, eps: tuple[float, float, float]):
        self.emb, self.eps = emb, np.asarray(eps)
        self.n_state_, self.n_action_ = 3, 3

    def fit(self, *args):
        return self

    def rollout(self, s_t, s_tm1, actions, a_tm1):
        phi, r, h = np.moveaxis(actions, -1, 0)  # each (M, H)
        ra, ha = np.moveaxis(self.emb.g(phi), -1, 0)
        return np.stack(
            [
                (phi - a_tm1[0]) / self.eps[0] - 0.7,
                (r - ra) / self.eps[1] - 0.4,
                (h - ha) / self.eps[2] + 0.8,
            ],
            axis=-1,
        )


def check_box(problem: SearchProblem, sel: ActionSelector, action: np.ndarray) -> None:
    """Eqs. (9)–(11) for every candidate and for ``action``, eq. (13) at each φ_s."""
    phi_prev = problem.a_tm1[0]
    for a in [*problem.actions, action]:
        phi, r, h = a
        ra, ha = sel.embedding.g(phi)  # eq. (13) at this candidate's φ_s
        assert phi_prev < phi <= phi_prev + sel.eps_phi  # (9)
        assert ra - sel.eps_r - 1e-12 <= r <= ra + sel.eps_r + 1e-12  # (10)
        assert ha - sel.eps_h - 1e-12 <= h <= ha + sel.eps_h + 1e-12  # (11)
    np.testing.assert_allclose(problem.nominal, sel.embedding.g(problem.actions[:, 0]), atol=1e-12)
    assert np.all(problem.actions[:, 0] > problem.lower[:, 0])
    assert np.all(problem.actions <= problem.upper) and np.all(
        problem.actions[:, 1:] >= problem.lower[:, 1:]
    )


@settings(max_examples=40, deadline=None)
@given(
    s=st.lists(st.floats(-2.0, 2.0), min_size=6, max_size=6),
    phi_prev=st.floats(-20.0, 20.0),
    r_prev=st.floats(0.5, 1.5),
    h_prev=st.floats(-0.4, 0.4),
    eps_phi=st.floats(0.01, 6.28),
    eps_r=st.floats(0.0, 0.3),
    eps_h=st.floats(0.0, 0.3),
    samples=st.one_of(st.none(), st.integers(1, 200)),
    horizon=st.integers(1, 3),
)
def test_never_leaves_the_box(s, phi_prev, r_prev, h_prev, eps_phi, eps_r, eps_h, samples, horizon):
    sel = ActionSelector(
        embedding(),
        model(),
        eps_phi=eps_phi,
        eps_r=eps_r,
        eps_h=eps_h,
        n_phi=3,
        n_r=4,
        n_h=3,
        samples=samples,
        horizon=horizon,
    )
    a_tm1 = np.array([phi_prev, r_prev, h_prev])
    problem = sel.build(s[:3], s[3:], a_tm1)
    decision = sel.solve(problem)
    M = 36 if samples is None else samples
    assert problem.actions.shape == (M, 3) and problem.costs.shape == (M,)
    assert problem.predicted.shape == (M, horizon, 3)
    assert decision.n_candidates == M
    check_box(problem, sel, decision.action)
    # The chosen action has the least cost of the built problem.
    assert decision.cost == problem.costs.min()
    np.testing.assert_array_equal(decision.action, problem.actions[decision.index])


def test_costs_are_eq6_of_the_model_prediction():
    sel = ActionSelector(
        embedding(), model(), weights=(1.0, 2.0, 0.5), eps_phi=0.2, eps_r=0.05, eps_h=0.05
    )
    s_t, s_tm1, a_tm1 = (
        np.array([0.1, -0.2, 0.3]),
        np.array([0.0, -0.1, 0.25]),
        np.array([1.0, 1.2, 0.1]),
    )
    problem = sel.build(s_t, s_tm1, a_tm1)
    assert len(problem.actions) == 125
    pred = model().predict(s_t, s_tm1, problem.actions, a_tm1)  # (M, 3)
    np.testing.assert_allclose(problem.predicted[:, 0], pred, rtol=1e-12, atol=1e-14)
    expected = 1.0 * pred[:, 0] ** 2 + 2.0 * pred[:, 1] ** 2 + 0.5 * pred[:, 2] ** 2
    np.testing.assert_allclose(problem.costs, expected, rtol=1e-12)
    np.testing.assert_allclose(stability_cost(pred, [1.0, 2.0, 0.5]), expected, rtol=1e-12)
    d = sel.select(s_t, s_tm1, a_tm1)
    assert isinstance(d, Decision)
    assert d.index == int(np.argmin(expected)) and d.cost == pytest.approx(expected.min())
    np.testing.assert_allclose(d.predicted, pred[d.index])


def test_picks_the_known_minimiser_on_the_grid():
    eps = (0.3, 0.1, 0.05)
    emb = embedding()
    sel = ActionSelector(emb, KnownModel(emb, eps), eps_phi=eps[0], eps_r=eps[1], eps_h=eps[2])
    a_tm1 = np.array([2.0, 1.0, 0.0])
    d = sel.select(np.zeros(3), np.zeros(3), a_tm1)
    phi = 2.0 + 0.7 * eps[0]  # on the 5×5×5 grid of cell midpoints
    ra, ha = emb.g(phi)
    np.testing.assert_allclose(d.action, [phi, ra + 0.4 * eps[1], ha - 0.8 * eps[2]], atol=1e-12)
    assert d.cost == pytest.approx(0.0, abs=1e-20)


def test_sampled_search_approaches_the_known_minimiser():
    eps = (0.3, 0.1, 0.05)
    emb = embedding()
    sel = ActionSelector(
        emb, KnownModel(emb, eps), eps_phi=eps[0], eps_r=eps[1], eps_h=eps[2], samples=3000
    )
    d = sel.select(np.zeros(3), np.zeros(3), np.array([2.0, 1.0, 0.0]))
    phi, r, h = d.action
    ra, ha = emb.g(phi)
    offsets = np.array(
        [(phi - 2.0) / eps[0] - 0.7, (r - ra) / eps[1] - 0.4, (h - ha) / eps[2] + 0.8]
    )
    assert np.all(np.abs(offsets) < 0.1)  # within 10 % of each half-width


def test_horizon_extends_each_candidate_along_the_loop():
    sel = ActionSelector(
        embedding(), model(), eps_phi=0.2, eps_r=0.05, eps_h=0.05, horizon=3, n_r=3
    )
    s_t, s_tm1, a_tm1 = np.array([0.1, 0.0, -0.1]), np.zeros(3), np.array([0.5, 1.3, 0.0])
    p = sel.build(s_t, s_tm1, a_tm1)
    assert p.sequences.shape == (75, 3, 3)
    np.testing.assert_array_equal(p.sequences[:, 0], p.actions)
    step = p.actions[:, 0] - a_tm1[0]
    np.testing.assert_allclose(p.sequences[:, 2, 0], p.actions[:, 0] + 2 * step)
    off = p.actions[:, 1:] - p.nominal
    np.testing.assert_allclose(
        p.sequences[:, 2, 1:] - embedding().g(p.sequences[:, 2, 0]), off, atol=1e-12
    )
    np.testing.assert_allclose(p.predicted, model().rollout(s_t, s_tm1, p.sequences, a_tm1))
    np.testing.assert_allclose(p.costs, stability_cost(p.predicted, np.ones(3)).sum(axis=1))


def test_the_way_back_to_joint_targets():
    rng = np.random.default_rng(0)
    phi = TWO_PI * np.arange(200) / 200
    W = np.linalg.qr(rng.normal(size=(25, 3)))[0].T  # (3, 25)
    Q = rng.uniform(-0.3, 0.3, 25) + 0.2 * latent_loop(phi) @ W  # (T, 25) joint angles [rad]
    ps = PostureSubspace(3).fit(Q)
    X = ps.transform(Q)
    emb = GaitEmbedding(n_centers=16).fit(X)
    sel = ActionSelector(emb, model(), eps_phi=0.2, eps_r=0.01, eps_h=0.01)
    i = 37
    phi_i = emb.to_cylinder(X[i : i + 1])[0, 0]
    posture = sel.to_posture([phi_i, *emb.g(phi_i)])  # the nominal action at that phase
    assert posture.shape == (3,)
    q = ps.inverse_transform(posture)
    assert q.shape == (25,)
    np.testing.assert_allclose(q, Q[i], atol=2e-3)


def test_configuration_errors():
    emb, m = embedding(), model()
    with pytest.raises(ConfigError, match="weights"):
        ActionSelector(emb, m, weights=(1.0, 1.0), eps_phi=0.1, eps_r=0.1, eps_h=0.1)
    with pytest.raises(ConfigError, match=r"eq\. 12"):
        ActionSelector(emb, m, eps_phi=TWO_PI, eps_r=0.1, eps_h=0.1)
    with pytest.raises(ConfigError, match="eps_r"):
        ActionSelector(emb, m, eps_phi=0.1, eps_r=-0.1, eps_h=0.1)
    with pytest.raises(ConfigError, match="n_phi"):
        ActionSelector(emb, m, eps_phi=0.1, eps_r=0.1, eps_h=0.1, n_phi=0)
    with pytest.raises(TypeError):
        ActionSelector(emb, m)  # the box half-widths have no defaults: they carry units
    four = KnownModel(emb, (1.0, 1.0, 1.0))
    four.n_action_ = 4
    with pytest.raises(ConfigError, match="actions"):
        ActionSelector(emb, four, eps_phi=0.1, eps_r=0.1, eps_h=0.1)
