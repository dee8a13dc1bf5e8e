"""Radial basis function network, paper eq. (4) (§4).

    β = Σ_k w_k exp(−(α − μ_k)ᵀ Σ_k⁻¹ (α − μ_k))  (+ bias, + optional linear terms)

Centres μ_k come from k-means on standardised inputs (or are all the inputs when there
are no more of them than kernels). Each kernel's covariance Σ_k is built from its
cluster's spread, regularised by the distance to the nearest other centre, and scaled
by ``width``; in standardised units

    Σ_k = width² · (16 S_k + 2 d_k² I)

where S_k is the cluster's covariance (diagonal, full, or one pooled diagonal shared by
all kernels) and d_k the distance from μ_k to its nearest other centre. A kernel thus
reaches 1/e about four cluster standard deviations out, and at least √2 d_k out: the d_k²
term keeps singleton clusters (and interpolating networks) smooth and every Σ_k invertible. Output
weights are regularised least squares (ridge on kernel and linear weights, not on the bias).
Evaluation is fully vectorised. Pure NumPy / scikit-learn.
"""

from __future__ import annotations

import numpy as np
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.cluster import KMeans
from sklearn.utils.validation import check_is_fitted
from threadpoolctl import threadpool_limits  # a scikit-learn dependency

from imitwalk.errors import ConfigError, unknown_name

__all__ = ["COVARIANCES", "RBFNetwork", "ridge_lstsq"]

COVARIANCES = ("diag", "full", "shared")


def ridge_lstsq(Phi: np.ndarray, B: np.ndarray, ridge: float, penalised: np.ndarray) -> np.ndarray:
    """Solve ``min ‖Φ W − B‖² + ridge ‖W[penalised]‖²`` stably (stacked least squares).

    Args:
        Phi: ``(N, p)`` design matrix; B: ``(N, m)`` targets;
        penalised: ``(p,)`` bool, which rows of W carry the ridge penalty.
    Returns:
        W: ``(p, m)``.
    """
    idx = np.flatnonzero(penalised)
    R = np.zeros((idx.size, Phi.shape[1]))
    R[np.arange(idx.size), idx] = np.sqrt(ridge)
    lhs = np.vstack([Phi, R])
    rhs = np.vstack([B, np.zeros((idx.size, B.shape[1]))])
    return np.linalg.lstsq(lhs, rhs, rcond=None)[0]


def _checked_data(A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inputs ``(N, d)`` and targets ``(N,)`` or ``(N, m)`` as float arrays; ValueError if
    their shapes do not fit or they are not finite."""
    A = np.asarray(A, dtype=float)
    B = np.asarray(B, dtype=float)
    if A.ndim != 2 or B.ndim not in (1, 2) or len(B) != len(A) or len(A) == 0:
        raise ValueError(f"expected A (N, d) and B (N,) or (N, m), got {A.shape}, {B.shape}")
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(B))):
        raise ValueError("inputs or targets contain NaN or inf")
    return A, B


def _standardisation(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean and scale ``(d,)`` of the inputs ``A`` ``(N, d)`` (scale 1 on a constant input)."""
    mean = A.mean(axis=0)
    scale = A.std(axis=0)
    scale = np.where(scale > 1e-12 * (1.0 + np.abs(mean)), scale, 1.0)
    return mean, scale


def _nearest_centre_sq(C: np.ndarray, d: int) -> np.ndarray:
    """``(K,)`` squared distance d_k² from each centre of ``C`` ``(K, d)`` to its nearest
    other one (a coincident or lone centre gets the median of the others, else ``d``)."""
    K = len(C)
    D2 = np.sum((C[:, None, :] - C[None, :, :]) ** 2, axis=-1)  # (K, K)
    np.fill_diagonal(D2, np.inf)
    dnn2 = D2.min(axis=1) if K > 1 else np.full(1, np.inf)
    ok = np.isfinite(dnn2) & (dnn2 > 1e-24)
    return np.where(ok, dnn2, np.median(dnn2[ok]) if ok.any() else float(d))


class RBFNetwork(RegressorMixin, BaseEstimator):
    """Gaussian RBF network β = F'(α), eq. (4).

    Args:
        n_centers: K, the number of kernels (fewer if there are fewer samples).
        width: scale of every kernel's covariance (1 = the rule in the module docstring).
        ridge: ridge penalty on the output weights (≥ 0).
        covariance: ``"diag"`` (per-kernel diagonal Σ_k), ``"full"`` (per-kernel full Σ_k)
            or ``"shared"`` (one diagonal Σ for all kernels).
        linear: add linear terms in α to the output.
        random_state: seed of k-means.

    Attributes (after :meth:`fit`), all in input units:
        centers_: ``(K, d)`` kernel means μ_k.
        precisions_: ``(K, d, d)`` inverse covariances Σ_k⁻¹.
        weights_: ``(K, m)`` output weights w_k; intercept_: ``(m,)`` bias.
        linear_coef_: ``(d, m)`` linear weights (zeros unless ``linear``).
        input_mean_, input_scale_: ``(d,)`` standardisation of α used internally.
        n_features_in_: d; n_outputs_: m.
    """

    def __init__(
        self,
        n_centers: int = 40,
        width: float = 1.0,
        ridge: float = 1e-6,
        covariance: str = "diag",
        linear: bool = False,
        random_state: int | None = 0,
    ):
        self.n_centers = n_centers
        self.width = width
        self.ridge = ridge
        self.covariance = covariance
        self.linear = linear
        self.random_state = random_state

    def _check_params(self) -> None:
        if self.covariance not in COVARIANCES:
            raise unknown_name("covariance", self.covariance, COVARIANCES, ConfigError)
        if not isinstance(self.n_centers, int | np.integer) or self.n_centers < 1:
            raise ConfigError(f"n_centers must be a positive integer, got {self.n_centers!r}")
        if not self.width > 0:
            raise ConfigError(f"width must be > 0, got {self.width!r}")
        if not self.ridge >= 0:
            raise ConfigError(f"ridge must be >= 0, got {self.ridge!r}")

    def fit(self, A: np.ndarray, B: np.ndarray) -> RBFNetwork:
        """Fit centres, covariances and output weights.

        Runs single-threaded: at these sizes OpenMP (k-means) and BLAS threads only fight
        each other, which made fits ~25× slower on a 2-core machine.

        Args:
            A: ``(N, d)`` inputs α; B: ``(N, m)`` or ``(N,)`` targets β.
        """
        with threadpool_limits(limits=1):
            return self._fit(A, B)

    def _fit(self, A: np.ndarray, B: np.ndarray) -> RBFNetwork:
        self._check_params()
        A, B = _checked_data(A, B)
        self._1d, self._linear = B.ndim == 1, bool(self.linear)
        B2 = B.reshape(len(B), -1)  # (N, m)
        d = A.shape[1]
        mean, scale = _standardisation(A)
        Z = (A - mean) / scale  # (N, d) standardised
        C, labels = self._centres(Z)
        K = len(C)
        dnn2 = _nearest_centre_sq(C, d)
        P = self._set_precisions(Z, C, labels, dnn2)
        self.input_mean_, self.input_scale_ = mean, scale
        self.n_features_in_ = d
        self.n_outputs_ = B2.shape[1]
        self._fit_weights(Z, B2, K, mean, scale)
        self.centers_ = mean + C * scale  # (K, d)
        self.precisions_ = P / np.outer(scale, scale)  # (K, d, d) Σ_k⁻¹ in input units
        return self

    def _centres(self, Z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Kernel centres ``(K, d)`` and each input's centre ``(N,)`` for standardised
        inputs ``Z`` ``(N, d)``: every input if there are few, else k-means."""
        N = len(Z)
        distinct, inverse = np.unique(Z, axis=0, return_inverse=True)
        if N <= self.n_centers:
            C, labels = Z.copy(), np.arange(N)
        elif len(distinct) <= self.n_centers:  # repeated rows (e.g. one robot, replayed)
            C = distinct  # every distinct input a centre; k-means would warn and duplicate
            labels = inverse.reshape(-1)
        else:
            km = KMeans(n_clusters=int(self.n_centers), n_init=3, random_state=self.random_state)
            km.fit(Z)
            C, labels = km.cluster_centers_, km.labels_
        return C, labels

    def _set_precisions(
        self, Z: np.ndarray, C: np.ndarray, labels: np.ndarray, dnn2: np.ndarray
    ) -> np.ndarray:
        """Each kernel's precision Σ_k⁻¹ ``(K, d, d)`` in standardised units, from its
        cluster's spread and ``dnn2`` ``(K,)``; sets the products :meth:`_kernels` uses."""
        K, d = len(C), Z.shape[1]
        dev = Z - C[labels]  # (N, d) deviation from own centre
        counts = np.bincount(labels, minlength=K).astype(float)  # (K,)
        w2 = self.width**2
        if self.covariance == "full":
            S = np.zeros((K, d, d))
            np.add.at(S, labels, dev[:, :, None] * dev[:, None, :])
            S /= np.maximum(counts, 1.0)[:, None, None]
            Sigma = w2 * (16.0 * S + 2.0 * dnn2[:, None, None] * np.eye(d))  # (K, d, d)
            P = np.linalg.inv(Sigma)
            P = 0.5 * (P + np.swapaxes(P, 1, 2))  # (K, d, d)
            self._pflat = P.reshape(K, d * d)  # (K, d²)
            self._cp = np.einsum("kde,ke->kd", P, C)  # (K, d): Σ_k⁻¹ μ_k
            self._c2p = np.sum(C * self._cp, axis=1)  # (K,)
            self._pdiag = None
        else:
            if self.covariance == "diag":
                V = np.zeros((K, d))
                np.add.at(V, labels, dev**2)
                V /= np.maximum(counts, 1.0)[:, None]
                var = w2 * (16.0 * V + 2.0 * dnn2[:, None])  # (K, d)
            else:
                v = np.mean(dev**2, axis=0)  # (d,) pooled within-cluster variance
                var = np.tile(w2 * (16.0 * v + 2.0 * np.mean(dnn2)), (K, 1))  # (K, d)
            self._pdiag = 1.0 / var  # (K, d)
            self._cp = C * self._pdiag  # (K, d)
            self._c2p = np.sum(C * self._cp, axis=1)  # (K,)
            P = np.einsum("kd,de->kde", self._pdiag, np.eye(d))
        return P

    def _fit_weights(
        self, Z: np.ndarray, B2: np.ndarray, K: int, mean: np.ndarray, scale: np.ndarray
    ) -> None:
        """Output weights, linear terms and bias by ridge least squares on ``Z`` ``(N, d)``
        -> ``B2`` ``(N, m)``, in input units (``mean``, ``scale`` ``(d,)``)."""
        d = Z.shape[1]
        Phi = self._design(Z)  # (N, K + 1 [+ d])
        pen = np.ones(Phi.shape[1], dtype=bool)
        pen[K] = False  # bias column
        W = ridge_lstsq(Phi, B2, float(self.ridge), pen)
        self.weights_ = W[:K]  # (K, m)
        lin = W[K + 1 :] / scale[:, None] if self._linear else np.zeros((d, B2.shape[1]))
        self.linear_coef_ = lin  # (d, m) in input units
        self.intercept_ = W[K] - mean @ lin  # (m,)

    def _kernels(self, Z: np.ndarray) -> np.ndarray:
        """Eq. (4) kernel activations for standardised inputs: ``(N, d) -> (N, K)``."""
        # (z − μ)ᵀ P (z − μ) = zᵀ P z − 2 zᵀ P μ + μᵀ P μ, as matrix products (N, K).
        if self._pdiag is not None:
            zpz = (Z * Z) @ self._pdiag.T
        else:
            zpz = (Z[:, :, None] * Z[:, None, :]).reshape(len(Z), -1) @ self._pflat.T
        q = zpz - 2.0 * (Z @ self._cp.T) + self._c2p
        return np.exp(-np.maximum(q, 0.0))

    def _design(self, Z: np.ndarray) -> np.ndarray:
        cols = [self._kernels(Z), np.ones((len(Z), 1))]
        if self._linear:
            cols.append(Z)
        return np.hstack(cols)

    def _standardise(self, A: np.ndarray) -> np.ndarray:
        A = np.asarray(A, dtype=float)
        if A.ndim != 2 or A.shape[1] != self.n_features_in_:
            raise ValueError(f"expected (N, {self.n_features_in_}) inputs, got {A.shape}")
        return (A - self.input_mean_) / self.input_scale_

    def features(self, A: np.ndarray) -> np.ndarray:
        """Kernel activations exp(−(α−μ_k)ᵀ Σ_k⁻¹ (α−μ_k)) of eq. (4): ``(N, d) -> (N, K)``."""
        check_is_fitted(self)
        return self._kernels(self._standardise(A))

    def predict(self, A: np.ndarray) -> np.ndarray:
        """β for each input: ``(N, d) -> (N, m)``, or ``(N,)`` if fitted on 1-D targets."""
        check_is_fitted(self)
        A = np.asarray(A, dtype=float)
        out = self._kernels(self._standardise(A)) @ self.weights_ + self.intercept_
        if self._linear:
            out = out + A @ self.linear_coef_
        return out[:, 0] if self._1d else out
