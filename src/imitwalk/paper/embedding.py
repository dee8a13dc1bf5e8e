"""Cylindrical gait embedding and the periodic map g(φ) (paper §3.2, eqs. 1–2).

The gait is a closed loop in the posture subspace 𝕏. Centred on the data mean μ, the
loop turns about the principal axis of rotation z_θ (eq. 1); x_θ points along the
largest variance in the plane ⟂ z_θ and y_θ = z_θ × x_θ. A point then has cylindrical
coordinates (φ, r, h): φ the angle in the x_θ–y_θ plane in [0, 2π), r the radius, h the
height along z_θ. The action space is the curve [r, h] = g(φ) (eq. 2), an RBF network on
the circle, so it is periodic in φ by construction.

With ``phase_source="time"`` the loop is parameterised by the reference's time phase
instead, φ := 2π·phase, because at large scales the geometric angle θ of the loop can run
backwards for a while, and then [r, h] is not a function of θ. The periodic map then fits
the loop point itself, (u, v, h) in the (x_θ, y_θ, z_θ) frame, as a function of φ: smooth,
first-harmonic-dominated functions that need no angle unwrapping. From it,
g(φ) = [‖(u, v)‖, h] and the geometric angle θ(φ) = atan2(v, u) (so the offset θ(φ) − φ)
that rebuilds a point. Subspace components beyond the first three follow the phase: they
are fitted as periodic functions of φ as well. Pure NumPy / scikit-learn.
"""

from __future__ import annotations

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted

from imitwalk.errors import ConfigError, unknown_name
from imitwalk.paper.rbf import ridge_lstsq

__all__ = ["PHASE_SOURCES", "GaitEmbedding", "rotation_axis"]

PHASE_SOURCES = ("angle", "time")
TWO_PI = 2.0 * np.pi


def rotation_axis(X: np.ndarray) -> np.ndarray:
    """Principal axis of rotation z_θ of a closed loop, eq. (1).

    Args:
        X: ``(T, 3)`` points of the loop in time order (one or more cycles).
    Returns:
        ``(3,)`` unit vector Σ x̂ⁱ × x̂ⁱ⁺¹ / ‖·‖ over the centred points, the wrap-around
        pair (last, first) included. Its sign makes the loop turn counter-clockwise about
        it, so the angle in a right-handed (x, y, z) frame increases on average.
    """
    Xc = np.asarray(X, dtype=float) - np.mean(X, axis=0)  # (T, 3)
    s = np.cross(Xc, np.roll(Xc, -1, axis=0)).sum(axis=0)  # (3,)
    n = np.linalg.norm(s)
    if not n > 1e-12 * max(1.0, float(np.sum(Xc**2))):
        raise ValueError("the gait loop does not turn about any axis (eq. 1 sums to zero)")
    return s / n


def _kernels(phi: np.ndarray, centers: np.ndarray, inv_s2: float) -> np.ndarray:
    """Gaussian kernels on the unit circle: ``(…,) -> (…, n)``.

    exp(−‖e(φ) − e(c_j)‖² / σ²) with e(φ) = (cos φ, sin φ), i.e. eq. (4) on the circle,
    using ‖e(φ) − e(c)‖² = 2 − 2 cos(φ − c) (a von Mises kernel); 2π-periodic in φ.
    """
    return np.exp((2.0 * np.cos(phi[..., None] - centers) - 2.0) * inv_s2)


class GaitEmbedding(BaseEstimator):
    """Cylindrical embedding of a gait loop with a periodic g(φ) (§3.2, eqs. 1–2).

    Args:
        n_centers: number of kernels of g, evenly spaced on the circle.
        width: kernel width σ in units of the chord between neighbouring centres.
        ridge: ridge penalty on the kernel weights (≥ 0).
        phase_source: ``"angle"`` (φ is the geometric angle, as in the paper) or ``"time"``
            (φ = 2π × the reference's time phase).

    Attributes (after :meth:`fit`):
        mean_: ``(3,)`` μ, mean of the first three subspace coordinates.
        z_axis_, x_axis_, y_axis_: ``(3,)`` unit vectors x_θ, y_θ, z_θ; basis_: ``(3, 3)``
            with rows x_θ, y_θ, z_θ (a right-handed orthonormal frame).
        centers_: ``(n_centers,)`` kernel centres [rad]; sigma_: kernel width (chord units).
        weights_: ``(n_centers, m)``, intercept_: ``(m,)`` output layer; the m outputs
            are r, h (``"angle"``) or u, v, h (``"time"``), then subspace components 4…k.
        train_rmse_: ``(m,)`` RMS residual of those outputs at the training points.
        n_features_in_: k, the subspace dimension (≥ 3).
    """

    def __init__(
        self,
        n_centers: int = 12,
        width: float = 1.0,
        ridge: float = 1e-6,
        phase_source: str = "angle",
    ):
        self.n_centers = n_centers
        self.width = width
        self.ridge = ridge
        self.phase_source = phase_source

    def fit(self, X: np.ndarray, phase: np.ndarray | None = None) -> GaitEmbedding:
        """Fit the frame (eq. 1) and g (eq. 2).

        Args:
            X: ``(T, k)`` posture-subspace points of a closed gait loop in time order
                (one or more whole cycles), k ≥ 3.
            phase: ``(T,)`` time phase in [0, 1) of each point; required, and only used,
                with ``phase_source="time"``.
        """
        if self.phase_source not in PHASE_SOURCES:
            raise unknown_name("phase_source", self.phase_source, PHASE_SOURCES, ConfigError)
        if not isinstance(self.n_centers, int | np.integer) or self.n_centers < 3:
            raise ConfigError(f"n_centers must be an integer >= 3, got {self.n_centers!r}")
        if not self.width > 0 or not self.ridge >= 0:
            raise ConfigError(f"need width > 0 and ridge >= 0, got {self.width!r}, {self.ridge!r}")
        X = np.asarray(X, dtype=float)
        if X.ndim != 2 or X.shape[1] < 3 or len(X) < 3 or not np.all(np.isfinite(X)):
            raise ValueError(f"expected finite (T >= 3, k >= 3) subspace points, got {X.shape}")
        timed = self.phase_source == "time"
        if timed:
            if phase is None:
                raise ValueError("phase_source='time' needs the (T,) time phase of each point")
            phase = np.asarray(phase, dtype=float)
            if phase.shape != (len(X),) or not np.all(np.isfinite(phase)):
                raise ValueError(f"phase must be finite with shape ({len(X)},)")
        elif phase is not None:
            raise ValueError("phase is only used with phase_source='time'")

        self.mean_ = mean = X[:, :3].mean(axis=0)  # (3,)
        Xc = X[:, :3] - mean  # (T, 3)
        z = rotation_axis(Xc)  # eq. (1)
        P = Xc - np.outer(Xc @ z, z)  # projection on the plane ⟂ z
        x = np.linalg.eigh(P.T @ P)[1][:, -1]  # maximal variance in that plane
        x = x - (x @ z) * z
        x /= np.linalg.norm(x)
        x *= np.sign(x[np.argmax(np.abs(x))])  # deterministic sign
        y = np.cross(z, x)
        self.x_axis_, self.y_axis_, self.z_axis_ = x, y, z
        self.basis_ = basis = np.vstack([x, y, z])  # (3, 3) rows x_θ, y_θ, z_θ

        if timed and phase is not None:  # the loop point, (u, v, h), against the time phase
            phi = TWO_PI * np.mod(phase, 1.0)
            L = (X[:, :3] - mean) @ basis.T  # (T, 3) in the (x_θ, y_θ, z_θ) frame
            T = np.column_stack([L, X[:, 3:]])  # (T, m)
        else:  # eq. (2): [r, h] as a function of the angle
            phi, r, h = self._cylinder(X)
            T = np.column_stack([r, h, X[:, 3:]])  # (T, m)

        n = int(self.n_centers)
        self.centers_ = TWO_PI * np.arange(n) / n
        self.sigma_ = float(self.width) * 2.0 * np.sin(np.pi / n)
        Phi = np.hstack([self._features(phi), np.ones((len(phi), 1))])  # (T, n + 1)
        pen = np.r_[np.ones(n, dtype=bool), False]
        W = ridge_lstsq(Phi, T, float(self.ridge), pen)
        self.weights_, self.intercept_ = W[:n], W[n]
        self.train_rmse_ = np.sqrt(np.mean((Phi @ W - T) ** 2, axis=0))
        self.n_features_in_ = X.shape[1]
        self._extra = 3 if timed else 2  # first output column of components 4…k
        if timed:  # dense samples of the fitted loop, to look a point's phase up
            grid = np.linspace(0.0, TWO_PI, max(720, 16 * n), endpoint=False)
            self._grid_phi = grid
            self._grid_loc = self._eval(grid)[:, :3]  # (G, 3)
        return self

    # -- internals -------------------------------------------------------------------
    def _features(self, phi: np.ndarray) -> np.ndarray:
        return _kernels(np.asarray(phi, dtype=float), self.centers_, 1.0 / self.sigma_**2)

    def _eval(self, phi: np.ndarray) -> np.ndarray:
        """All periodic outputs at φ: ``(…,) -> (…, m)``."""
        return self._features(phi) @ self.weights_ + self.intercept_

    def _cylinder(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        L = (X[:, :3] - self.mean_) @ self.basis_.T  # (T, 3) in the (x_θ, y_θ, z_θ) frame
        return np.mod(np.arctan2(L[:, 1], L[:, 0]), TWO_PI), np.hypot(L[:, 0], L[:, 1]), L[:, 2]

    def _rh(self, phi: np.ndarray) -> np.ndarray:
        """[r, h] at φ: ``(…,) -> (…, 2)``."""
        out = self._eval(phi)
        if self._extra == 2:
            return out[..., :2]
        return np.stack([np.hypot(out[..., 0], out[..., 1]), out[..., 2]], axis=-1)

    def _theta(self, phi: np.ndarray) -> np.ndarray:
        if self._extra == 2:
            return phi
        out = self._eval(phi)
        return np.arctan2(out[..., 1], out[..., 0])

    def _local(self, phi: np.ndarray, rh: np.ndarray) -> np.ndarray:
        th = self._theta(phi)
        return np.column_stack([rh[:, 0] * np.cos(th), rh[:, 0] * np.sin(th), rh[:, 1]])

    def _time_phase(self, X: np.ndarray, theta: np.ndarray) -> np.ndarray:
        """φ of each point for ``"time"``: nearest sample of the fitted loop, then bisection
        on θ(φ) = the point's angle within one grid step (kept if that has no root)."""
        L = (X[:, :3] - self.mean_) @ self.basis_.T  # (T, 3)
        G = self._grid_loc
        d2 = np.sum(G**2, axis=1) - 2.0 * (L @ G.T)  # (T, G) squared distance − ‖L‖²
        phi = self._grid_phi[np.argmin(d2, axis=1)]
        step = self._grid_phi[1]

        def f(p: np.ndarray) -> np.ndarray:
            return np.angle(np.exp(1j * (self._theta(p) - theta)))

        lo, hi = phi - step, phi + step
        flo, fhi = f(lo), f(hi)
        ok = (flo * fhi <= 0) & (np.abs(flo - fhi) < np.pi)  # a root, not a ±π wrap
        for _ in range(48):
            mid = 0.5 * (lo + hi)
            fm = f(mid)
            left = (flo * fm) <= 0
            hi, lo = np.where(left, mid, hi), np.where(left, lo, mid)
            flo = np.where(left, flo, fm)
        return np.where(ok, 0.5 * (lo + hi), phi)

    # -- public ----------------------------------------------------------------------
    def g(self, phi: np.ndarray | float) -> np.ndarray:
        """[r, h] = g(φ), eq. (2): ``(…,) [rad] -> (…, 2)``; g(φ) = g(φ + 2π) (up to the
        rounding of φ + 2π). For ``"time"``, r = ‖(u, v)(φ)‖ of the fitted loop point."""
        check_is_fitted(self)
        return self._rh(np.asarray(phi, dtype=float))

    def theta(self, phi: np.ndarray | float) -> np.ndarray:
        """Geometric angle θ(φ) of the loop in the x_θ–y_θ plane [rad]: φ itself for
        ``"angle"``; atan2(v(φ), u(φ)) in (−π, π] for ``"time"``. ``(…,) -> (…,)``."""
        check_is_fitted(self)
        return self._theta(np.asarray(phi, dtype=float))

    def to_cylinder(self, X: np.ndarray) -> np.ndarray:
        """Subspace points to (φ, r, h): ``(T, k) -> (T, 3)``, φ in [0, 2π) [rad].

        For ``"time"``, φ is the phase whose loop point matches the point's angle (the
        nearest branch of the fitted loop); r and h are always the point's own.
        """
        check_is_fitted(self)
        X = np.atleast_2d(np.asarray(X, dtype=float))
        if X.shape[1] != self.n_features_in_:
            raise ValueError(f"expected (T, {self.n_features_in_}) points, got {X.shape}")
        theta, r, h = self._cylinder(X)
        phi = np.mod(self._time_phase(X, theta), TWO_PI) if self._extra == 3 else theta
        return np.column_stack([phi, r, h])

    def from_cylinder(self, phr: np.ndarray) -> np.ndarray:
        """(φ, r, h) to subspace points: ``(T, 3) -> (T, k)`` (or ``(3,) -> (k,)``).

        The first three coordinates are μ + r cos θ x_θ + r sin θ y_θ + h z_θ with
        θ = :meth:`theta` (φ); components 4…k are their fitted periodic functions of φ.
        """
        check_is_fitted(self)
        a = np.asarray(phr, dtype=float)
        P = np.atleast_2d(a)
        if P.ndim != 2 or P.shape[1] != 3:
            raise ValueError(f"expected (T, 3) cylinder coordinates, got {a.shape}")
        Y = self.mean_ + self._local(P[:, 0], P[:, 1:]) @ self.basis_  # (T, 3)
        if self.n_features_in_ > 3:
            Y = np.hstack([Y, self._eval(P[:, 0])[:, self._extra :]])
        return Y[0] if a.ndim == 1 else Y

    def loop(self, n: int = 200) -> np.ndarray:
        """``(n, k)`` points of the fitted gait loop at φ = 2π i / n."""
        phi = TWO_PI * np.arange(n) / n
        return self.from_cylinder(np.column_stack([phi, self.g(phi)]))

    def phase_of(self, X: np.ndarray) -> np.ndarray:
        """Phase of subspace points as a fraction of the cycle, φ / 2π in [0, 1): ``(T,)``."""
        return self.to_cylinder(X)[:, 0] / TWO_PI
