"""PostureSubspace: linear PCA of joint trajectories (paper §3.1)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from sklearn.base import clone
from sklearn.exceptions import NotFittedError

from imitwalk.errors import ConfigError
from imitwalk.paper.subspace import PostureSubspace


def low_rank(seed: int, T: int, n: int, rank: int) -> np.ndarray:
    """``(T, n)`` joint angles [rad] of exact rank ``rank`` about a random mean posture."""
    rng = np.random.default_rng(seed)
    Z = rng.normal(size=(T, rank)) * np.geomspace(1.0, 0.2, rank)  # (T, rank)
    W = np.linalg.qr(rng.normal(size=(n, rank)))[0].T  # (rank, n) orthonormal rows
    return rng.uniform(-0.5, 0.5, n) + Z @ W


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(4, 25),
    k=st.integers(1, 4),
    extra_t=st.integers(2, 60),
    data=st.data(),
)
def test_round_trip_reconstructs_low_rank_data(seed, n, k, extra_t, data):
    rank = data.draw(st.integers(1, k))
    Q = low_rank(seed, k + extra_t, n, rank)
    ps = PostureSubspace(n_components=k).fit(Q)
    X = ps.transform(Q)
    assert X.shape == (len(Q), k)
    np.testing.assert_allclose(ps.inverse_transform(X), Q, rtol=0, atol=1e-10)
    assert np.all(ps.reconstruction_error(Q) < 1e-10)


def test_c_pinv_is_the_pseudo_inverse_of_c():
    Q = low_rank(0, 80, 25, 6) + 0.01 * np.random.default_rng(1).normal(size=(80, 25))
    ps = PostureSubspace(3).fit(Q)
    C = ps.components_
    assert C.shape == (3, 25) and ps.C_pinv_.shape == (25, 3) and ps.mean_.shape == (25,)
    np.testing.assert_allclose(ps.C_pinv_, np.linalg.pinv(C), atol=1e-12)
    np.testing.assert_allclose(C @ ps.C_pinv_, np.eye(3), atol=1e-12)
    # Moore–Penrose conditions.
    np.testing.assert_allclose(C @ ps.C_pinv_ @ C, C, atol=1e-12)
    np.testing.assert_allclose(ps.C_pinv_ @ C @ ps.C_pinv_, ps.C_pinv_, atol=1e-12)
    # Rows of C are orthonormal eigenvectors of the covariance, sorted by eigenvalue.
    cov = np.cov(Q.T)
    np.testing.assert_allclose(C @ cov @ C.T, np.diag(ps.explained_variance_), atol=1e-10)


def test_explained_variance_is_sorted_and_a_fraction():
    Q = low_rank(2, 100, 12, 5) + 0.05 * np.random.default_rng(3).normal(size=(100, 12))
    ps = PostureSubspace(4).fit(Q)
    r = ps.explained_variance_ratio_
    assert r.shape == (4,)
    assert np.all(np.diff(r) <= 0) and np.all(r > 0) and r.sum() <= 1.0 + 1e-12


def test_fit_on_a_list_equals_fit_on_the_concatenation():
    base = low_rank(4, 90, 10, 4)
    refs = [0.3 * base, 0.6 * base[:70], 1.0 * base[10:]]
    a = PostureSubspace(3).fit(refs)
    b = PostureSubspace(3).fit(np.concatenate(refs))
    for name in ("mean_", "components_", "C_pinv_", "explained_variance_ratio_"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    np.testing.assert_array_equal(a.fit_transform(refs), b.transform(np.concatenate(refs)))


def test_reconstruction_error_is_per_joint_rms():
    rng = np.random.default_rng(5)
    Q = rng.normal(size=(50, 8))
    ps = PostureSubspace(2).fit(Q)
    R = Q - ps.inverse_transform(ps.transform(Q))
    err = ps.reconstruction_error(Q)
    assert err.shape == (8,)
    np.testing.assert_allclose(err, np.sqrt(np.mean(R**2, axis=0)))
    assert np.all(err > 0)


def test_single_posture_round_trip_keeps_shape():
    Q = low_rank(6, 40, 25, 3)
    ps = PostureSubspace(3).fit(Q)
    x = ps.transform(Q[7])
    assert x.shape == (3,)
    np.testing.assert_allclose(ps.inverse_transform(x), Q[7], atol=1e-10)


def test_estimator_contract_and_errors():
    ps = PostureSubspace(n_components=2)
    assert ps.get_params() == {"n_components": 2}
    assert not hasattr(ps, "mean_")
    with pytest.raises(NotFittedError):
        ps.transform(np.zeros((3, 4)))
    Q = low_rank(7, 30, 6, 3)
    assert ps.fit(Q) is ps
    assert clone(ps).get_params() == ps.get_params()
    with pytest.raises(ConfigError, match="n_components"):
        PostureSubspace(0).fit(Q)
    with pytest.raises(ConfigError, match="n_components"):
        PostureSubspace(7).fit(Q)
    with pytest.raises(ValueError, match="same number of joints"):
        PostureSubspace(2).fit([Q, Q[:, :5]])
    with pytest.raises(ValueError, match="expected"):
        ps.transform(np.zeros((3, 5)))
