"""The step-level balance channels and the state estimator (pure NumPy)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.balance import STEP_CHANNELS, STEP_STATE, StepConfig, StepController, mirror_state
from imitwalk.estimator import StateEstimator
from imitwalk.predictor import SensoryMotorModel

finite = st.floats(-1.0, 1.0, allow_nan=False)


@given(st.lists(finite, min_size=len(STEP_STATE), max_size=len(STEP_STATE)))
def test_mirroring_twice_is_identity(values):
    s = np.array(values)
    s[6] = abs(s[6])  # a load share
    assert np.allclose(mirror_state(mirror_state(s, -1.0), -1.0), s)
    assert np.allclose(mirror_state(s, 1.0), s)


def _controller(actions, n=100, ds=0.1):
    ctrl = StepController(StepConfig(), n, ds)
    for k, c in enumerate(actions):
        ctrl.decide(np.zeros(len(STEP_STATE)), k)
        ctrl.actions[-1] = np.asarray(c, dtype=float)
    return ctrl


@settings(max_examples=25, deadline=None)
@given(
    st.lists(
        st.lists(finite, min_size=len(STEP_CHANNELS), max_size=len(STEP_CHANNELS)),
        min_size=4,
        max_size=4,
    )
)
def test_task_offsets_are_continuous_and_start_at_zero(raw):
    ctrl = _controller([np.array(c) * ctrl_max() for c in raw])
    offs = np.array([ctrl.offsets(i) for i in range(len(raw) * 50)])  # (T, 8)
    assert np.allclose(offs[0], 0.0)
    jumps = np.abs(np.diff(offs, axis=0)).max(axis=0)
    # no jump bigger than a smooth profile's slope over one tick allows
    assert np.all(jumps <= 0.2 * np.maximum(np.abs(offs).max(axis=0), 1e-9) + 1e-9)


def ctrl_max():
    return np.asarray(StepConfig().c_max)


def test_landing_offset_persists_then_decays():
    c = np.zeros(len(STEP_CHANNELS))
    c[0] = 0.01  # step 0: the right foot lands 1 cm further forward
    ctrl = _controller([c, np.zeros_like(c), np.zeros_like(c)], n=100)
    offs = np.array([ctrl.offsets(i) for i in range(150)])
    r_x = offs[:, 3]
    assert r_x[0] == 0.0 and r_x[49] == pytest.approx(0.01, rel=0.05)  # landed
    assert r_x[50] == pytest.approx(0.01, rel=0.05)  # still there at the next step's start
    assert abs(r_x[99]) < 1e-3  # decayed over the next stance
    assert np.all(offs[:, 0] == 0.0)  # the left foot never moved


def test_search_prefers_the_action_a_known_model_says_is_best():
    rng = np.random.default_rng(0)
    S, A = [], []
    for _ in range(20):  # synthetic steps: next pitch = pitch + 5 * lean (mirror-free dims)
        s = np.zeros((30, len(STEP_STATE)))
        a = np.c_[rng.uniform(-1, 1, (30, len(STEP_CHANNELS))) * ctrl_max(), np.ones(30)]
        s[0, 1] = rng.normal(0, 0.05)
        for k in range(29):
            s[k + 1, 1] = s[k, 1] + 5.0 * a[k, 4]
        S.append(s)
        A.append(a)
    model = SensoryMotorModel(angle_action=False, linear=True, n_centers=4, ridge=1e-6)
    model.fit(list(zip(S, A, strict=True)))
    cfg = StepConfig(weights=(0, 1, 0, 0, 0, 0, 0, 0), effort=0.0, horizon=1, candidates=400)
    ctrl = StepController(cfg, 100, 0.1, model=model)
    state = np.zeros(len(STEP_STATE))
    ctrl.decide(state, 0)
    state[1] = -0.03  # leaning back: lean forward by 6 mm to level out
    c = ctrl.decide(state, 1)
    assert c[4] == pytest.approx(0.006, abs=0.0015)


def test_estimator_tilt_from_gravity_and_heading_from_gyro():
    est = StateEstimator(dt=0.01, tau=0.2)
    g = 9.81
    roll = np.radians(5.0)
    accel = np.array([0.0, g * np.sin(roll), g * np.cos(roll)])
    ff = np.array([[10.0, 10.0, 5.0, 5.0], [0.0, 0.0, 0.0, 0.0]])
    for _ in range(300):
        e = est.update(np.array([0.0, 0.0, 0.1]), accel, ff)
    assert e.roll == pytest.approx(roll, abs=1e-3) and abs(e.pitch) < 1e-6
    assert e.heading == pytest.approx(0.3, rel=1e-6)
    assert e.load_left == 1.0 and e.cop_x == pytest.approx(10.0 / 30.0)


def test_search_stays_where_the_model_has_data_and_never_steps_inwards():
    rng = np.random.default_rng(1)
    S = [rng.normal(0, 0.05, (30, len(STEP_STATE))) for _ in range(4)]
    A = [
        np.c_[rng.uniform(-0.3, 0.3, (30, len(STEP_CHANNELS))) * ctrl_max(), np.ones(30)]
        for _ in range(4)
    ]
    model = SensoryMotorModel(angle_action=False, linear=True, n_centers=4, ridge=1e-3)
    model.fit(list(zip(S, A, strict=True)))
    limits = 0.3 * ctrl_max()
    ctrl = StepController(StepConfig(), 100, 0.1, model=model, limits=limits)
    state = np.zeros(len(STEP_STATE))
    for k in range(12):
        c = ctrl.decide(state + rng.normal(0, 0.05, len(STEP_STATE)), k)
        assert np.all(np.abs(c) <= limits + 1e-12)
        assert c[STEP_CHANNELS.index("dy")] >= 0.0


def test_a_fall_before_the_first_step_records_no_steps():
    from imitwalk.balance import STEP_CHANNELS, STEP_STATE

    states, actions = StepController(StepConfig(), 100, 0.1).episode()
    assert states.shape == (0, len(STEP_STATE)) and actions.shape == (0, len(STEP_CHANNELS) + 1)
