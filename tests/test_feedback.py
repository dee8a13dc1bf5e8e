"""The per-tick feedback law and its policy: validation, the run-folder round trip, and
what a law does to the reference's joint targets (NumPy; MuJoCo for the closed loop)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.balance.channels import CHANNELS, FEATURES
from imitwalk.balance.feedback import Episode, FeedbackLaw, TickPolicy
from imitwalk.errors import ConfigError
from imitwalk.runs import RunDir
from imitwalk.sim.mujoco import MujocoPlant, playback, run
from imitwalk.sim.types import Observation

#: The walk the closed-loop checks play: scale 0.4 of the tiny reference, 3 s.
SCALE, SECONDS = 0.4, 3.0


def _obs(robot, gyro=(0.0, 0.0, 0.0)) -> Observation:
    """A level, still robot (gravity on the accelerometer) with this gyro reading."""
    n = len(robot.joint_names)
    return Observation(
        0.0, np.array(gyro, float), np.array([0, 0, 9.81]), np.ones((2, 4)), np.zeros(n)
    )


@st.composite
def laws(draw):
    channels = draw(
        st.lists(st.sampled_from(sorted(CHANNELS)), min_size=1, max_size=4, unique=True)
    )
    features = draw(st.lists(st.sampled_from(FEATURES), min_size=1, max_size=6, unique=True))
    memory = draw(st.booleans())
    m, d = len(channels), len(features)
    D = 2 * d + m if memory else d
    P = draw(st.sampled_from([1, 7]))
    N = draw(st.sampled_from([1, 7]))
    finite = st.floats(-10, 10, allow_nan=False)
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    return FeedbackLaw(
        tuple(channels),
        tuple(features),
        rng.uniform(-1, 1, (P, m, D)) * draw(finite),
        rng.normal(size=(N, d)),
        np.abs(rng.normal(size=m)),
        memory,
    )


def _same(a: FeedbackLaw, b: FeedbackLaw) -> None:
    assert (a.channels, a.features, a.memory) == (b.channels, b.features, b.memory)
    for k in ("gains", "nominal", "box"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))


@settings(max_examples=30, deadline=None)
@given(law=laws())
def test_a_law_round_trips_through_a_run_folder(tmp_path_factory, law):
    rd = RunDir(tmp_path_factory.mktemp("law"))
    rd.write_arrays("law.npz", {**law.to_arrays("a_"), **law.to_arrays("b_")})
    back = rd.read_arrays("law.npz")
    _same(FeedbackLaw.from_arrays(back, "a_"), law)
    _same(FeedbackLaw.from_arrays(back, "b_"), law)


def test_a_law_that_does_not_fit_is_refused():
    law = FeedbackLaw.zero(("ankle_pitch", "ankle_roll"), ("gyro_x", "gyro_y", "roll"), 0.1)
    assert law.gains.shape == (1, 2, 3) and law.nominal.shape == (1, 3)
    assert FeedbackLaw.zero(law.channels, law.features, 0.1, memory=True).gains.shape == (1, 2, 8)
    bad = {
        "gains have shape": {"gains": np.zeros((1, 3, 2))},
        "expected \\(P, 2, 3\\)": {"gains": np.zeros((2, 3))},
        "nominal \\(4,\\) / box": {"nominal": np.zeros(4)},
        "box \\(3,\\) do not fit": {"box": np.zeros(3)},
        "must be finite \\(box >= 0\\)": {"box": np.array([0.1, -0.1])},
        "must be finite": {"gains": np.full((1, 2, 3), np.nan)},
        "unknown channel 'knee'": {"channels": ("knee", "ankle_roll")},
        "unknown feature 'yaw'": {"features": ("gyro_x", "gyro_y", "yaw")},
        "given twice": {"channels": ("ankle_roll", "ankle_roll")},
    }
    for message, change in bad.items():
        with pytest.raises(ConfigError, match=message):
            replace(law, **change)
    # memory: the gains read x, the previous x and the previous action: D = 2d + m
    with pytest.raises(ConfigError, match=r"expected \(P, 2, 8\)"):
        replace(law, memory=True)


def test_with_gain_sets_one_gain_at_every_phase():
    law = FeedbackLaw.zero(("ankle_pitch", "ankle_roll"), ("gyro_x", "gyro_y"), 0.1)
    law = replace(law, gains=np.zeros((5, 2, 2)))
    g = law.with_gain("ankle_roll", "gyro_y", 0.3)
    assert g.gain("ankle_roll", "gyro_y") == pytest.approx(0.3)
    np.testing.assert_array_equal(g.gains[:, 1, 1], 0.3)
    assert np.count_nonzero(g.gains) == 5 and np.count_nonzero(law.gains) == 0


def test_the_zero_law_reproduces_open_loop_playback_tick_for_tick(robot, tiny_reference):
    ref, _ = tiny_reference
    law = FeedbackLaw.zero(("ankle_pitch", "ankle_roll", "hip_yaw"), FEATURES, 0.15)
    policy = TickPolicy(ref, SCALE, (law,), robot.joint_names, SECONDS)
    targets = ref.trajectory(SCALE, SECONDS)  # (T, n)
    np.testing.assert_array_equal(policy.q0, targets[0])
    closed = run(MujocoPlant(robot, ref.sim_options()), policy, len(targets))
    open_ = playback(MujocoPlant(robot, ref.sim_options()), targets, q0=targets[0])
    assert len(closed.t) == len(open_.t) == len(targets) and not closed.fell
    np.testing.assert_array_equal(closed.q_cmd, targets)
    np.testing.assert_array_equal(closed.q_cmd, open_.q_cmd)
    np.testing.assert_array_equal(closed.qpos, open_.qpos)
    np.testing.assert_array_equal(closed.gyro, open_.gyro)
    # and it recorded every tick: its phase, the six features as measured, zero actions
    ep = policy.episode()
    assert ep.features.shape == (len(targets), len(FEATURES)) and not ep.actions.any()
    np.testing.assert_array_equal(ep.features[1:, :3], closed.gyro[:-1])  # what tick k saw
    np.testing.assert_array_equal(ep.phase, [policy.phase_of(k) for k in range(len(targets))])


def test_a_gain_moves_the_named_joints_only(robot, tiny_reference):
    ref, _ = tiny_reference
    names = robot.joint_names
    law = FeedbackLaw.zero(("ankle_pitch",), ("gyro_x", "gyro_y"), 0.15)
    law = law.with_gain("ankle_pitch", "gyro_y", 0.1)
    q_ref = ref.trajectory(SCALE, SECONDS)
    pitch = [names.index(j) for j in CHANNELS["ankle_pitch"]]
    # a measured pitch rate moves both ankle pitches by gain x rate (up to the box) ...
    for gyro_y, offset in ((0.5, 0.05), (-1.0, -0.1), (4.0, 0.15), (-4.0, -0.15)):
        policy = TickPolicy(ref, SCALE, (law,), names, SECONDS)
        dq = policy(10, _obs(robot, (0.0, gyro_y, 0.0))) - q_ref[10]
        np.testing.assert_allclose(dq[pitch], offset, atol=1e-12)
        assert not np.delete(dq, pitch).any()
    # ... a feature without a gain moves nothing
    policy = TickPolicy(ref, SCALE, (law,), names, SECONDS)
    np.testing.assert_array_equal(policy(10, _obs(robot, (2.0, 0.0, 3.0))), q_ref[10])
    # and in closed loop only the ankle pitches are commanded off the reference
    policy = TickPolicy(ref, SCALE, (law,), names, SECONDS)
    ro = run(MujocoPlant(robot, ref.sim_options()), policy, len(q_ref))
    dq = ro.q_cmd - q_ref[: len(ro.q_cmd)]
    assert np.abs(dq[:, pitch]).max() > 1e-3
    assert not np.delete(dq, pitch, axis=1).any()
    np.testing.assert_allclose(dq[:, pitch[0]], dq[:, pitch[1]], atol=1e-12)
    seen = ro.gyro[:-1, 1]  # tick k acts on the reading after physics step k - 1
    np.testing.assert_allclose(dq[1:, pitch[0]], np.clip(0.1 * seen, -0.15, 0.15), atol=1e-12)


def test_a_law_with_memory_reads_the_last_ticks_state_and_action(robot, tiny_reference):
    """a_k = K [x_k, x_{k−1}, a_{k−1}]: here a_k = x_k − x_{k−1} + 0.5 a_{k−1} on gyro_y."""
    ref, _ = tiny_reference
    law = FeedbackLaw.zero(("ankle_pitch",), ("gyro_y",), 10.0, memory=True)
    law = replace(law, gains=np.array([[[1.0, -1.0, 0.5]]]))
    policy = TickPolicy(ref, SCALE, (law,), robot.joint_names, SECONDS)
    j = robot.joint_names.index("l_ankle_pitch")
    x = np.array([0.2, 0.5, -0.1, 0.0, 0.3])
    a_prev, x_prev = 0.0, x[0]  # the first tick has no previous state: it is its own
    for k, xk in enumerate(x):
        a = xk - x_prev + 0.5 * a_prev
        q = policy(k, _obs(robot, (0.0, xk, 0.0)))
        assert q[j] - ref.trajectory(SCALE, SECONDS)[k, j] == pytest.approx(a, abs=1e-12)
        a_prev, x_prev = a, xk
    np.testing.assert_allclose(policy.episode().actions[-1], [a_prev])


def test_laws_add_up_and_exploration_goes_to_the_last_one(robot, tiny_reference):
    ref, _ = tiny_reference
    names = robot.joint_names
    q_ref = ref.trajectory(SCALE, SECONDS)
    base = FeedbackLaw.zero(("ankle_pitch",), ("gyro_y",), 0.15).with_gain(
        "ankle_pitch", "gyro_y", 0.1
    )
    top = FeedbackLaw.zero(("l_ankle_pitch", "hip_roll"), ("gyro_y",), 0.15).with_gain(
        "l_ankle_pitch", "gyro_y", 0.02
    )
    policy = TickPolicy(ref, SCALE, (base, top), names, SECONDS)
    dq = policy(0, _obs(robot, (0.0, 1.0, 0.0))) - q_ref[0]
    assert dq[names.index("l_ankle_pitch")] == pytest.approx(0.12)
    assert dq[names.index("r_ankle_pitch")] == pytest.approx(0.1)
    assert not np.delete(dq, [names.index(j) for j in ("l_ankle_pitch", "r_ankle_pitch")]).any()
    # exploration: held for `hold` ticks, on the last law's channels only, from its seed
    runs = []
    for seed in (3, 3, 4):
        p = TickPolicy(ref, SCALE, (base, top), names, SECONDS, explore=0.05, hold=4, seed=seed)
        runs.append(np.array([p(k, _obs(robot)) - q_ref[k] for k in range(12)]))
        acts = p.episode().actions  # (12, 2): the last law's, noise included
        assert acts.shape == (12, 2) and np.abs(acts).max() <= 0.05
        for block in np.split(acts, 3):
            assert np.all(block == block[0]) and np.any(block[0] != 0)
    np.testing.assert_array_equal(runs[0], runs[1])
    assert not np.array_equal(runs[0], runs[2])
    moved = {names[i] for i in np.flatnonzero(np.abs(runs[0]).sum(axis=0))}
    assert moved == {"l_ankle_pitch", "l_hip_roll", "r_hip_roll"}  # not the base's r_ankle_pitch


def test_an_episodes_states_are_its_features_less_the_nominal_at_each_phase():
    rng = np.random.default_rng(0)
    phase = np.array([0, 1, 2, 0, 1, 2, 0])
    ep = Episode(phase, rng.normal(size=(7, len(FEATURES))), np.zeros((7, 1)))
    law = FeedbackLaw.zero(("ankle_roll",), ("roll", "gyro_x"), 0.1, n_ticks=3)
    law = replace(law, nominal=np.array([[1.0, 10.0], [2.0, 20.0], [3.0, 30.0]]))
    s = ep.states(law)
    cols = [FEATURES.index("roll"), FEATURES.index("gyro_x")]
    np.testing.assert_allclose(s, ep.features[:, cols] - law.nominal[phase])


def test_a_per_phase_gain_is_the_one_of_the_ticks_loop_phase(robot, tiny_reference):
    ref, _ = tiny_reference
    n, start = ref.loops.shape[1], ref.starts.shape[1]
    gains = np.linspace(0.0, 0.1, n)[:, None, None]  # (N, 1, 1)
    law = replace(FeedbackLaw.zero(("ankle_roll",), ("gyro_x",), 1.0), gains=gains)
    policy = TickPolicy(ref, SCALE, (law,), robot.joint_names, SECONDS)
    j = robot.joint_names.index("r_ankle_roll")
    q_ref = ref.trajectory(SCALE, SECONDS)
    for k in range(len(q_ref)):
        dq = policy(k, _obs(robot, (1.0, 0.0, 0.0)))[j] - q_ref[k, j]
        assert policy.phase_of(k) == (k - start) % n
        assert dq == pytest.approx(gains[(k - start) % n, 0, 0], abs=1e-12)
    assert policy.phase_of(start) == 0  # the loop's first tick is phase 0
