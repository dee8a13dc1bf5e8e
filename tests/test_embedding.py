"""GaitEmbedding: cylindrical frame (eq. 1) and the periodic g(φ) (eq. 2), paper §3.2."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.errors import ConfigError
from imitwalk.paper.embedding import GaitEmbedding, rotation_axis

TWO_PI = 2.0 * np.pi


def circular_error(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|a − b| on the circle [rad]."""
    return np.abs(np.angle(np.exp(1j * (a - b))))


def frame(axis: np.ndarray, seed: int) -> np.ndarray:
    """``(3, 3)`` rows u, v, axis: a right-handed orthonormal frame around ``axis``."""
    z = axis / np.linalg.norm(axis)
    t = np.random.default_rng(seed).normal(size=3)
    u = t - (t @ z) * z
    u /= np.linalg.norm(u)
    return np.vstack([u, np.cross(z, u), z])


def gait_loop(phi: np.ndarray, back: float = 0.0, aspect: float = 1.3) -> np.ndarray:
    """``(T, 5)`` synthetic gait loop: angle θ = φ + back·sin 2φ (runs backwards where
    1 + 2 back cos 2φ < 0), radius and height varying with φ, two components following φ."""
    th = phi + back * np.sin(2 * phi)
    r = 1.0 + 0.15 * np.cos(phi)
    return np.column_stack(
        [
            aspect * r * np.cos(th),
            r * np.sin(th),
            0.3 * np.sin(2 * phi + 0.5),
            0.1 * np.sin(phi),
            0.05 * np.cos(2 * phi),
        ]
    )


unit_vectors = st.tuples(*[st.floats(-1, 1)] * 3).filter(lambda v: np.linalg.norm(v) > 0.2)


@settings(max_examples=40, deadline=None)
@given(axis=unit_vectors, seed=st.integers(0, 2**31 - 1), cycles=st.integers(1, 3))
def test_eq1_recovers_the_rotation_axis_of_a_tilted_noisy_ellipse(axis, seed, cycles):
    rng = np.random.default_rng(seed)
    B = frame(np.array(axis), seed)  # rows: major axis, minor axis, rotation axis
    t = TWO_PI * cycles * np.arange(120 * cycles) / (120 * cycles)
    E = np.column_stack([2.0 * np.cos(t), np.sin(t), np.zeros_like(t)])  # counter-clockwise
    X = E @ B + rng.normal(size=3) + 0.02 * rng.normal(size=(len(t), 3))
    emb = GaitEmbedding().fit(X)
    assert emb.z_axis_ @ B[2] > 0.999  # the right axis, with the sign of the rotation
    assert abs(emb.x_axis_ @ B[0]) > 0.999  # x along the major axis
    np.testing.assert_allclose(emb.basis_ @ emb.basis_.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(emb.basis_) == pytest.approx(1.0)
    dphi = np.angle(np.exp(1j * np.diff(emb.to_cylinder(X)[:, 0])))
    assert dphi.mean() > 0  # φ increases along the loop
    # Traversed the other way round, the axis flips.
    np.testing.assert_allclose(rotation_axis(X[::-1]), -rotation_axis(X), atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(phi=st.floats(-50.0, 50.0), turns=st.integers(-3, 3))
def test_g_is_periodic(phi, turns):
    emb = _angle_embedding()
    a = emb.g(phi)
    assert a.shape == (2,)
    np.testing.assert_allclose(emb.g(phi + TWO_PI * turns), a, rtol=0, atol=1e-12)


def test_g_passes_through_its_training_points():
    emb = _angle_embedding()
    X = gait_loop(TWO_PI * np.arange(200) / 200)
    phr = emb.to_cylinder(X)
    np.testing.assert_allclose(emb.g(phr[:, 0]), phr[:, 1:], atol=2e-3)
    assert np.all(emb.train_rmse_ < 1e-3)
    assert emb.g(np.zeros((4, 5))).shape == (4, 5, 2)


def test_cylinder_round_trip_on_the_loop():
    emb = _angle_embedding()
    L = emb.loop(300)  # points of the fitted loop, all 5 components
    assert L.shape == (300, 5)
    phr = emb.to_cylinder(L)
    np.testing.assert_allclose(phr[:, 0], TWO_PI * np.arange(300) / 300, atol=1e-9)
    np.testing.assert_allclose(emb.from_cylinder(phr), L, atol=1e-9)
    X = gait_loop(TWO_PI * np.arange(200) / 200)  # the training points: on it up to the fit
    np.testing.assert_allclose(emb.from_cylinder(emb.to_cylinder(X)), X, atol=2e-3)
    assert emb.from_cylinder(phr[0]).shape == (5,)
    np.testing.assert_allclose(emb.phase_of(L), np.arange(300) / 300, atol=1e-9)


def test_time_phase_follows_a_loop_whose_angle_runs_backwards():
    phase = np.mod(np.arange(400) / 200, 1.0)  # two cycles
    X = gait_loop(TWO_PI * phase, back=0.6)
    # Check the premise: the geometric angle does go backwards for a while.
    th = np.unwrap(np.arctan2(X[:, 1], X[:, 0]))
    assert (np.diff(th) < 0).mean() > 0.1
    emb = GaitEmbedding(n_centers=16, phase_source="time").fit(X, phase)
    phi = TWO_PI * phase
    rebuilt = emb.from_cylinder(np.column_stack([phi, emb.g(phi)]))
    time_err = np.abs(rebuilt - X).max()
    assert time_err < 0.02
    np.testing.assert_allclose(emb.g(phi + TWO_PI), emb.g(phi), atol=1e-12)
    phr = emb.to_cylinder(X)
    assert circular_error(phr[:, 0], phi).max() < 0.05
    assert circular_error(TWO_PI * emb.phase_of(X), phi).max() < 0.05
    np.testing.assert_allclose(emb.from_cylinder(phr), X, atol=0.01)
    # The paper's angle parameterisation cannot represent this loop as well.
    ang = GaitEmbedding(n_centers=16).fit(X)
    p = ang.to_cylinder(X)[:, 0]
    angle_err = np.abs(ang.from_cylinder(np.column_stack([p, ang.g(p)])) - X).max()
    assert angle_err > 5 * time_err


def test_errors():
    X = gait_loop(TWO_PI * np.arange(50) / 50)
    with pytest.raises(ConfigError, match="valid: angle, time"):
        GaitEmbedding(phase_source="clock").fit(X)
    with pytest.raises(ValueError, match="time phase"):
        GaitEmbedding(phase_source="time").fit(X)
    with pytest.raises(ValueError, match="only used"):
        GaitEmbedding().fit(X, np.zeros(50))
    line = np.outer(np.linspace(-1, 1, 20), [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="does not turn"):
        GaitEmbedding().fit(line)
    with pytest.raises(ValueError, match="k >= 3"):
        GaitEmbedding().fit(X[:, :2])


_CACHE: dict[str, GaitEmbedding] = {}


def _angle_embedding() -> GaitEmbedding:
    if "angle" not in _CACHE:
        X = gait_loop(TWO_PI * np.arange(200) / 200)
        _CACHE["angle"] = GaitEmbedding(n_centers=24).fit(X)
    return _CACHE["angle"]
