"""The linear inverted pendulum of the start-up, and the start-up's weight shift."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from imitwalk.mocap import default_clip, load_motion
from imitwalk.retarget import GaitParams, extract_template
from imitwalk.retarget.ik import leg_geometry
from imitwalk.retarget.lipm import lipm_com, lipm_zmp
from imitwalk.retarget.plan import START_CYCLES, plan_walk
from imitwalk.robots import load_robot

DT, HEIGHT = 0.01, 0.25


@settings(max_examples=50, deadline=None)
@given(arrays(np.float64, st.integers(3, 200), elements=st.floats(-0.1, 0.1)))
def test_the_com_keeps_the_zmp_it_was_solved_for(zmp):
    com = lipm_com(zmp, DT, HEIGHT)
    assert np.allclose(lipm_zmp(com, DT, HEIGHT)[1:-1], zmp[1:-1], atol=1e-12)
    assert com[0] == pytest.approx(zmp[0]) and com[-1] == pytest.approx(zmp[-1])  # at rest
    # a smoothing: never beyond the ZMP's own range
    assert zmp.min() - 1e-12 <= com.min() and com.max() <= zmp.max() + 1e-12


def test_the_com_leans_into_a_step_before_the_zmp_moves():
    zmp = np.where(np.arange(300) < 150, 0.0, 0.04)
    com = lipm_com(zmp, DT, HEIGHT)
    assert np.all(np.diff(com) >= 0.0)  # one move, no swing back
    assert 0.0 < com[140] < 0.02 and com[149] == pytest.approx(0.02, abs=1e-3)  # midway
    assert lipm_com(np.full(50, 0.03), DT, HEIGHT) == pytest.approx(0.03)
    both = lipm_com(np.stack([zmp, -zmp], axis=1), DT, HEIGHT)  # axes solved alike
    assert np.allclose(both[:, 0], com) and np.allclose(both[:, 1], -com)


@pytest.fixture(scope="module")
def plans():
    template = extract_template(load_motion(default_clip()))
    geom = leg_geometry(load_robot("hoap2"))
    params = GaitParams(sway=0.95, ds=0.075)
    start = plan_walk(template, geom, params, 1.0, DT, cycles=2, start=True)
    steady = plan_walk(template, geom, params, 1.0, DT, cycles=2)
    return start, steady, geom, params


def test_the_start_up_shifts_the_weight_once_onto_the_first_stance_foot(plans):
    plan, _, geom, params = plans
    n = round(plan.period / DT)
    reach = params.sway * (geom.hip_y + params.width)
    y = plan.com[:, 1]
    lift = n + int(np.ceil(params.ds * n))  # the right foot's first lift-off
    assert plan.stance[:lift].all() and not plan.stance[lift, 1]
    assert y[:lift].min() > -1e-3  # never out over the right sole (the old sway went to −36 mm)
    assert np.all(np.diff(y[: n + 10]) >= -1e-6)  # one move to the left
    assert y[lift] > 0.8 * reach
    # the pendulum's ZMP stays inside the support and never beyond the left sole's centre
    zmp = lipm_zmp(y, DT, float(plan.pelvis_z[0] - geom.hip_z + geom.com_above_hip))
    assert zmp[:lift].min() > -0.005 and zmp[:lift].max() < reach + 1e-3


def test_the_start_up_hands_over_to_the_steady_sway(plans):
    start, steady, _, _ = plans
    n = round(start.period / DT)
    # from the end of the hand-over (the first stepping cycle and its double support) on,
    # the start-up sways as the steady plan does, tick for tick
    done = round((2 + 0.075) * n) + 1
    last = slice(done, (START_CYCLES + 1) * n)
    assert np.allclose(start.com[last, 1], steady.com[done - 2 * n : 2 * n, 1], atol=1e-12)
    assert np.abs(np.diff(start.com[:, 1])).max() < 0.004  # smooth: under 0.4 m/s
