"""Retargeting: the gait template, the task-space plan, the IK reference and its record."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from imitwalk.mocap import default_clip, load_motion
from imitwalk.retarget import GaitParams, Reference, RetargetConfig, extract_template, retarget
from imitwalk.retarget.ik import leg_geometry
from imitwalk.retarget.plan import START_CYCLES, plan_walk
from imitwalk.retarget.search import SearchConfig, search_params
from imitwalk.retarget.walkable import build_walkable
from imitwalk.robots import load_robot


@pytest.fixture(scope="module")
def robot():
    return load_robot("hoap2")


@pytest.fixture(scope="module")
def template():
    return extract_template(load_motion(default_clip()))


@pytest.fixture(scope="module")
def built(robot, template):
    return build_walkable(template, robot, GaitParams(), [0.5, 1.0], 0.01)


def test_template_of_the_default_walk(template):
    assert template.period == pytest.approx(1.267, abs=0.02)
    assert 1.0 < template.stride < 1.4 and 0.75 < template.leg_length < 0.95
    assert 0.55 < template.stance < 0.7 and 0.05 < template.double_support < 0.2
    assert template.swing_x[0] == 0.0 and template.swing_x[-1] == pytest.approx(1.0)
    assert np.all(np.diff(template.swing_x) >= 0)
    assert template.swing_z.max() == pytest.approx(1.0) and template.arms_measured


@pytest.mark.parametrize("clip", ["07_04.bvh", "07_06.bvh"])
def test_template_of_cmu_walks(shared_mocap, clip):
    t = extract_template(load_motion(shared_mocap / "cmu_bvh" / clip))
    assert 0.9 < t.period < 1.6 and 0.9 < t.stride < 1.7
    assert 0.5 < t.stride / t.period < 2.0  # a plausible human walking speed [m/s]


def test_plan_stance_foot_is_fixed_and_feet_alternate(robot, template):
    plan = plan_walk(template, leg_geometry(robot), GaitParams(), 1.0, 0.01, cycles=2)
    for j, sole in enumerate((plan.l_sole, plan.r_sole)):
        st = plan.stance[:, j]
        runs = np.split(np.arange(len(st)), np.flatnonzero(np.diff(st.astype(int))) + 1)
        for run in runs:
            if st[run[0]]:
                assert np.ptp(sole[run], axis=0).max() < 1e-12  # planted
                assert np.all(sole[run, 2] == 0.0)
    assert not np.any(~plan.stance[:, 0] & ~plan.stance[:, 1])  # never both feet in the air
    mid = np.abs(plan.swing - 0.5) < 0.02
    assert np.all(np.concatenate([plan.l_sole[mid[:, 0], 2], plan.r_sole[mid[:, 1], 2]]) >= 0.015)


def test_steady_plan_is_periodic(robot, template):
    plan = plan_walk(template, leg_geometry(robot), GaitParams(), 0.8, 0.01, cycles=2)
    n = round(plan.period / 0.01)
    assert np.allclose(plan.l_sole[n:, 0] - plan.l_sole[:n, 0], plan.stride)
    assert np.allclose(plan.com[n:, 0] - plan.com[:n, 0], plan.stride)
    assert np.allclose(plan.com[n:, 1], plan.com[:n, 1])


def test_start_up_begins_standing(robot, template):
    plan = plan_walk(template, leg_geometry(robot), GaitParams(), 1.0, 0.01, start=True)
    n = round(plan.period / 0.01)
    assert len(plan.phase) == (START_CYCLES + 1) * n
    assert np.allclose(plan.com[0], 0.0) and plan.l_sole[0, 0] == plan.r_sole[0, 0] == 0.0
    assert plan.stance[:n].all()  # the first cycle only sways


def test_walkable_reference_kinematics(robot, built):
    ref = built.reference
    assert ref.residual_mm.max() < 5.0
    for q in (ref.loops, ref.starts):
        assert np.all(q >= robot.limits[:, 0] - 1e-9) and np.all(q <= robot.limits[:, 1] + 1e-9)
    c = ref.checks
    assert c["stance_tilt_deg_max"] < 3.0
    assert c["swing_clearance_mm_min"] >= 15.0
    assert c["feet_alternate"] and c["steps_forward"]
    assert c["loop_closure_rad_max"] < 0.05
    assert c["foot_skate_mm_per_step"] < 1.0
    assert c["knee_min_deg"] > 10.0
    # the start-up ends where the loop begins
    assert np.abs(ref.starts[:, -1] - ref.loops[:, 0]).max() < 0.1
    assert ref.strides[1] == pytest.approx(2 * ref.strides[0])


@pytest.mark.parametrize("clip", ["07_04.bvh", "07_06.bvh"])
def test_walkable_reference_of_cmu_walks(shared_mocap, robot, clip):
    t = extract_template(load_motion(shared_mocap / "cmu_bvh" / clip))
    ref = build_walkable(t, robot, GaitParams(), [1.0], 0.01).reference
    c = ref.checks
    assert ref.loops.shape[1] >= round(0.8 / 0.01)  # at least one whole cycle
    assert c["stance_tilt_deg_max"] < 3.0 and c["swing_clearance_mm_min"] >= 15.0
    assert c["feet_alternate"] and c["steps_forward"] and c["loop_closure_rad_max"] < 0.05
    assert np.all(ref.loops >= robot.limits[:, 0] - 1e-9)
    assert np.all(ref.loops <= robot.limits[:, 1] + 1e-9)


def test_reference_round_trip_and_access(tmp_path, built):
    ref = dataclasses.replace(built.reference, source="x.bvh")
    path = ref.save(tmp_path / "ref.npz")
    back = Reference.load(path)
    for f in dataclasses.fields(Reference):
        a, b = getattr(ref, f.name), getattr(back, f.name)
        if isinstance(a, np.ndarray):
            assert np.array_equal(a, b)
        elif f.name == "plan":  # scale -> named arrays
            assert a.keys() == b.keys()
            for key in a:
                assert np.array_equal(a[key], b[key]), key
        else:
            assert a == b, f.name
    q = back.trajectory(0.75, 10.0)
    assert q.shape == (1000, 25)
    _start, _loop, stride = back.at_scale(0.75)
    assert stride == pytest.approx(0.75 * ref.strides[1])
    d = [back.expected_distance(1.0, s) for s in (1, 5, 10, 20)]
    assert d[0] == 0.0 and np.all(np.diff(d) > 0)
    assert d[3] - d[2] == pytest.approx(10 / back.period * ref.strides[1], rel=0.02)


def test_search_is_small_deterministic_and_reported(robot, template):
    cfg = SearchConfig(
        generations=1, population=2, elites=1, scales=(0.5,), models=1, seconds=1.5, workers=1
    )
    p1, rep1 = search_params(template, robot, cfg)
    p2, rep2 = search_params(template, robot, cfg)
    assert p1 == p2 and rep1.best_score == rep2.best_score
    assert rep1.evaluations == 2 and len(rep1.history) == 2
    assert set(rep1.best["params"]) == {"sway", "height", "lift", "ds", "lean", "width"}


def test_paper_mapping_builds_and_reports_clipping(robot):
    res = retarget(load_motion(default_clip()), robot, RetargetConfig(mapping="paper"))
    ref = res.reference
    assert ref.mapping == "paper" and ref.loops.shape[2] == 25
    assert np.all(ref.loops >= robot.limits[:, 0] - 1e-9)
    stats = res.stats()
    assert 0.0 < stats["clipped_fraction"] < 1.0 and stats["clipped"]


def test_mid_swing_is_found_in_every_swing_whatever_the_sampling():
    """Clearance is measured at the tick nearest σ = 0.5 of each swing, so a coarse or
    uneven sampling of σ never leaves it undefined (it used to give NaN)."""
    from imitwalk.retarget.checks import _mid_swing_ticks

    stance = np.ones((40, 2), dtype=bool)
    sigma = np.full((40, 2), np.nan)
    stance[3:10, 0] = False
    sigma[3:10, 0] = np.linspace(0.02, 0.97, 7)  # coarse: no tick at exactly 0.5
    stance[20:33, 1] = False
    sigma[20:33, 1] = np.linspace(0.0, 1.0, 13)
    stance[37:, 0] = False  # a swing cut off by the end of the window
    sigma[37:, 0] = [0.1, 0.2, 0.3]
    ticks = _mid_swing_ticks(stance, sigma)
    assert sorted(ticks) == [(6, 0), (26, 1), (39, 0)]
