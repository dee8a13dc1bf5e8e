"""Linear PCA posture subspace 𝕏 (paper §3.1).

A joint-space posture ``q: (n,) [rad]`` maps to the low-dimensional subspace by the
transformation matrix **C**, whose rows are the leading eigenvectors of the motion
covariance (computed by SVD): ``x = C (q − μ)``. The way back is the pseudo-inverse,
``q = C⁺ x + μ``. Pure NumPy / scikit-learn.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from sklearn.base import BaseEstimator, TransformerMixin
from sklearn.decomposition import PCA
from sklearn.utils.validation import check_is_fitted

from imitwalk.errors import ConfigError

__all__ = ["PostureSubspace"]


def _stack(Q: np.ndarray | Sequence[np.ndarray]) -> np.ndarray:
    """One ``(T, n)`` array, or a list of ``(T_i, n)`` arrays stacked along time."""
    if isinstance(Q, np.ndarray):
        parts = [Q]
    else:
        parts = [np.asarray(q, dtype=float) for q in Q]
        if not parts:
            raise ValueError("no trajectories to fit")
    parts = [np.asarray(q, dtype=float) for q in parts]
    if any(q.ndim != 2 for q in parts):
        raise ValueError("each trajectory must be a (T, n) array of joint angles")
    if len({q.shape[1] for q in parts}) != 1:
        raise ValueError("all trajectories must have the same number of joints")
    out = np.concatenate(parts, axis=0)  # (ΣT, n)
    if not np.all(np.isfinite(out)):
        raise ValueError("joint trajectories contain NaN or inf")
    return out


class PostureSubspace(TransformerMixin, BaseEstimator):
    """PCA posture subspace: ``x = C (q − μ)``, ``q = C⁺ x + μ`` (§3.1).

    Args:
        n_components: k, the subspace dimension (the paper uses 3).

    Attributes (after :meth:`fit`):
        mean_: ``(n,)`` mean posture μ [rad].
        components_: **C**, ``(k, n)``; rows are the covariance eigenvectors, sorted by
            decreasing variance.
        C_pinv_: **C⁺**, ``(n, k)`` pseudo-inverse of C (equal to Cᵀ, rows being orthonormal).
        explained_variance_: ``(k,)`` variance along each component [rad²].
        explained_variance_ratio_: ``(k,)`` fraction of the total variance, decreasing.
        n_features_in_: n, the number of joints.
    """

    def __init__(self, n_components: int = 3):
        self.n_components = n_components

    def fit(self, Q: np.ndarray | Sequence[np.ndarray], y: object = None) -> PostureSubspace:
        """Fit the subspace.

        Args:
            Q: ``(T, n)`` joint angles [rad], or a list of such arrays (e.g. one
                reference at several scales) fitted together as one data set.
        """
        k = self.n_components
        if not isinstance(k, int | np.integer) or isinstance(k, bool) or k < 1:
            raise ConfigError(f"n_components must be a positive integer, got {k!r}")
        Q = _stack(Q)  # (T, n)
        if k > min(Q.shape):
            raise ConfigError(
                f"n_components={k} exceeds min(samples, joints)={min(Q.shape)} of the data"
            )
        pca = PCA(n_components=int(k), svd_solver="full").fit(Q)
        self.mean_ = pca.mean_.copy()  # (n,)
        self.components_ = pca.components_.copy()  # (k, n)
        self.C_pinv_ = np.linalg.pinv(self.components_)  # (n, k)
        self.explained_variance_ = pca.explained_variance_.copy()  # (k,)
        self.explained_variance_ratio_ = pca.explained_variance_ratio_.copy()  # (k,)
        self.n_features_in_ = Q.shape[1]
        return self

    def fit_transform(self, Q: np.ndarray | Sequence[np.ndarray], y: object = None) -> np.ndarray:
        """:meth:`fit`, then :meth:`transform` of the stacked data: ``(ΣT, k)``."""
        return self.fit(Q).transform(_stack(Q))

    def transform(self, Q: np.ndarray) -> np.ndarray:
        """Joint angles to subspace points: ``(T, n) [rad] -> (T, k)`` (or ``(n,) -> (k,)``)."""
        check_is_fitted(self)
        Q = np.asarray(Q, dtype=float)
        if Q.shape[-1] != self.n_features_in_ or Q.ndim > 2:
            raise ValueError(f"expected (T, {self.n_features_in_}) joint angles, got {Q.shape}")
        return (Q - self.mean_) @ self.components_.T  # (T, k)

    def inverse_transform(self, X: np.ndarray) -> np.ndarray:
        """Subspace points to joint angles through C⁺: ``(T, k) -> (T, n) [rad]`` (or
        ``(k,) -> (n,)``). Exact inverse of :meth:`transform` on the subspace."""
        check_is_fitted(self)
        X = np.asarray(X, dtype=float)
        k = self.components_.shape[0]
        if X.shape[-1] != k or X.ndim > 2:
            raise ValueError(f"expected (T, {k}) subspace points, got {X.shape}")
        return X @ self.C_pinv_.T + self.mean_  # (T, n)

    def reconstruction_error(self, Q: np.ndarray) -> np.ndarray:
        """Per-joint RMS of ``Q − C⁺ C (Q − μ) − μ``: ``(T, n) -> (n,)`` [rad]."""
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        R = Q - self.inverse_transform(self.transform(Q))  # (T, n)
        return np.sqrt(np.mean(R**2, axis=0))
