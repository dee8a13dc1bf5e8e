"""The pendulum and DCM maths of the stepping gait (pure NumPy, property tests)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.step.lipm import NominalGait, dcm_after, dcm_before, lipm_step, omega_of

coord = st.floats(-0.2, 0.2)
pts = st.tuples(coord, coord).map(np.array)


@given(xi=pts, a=pts, b=pts, h=st.floats(0.01, 0.8), z=st.floats(0.1, 1.0))
@settings(max_examples=60, deadline=None)
def test_dcm_before_inverts_dcm_after(xi, a, b, h, z):
    w = omega_of(z)
    end = dcm_after(xi, a, b, h, w)
    assert np.allclose(dcm_before(end, a, b, h, w), xi, atol=1e-9)


@given(c=pts, v=pts, p=pts)
@settings(max_examples=40, deadline=None)
def test_lipm_step_moves_the_dcm_as_its_first_order_law(c, v, p):
    w, dt = omega_of(0.25), 0.01
    c1, v1 = lipm_step(c, v, p, dt, w)
    assert np.allclose(c1 + v1 / w, dcm_after(c + v / w, p, p, dt, w), atol=1e-12)


def test_dcm_after_matches_a_fine_integration():
    w, xi, a, b, h = (
        omega_of(0.23),
        np.array([0.01, -0.02]),
        np.zeros(2),
        np.array([0.03, 0.0]),
        0.4,
    )
    x, n = xi.copy(), 40000
    for k in range(n):
        p = a + (b - a) * (k + 0.5) / n
        x = x + w * (x - p) * h / n
    assert np.allclose(x, dcm_after(xi, a, b, h, w), rtol=1e-3, atol=1e-6)


def test_nominal_offsets_mirror_and_follow_the_periodic_gait():
    g = NominalGait(
        step=0.15, width=0.08, ss=0.5, ds=0.13, heel=0.014, toe=0.014, inward=0.0, omega=6.1
    )
    left, right = g.offset(1.0), g.offset(-1.0)
    assert np.isclose(left[0], right[0]) and np.isclose(left[1], -right[1])
    # walking forward, the DCM lands behind the new foot and inside the feet
    assert left[0] < 0 and left[1] < 0 < right[1]
    # one step of the periodic gait from a touchdown brings the next touchdown's offset
    _, heel, toe = g.zmp_points(1.0)
    prev_toe = np.array([-g.step + g.toe, -g.width])
    xi = dcm_after(left, prev_toe, heel, g.ds, g.omega)
    xi = dcm_after(xi, heel, toe, g.ss, g.omega)
    assert np.allclose(xi - np.array([g.step, -g.width]), right, atol=1e-6)


def test_omega_refuses_a_height_that_is_not_positive():
    import pytest

    with pytest.raises(ValueError, match="expected > 0"):
        omega_of(0.0)
