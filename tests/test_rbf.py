"""RBFNetwork: eq. (4) Gaussian RBF network."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from sklearn.exceptions import NotFittedError

from imitwalk.errors import ConfigError
from imitwalk.paper.rbf import COVARIANCES, RBFNetwork


def smooth(A: np.ndarray) -> np.ndarray:
    """A known smooth map R² → R²."""
    return np.column_stack([np.sin(A[:, 0]) * np.cos(A[:, 1]), np.cos(A[:, 0] + 0.5 * A[:, 1])])


def separated_points(seed: int, n: int, d: int) -> np.ndarray:
    """``(n, d)`` points in [−2, 2]^d at least half a typical spacing apart."""
    rng = np.random.default_rng(seed)
    gap = 0.5 * 4.0 / n ** (1.0 / d)
    pts: list[np.ndarray] = []
    while len(pts) < n:
        p = rng.uniform(-2.0, 2.0, d)
        if all(np.linalg.norm(p - q) >= gap for q in pts):
            pts.append(p)
    return np.array(pts)


@pytest.mark.parametrize("covariance", COVARIANCES)
def test_fits_a_known_smooth_function(covariance):
    rng = np.random.default_rng(0)
    A = rng.uniform(-np.pi, np.pi, (500, 2))
    At = rng.uniform(-np.pi, np.pi, (400, 2))
    net = RBFNetwork(n_centers=40, covariance=covariance).fit(A, smooth(A))
    rmse = np.sqrt(np.mean((net.predict(At) - smooth(At)) ** 2))
    assert rmse < 0.05  # the targets' standard deviation is ≈ 0.5–0.7
    assert net.centers_.shape == (40, 2) and net.weights_.shape == (40, 2)


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(2, 30),
    d=st.integers(1, 4),
    covariance=st.sampled_from(COVARIANCES),
)
def test_interpolates_its_centres_when_ridge_vanishes(seed, n, d, covariance):
    A = separated_points(seed, n, d)
    B = np.column_stack([np.sin(A.sum(axis=1)), np.cos(A[:, 0])])
    net = RBFNetwork(n_centers=n, ridge=1e-12, covariance=covariance).fit(A, B)
    np.testing.assert_allclose(net.centers_, A, atol=1e-12)  # N ≤ n_centers: all points
    np.testing.assert_allclose(net.predict(A), B, atol=1e-8)


@pytest.mark.filterwarnings("error")  # k-means warns when asked for more centres than points
@pytest.mark.parametrize("covariance", COVARIANCES)
def test_repeated_rows_make_one_centre_each(covariance):
    # one robot replayed gives the same inputs again: fewer distinct rows than centres
    A = separated_points(3, 10, 2)
    B = np.column_stack([np.sin(A.sum(axis=1)), np.cos(A[:, 0])])
    net = RBFNetwork(n_centers=24, ridge=1e-12, covariance=covariance).fit(
        np.tile(A, (5, 1)), np.tile(B, (5, 1))
    )
    assert net.centers_.shape == (10, 2)
    np.testing.assert_allclose(np.sort(net.centers_, axis=0), np.sort(A, axis=0), atol=1e-12)
    np.testing.assert_allclose(net.predict(A), B, atol=1e-8)


@pytest.mark.parametrize("covariance", COVARIANCES)
def test_predict_is_eq4_with_the_public_parameters(covariance):
    rng = np.random.default_rng(1)
    A = rng.normal(size=(200, 3)) * [1.0, 10.0, 0.1] + [0.0, 5.0, -3.0]
    B = np.sin(A[:, 0]) + A[:, 2]
    net = RBFNetwork(n_centers=15, covariance=covariance).fit(A, B)
    At = A[:20] + 0.1
    diff = At[:, None, :] - net.centers_[None]  # (N, K, d)
    quad = np.einsum("nkd,kde,nke->nk", diff, net.precisions_, diff)
    phi = np.exp(-quad)
    np.testing.assert_allclose(net.features(At), phi, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(net.predict(At), phi @ net.weights_[:, 0] + net.intercept_[0])
    if covariance != "full":  # diagonal precisions
        P = net.precisions_
        np.testing.assert_array_equal(P, P * np.eye(3))
    if covariance == "shared":
        np.testing.assert_allclose(net.precisions_, net.precisions_[:1].repeat(15, axis=0))
    assert np.all(np.linalg.eigvalsh(net.precisions_) > 0)


def test_features_peak_at_their_centres():
    rng = np.random.default_rng(2)
    A = rng.normal(size=(300, 4))
    net = RBFNetwork(n_centers=10).fit(A, A[:, 0])
    F = net.features(net.centers_)
    np.testing.assert_allclose(np.diag(F), 1.0)
    assert np.all((F >= 0) & (F <= 1))


def test_one_dimensional_targets_give_one_dimensional_predictions():
    rng = np.random.default_rng(3)
    A = rng.uniform(-1, 1, (100, 2))
    net = RBFNetwork(n_centers=20).fit(A, A[:, 0] ** 2)
    assert net.predict(A).shape == (100,)
    assert net.n_outputs_ == 1
    net2 = RBFNetwork(n_centers=20).fit(A, (A[:, 0] ** 2)[:, None])
    assert net2.predict(A).shape == (100, 1)
    np.testing.assert_allclose(net2.predict(A)[:, 0], net.predict(A))


def test_linear_terms_capture_a_linear_map():
    rng = np.random.default_rng(4)
    A = rng.normal(size=(300, 3)) * [1.0, 3.0, 0.5] + 2.0
    B = A @ np.array([[1.0, -2.0], [0.5, 0.0], [3.0, 1.0]]) + [0.7, -0.2]
    net = RBFNetwork(n_centers=10, linear=True).fit(A, B)
    At = rng.normal(size=(50, 3)) * [1.0, 3.0, 0.5] + 2.0
    Bt = At @ np.array([[1.0, -2.0], [0.5, 0.0], [3.0, 1.0]]) + [0.7, -0.2]
    np.testing.assert_allclose(net.predict(At), Bt, atol=1e-3)


def test_errors_and_contract():
    with pytest.raises(ConfigError, match="valid: diag, full, shared"):
        RBFNetwork(covariance="spherical").fit(np.zeros((5, 2)), np.zeros(5))
    with pytest.raises(ConfigError, match="width"):
        RBFNetwork(width=0.0).fit(np.zeros((5, 2)), np.zeros(5))
    with pytest.raises(NotFittedError):
        RBFNetwork().predict(np.zeros((1, 2)))
    net = RBFNetwork(n_centers=3)
    A = np.arange(10.0).reshape(5, 2)
    assert net.fit(A, A[:, 0]) is net
    with pytest.raises(ValueError, match="expected"):
        net.predict(np.zeros((2, 3)))
