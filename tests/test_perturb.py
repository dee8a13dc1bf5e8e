"""Perturbed robots: leaving a factor out changes that factor only (pure NumPy)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.errors import ConfigError
from imitwalk.sim.perturb import FACTORS, perturbed
from imitwalk.sim.types import SimOptions

#: the fields of SimOptions each factor sets
FIELDS = {
    "mass": "mass_jitter",
    "friction": "friction",
    "servo": "kp_jitter",
    "disturbance": "init_twist",
}


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(1, 10**6),
    left_out=st.lists(st.sampled_from(FACTORS), unique=True, max_size=len(FACTORS)),
)
def test_leaving_factors_out_keeps_the_others(seed, left_out):
    full = perturbed(seed, disturbance=True)
    part = perturbed(seed, disturbance=True, factors=tuple(f for f in FACTORS if f not in left_out))
    nominal = SimOptions()
    for f, name in FIELDS.items():
        expected = getattr(nominal if f in left_out else full, name)
        assert getattr(part, name) == expected
    assert part.seed == full.seed  # sensor noise and the jitter draws are the robot's own


def test_nominal_robot_and_unknown_factor():
    assert perturbed(0, factors=("mass",)) == SimOptions(seed=0)
    with pytest.raises(ConfigError, match=r"unknown perturbation factor 'kp'.*servo"):
        perturbed(3, factors=("kp",))


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(1, 10**6), high=st.floats(1.0, 1.5))
def test_a_wider_friction_range_maps_the_same_draw(seed, high):
    """The learner's robots may draw friction from a wider range: the same robot, the same
    quantile of it, and every other factor as before."""
    base = perturbed(seed, disturbance=True)
    wide = perturbed(seed, disturbance=True, friction_range=(0.7, high))
    u = (base.friction - 0.7) / 0.3
    assert wide.friction == pytest.approx(0.7 + u * (high - 0.7))
    assert (wide.mass_jitter, wide.kp_jitter, wide.init_twist) == (
        base.mass_jitter,
        base.kp_jitter,
        base.init_twist,
    )
