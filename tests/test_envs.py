"""The Gymnasium environment: Gymnasium's own checks, exact seeding, the residual mode
at zero being imitwalk's own controller, falls ending episodes, rewards, vector
environments across processes, headless rendering, and bad input."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.errors import ConfigError


@pytest.fixture(scope="module")
def residual_setup():
    from imitwalk.envs import WalkConfig, build_setup

    return build_setup(WalkConfig(action="residual", seconds=4.0))


@pytest.fixture(scope="module")
def joints_setup():
    from imitwalk.envs import WalkConfig, build_setup

    return build_setup(WalkConfig(action="joints", seconds=4.0))


def _env(setup, **kw):
    from imitwalk.envs.walk import WalkEnv

    return WalkEnv(setup=setup, **kw)


@pytest.mark.parametrize("mode", ["residual", "joints"])
def test_gymnasium_check_env_passes(mode, residual_setup, joints_setup):
    import warnings

    from gymnasium.utils.env_checker import check_env

    env = _env(residual_setup if mode == "residual" else joints_setup)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*infinity.*")  # unbounded sensors
        check_env(env, skip_render_check=True)


def test_registered_and_made_by_id():
    import gymnasium as gym

    import imitwalk.envs  # noqa: F401

    env = gym.make("imitwalk/Walk-v0", action="residual", seconds=0.5)
    obs, info = env.reset(seed=0)
    assert obs.shape == env.observation_space.shape and "robot_seed" in info
    env.close()


def test_the_same_seed_walks_the_same_episode(residual_setup):
    """reset(seed=s) draws the same robot, and the same actions give the same walk."""
    runs = []
    for _ in range(2):
        env = _env(residual_setup)
        obs, info = env.reset(seed=11)
        rng = np.random.default_rng(0)
        rows = [obs]
        for _k in range(60):
            obs, r, term, trunc, _ = env.step(rng.uniform(-0.05, 0.05, env.action_space.shape))
            rows.append(np.append(obs, r))
            if term or trunc:
                break
        runs.append((info["robot_seed"], rows))
    assert runs[0][0] == runs[1][0]
    for a, b in zip(runs[0][1], runs[1][1], strict=True):
        np.testing.assert_array_equal(a, b)
    other = _env(residual_setup)
    assert other.reset(seed=12)[1]["robot_seed"] != runs[0][0]


def test_residual_at_zero_is_the_stepping_gait_itself(residual_setup):
    """With a zero residual the environment commands, tick for tick, what imitwalk's
    own loop (sim.run of the stepping controller) commands on the same robot."""
    from dataclasses import replace

    from imitwalk.sim.mujoco import MujocoPlant, run
    from imitwalk.step.controller import SteppingController

    s = residual_setup
    env = _env(s)
    env.reset(options={"robot_seed": 3})
    sent = []
    for _ in range(150):
        sent.append(env.base.copy())
        *_, term, trunc, _info = env.step(np.zeros(s.robot.dof))
        if term or trunc:
            break
    draw = s.protocol.draw(3, s.robot, seconds=s.config.seconds)
    plant = MujocoPlant(s.robot, replace(draw.options, control_hz=1.0 / s.dt))
    ro = run(plant, SteppingController(s.robot, s.style, s.gains, s.dt), len(sent))
    np.testing.assert_allclose(ro.q_cmd, s.robot.clip(np.array(sent)), atol=1e-12)


def test_a_fall_ends_the_episode(joints_setup):
    """Joint targets that fold the robot make it fall; the episode then terminates."""
    env = _env(joints_setup)
    env.reset(options={"robot_seed": 0})
    fold = env.action_space.high.copy()
    for k in range(400):
        *_, term, trunc, info = env.step(fold if k % 40 < 20 else env.action_space.low)
        if term or trunc:
            break
    assert term and not trunc and info["t"] < joints_setup.config.seconds
    assert env.plant is not None and env.plant.fell


def test_rewards_are_named_and_the_weights_sum_them(residual_setup):
    from imitwalk.envs import TERMS

    env = _env(residual_setup)
    env.reset(seed=1)
    _, r, _, _, info = env.step(np.zeros(residual_setup.robot.dof))
    terms = info["reward_terms"]
    assert tuple(terms) == TERMS
    w = residual_setup.config.reward_weights.to_dict()
    assert r == pytest.approx(sum(w[k] * terms[k] for k in TERMS))


@settings(max_examples=40, deadline=None)
@given(
    st.integers(1, 12),
    st.floats(-1, 1),
    st.floats(-1, 1),
)
def test_reward_terms_stay_in_their_ranges(n, a, b):
    from imitwalk.envs.rewards import TickState, reward_terms

    rng = np.random.default_rng(n)
    q = rng.normal(size=n)
    s = TickState(
        q,
        q + a,
        q * b,
        q,
        rng.normal(size=(2, 3)),
        rng.normal(size=(2, 3)),
        rng.normal(size=2),
        rng.normal(size=2),
        np.full(n, a),
        np.full(n, b),
    )
    t = reward_terms(s)
    for k in ("pose", "velocity", "end_effector", "com"):
        assert 0.0 <= t[k] <= 1.0
    assert t["alive"] == 1.0 and t["action_rate"] <= 0.0
    same = TickState(q, q, q, q, s.soles, s.soles, s.com_vel, s.com_vel, s.action, s.action)
    assert all(reward_terms(same)[k] == 1.0 for k in ("pose", "velocity", "end_effector", "com"))


def test_the_observation_is_the_sensors_in_named_blocks(residual_setup):
    lay = residual_setup.layout
    sl = lay.slices()
    assert [name for name, _ in lay.blocks] == list(sl)
    assert sum(s.stop - s.start for s in sl.values()) == lay.size
    assert "base" in sl and "previous" in sl


def test_two_processes_step_a_vector_environment():
    import gymnasium as gym

    import imitwalk.envs  # noqa: F401

    envs = gym.vector.AsyncVectorEnv(
        [lambda: gym.make("imitwalk/Walk-v0", action="residual", seconds=0.3)] * 2
    )
    try:
        obs, info = envs.reset(seed=[1, 2])
        assert obs.shape[0] == 2 and info["robot_seed"][0] != info["robot_seed"][1]
        for _ in range(40):  # past the 0.3 s episodes: the vector resets them itself
            obs, r, *_ = envs.step(np.zeros((2, *envs.single_action_space.shape)))
        assert np.all(np.isfinite(obs)) and r.shape == (2,)
    finally:
        envs.close()


def test_rgb_array_renders_headless(residual_setup):
    env = _env(residual_setup, render_mode="rgb_array")
    env.reset(seed=0)
    frame = env.render()
    env.close()
    assert frame.shape == (240, 320, 3) and frame.dtype == np.uint8 and frame.std() > 0


@pytest.mark.parametrize(
    ("kw", "words"),
    [
        ({"action": "torque"}, "valid: joints, residual"),
        ({"protocol": "nowhere"}, "valid: "),
        ({"protocol": "bullet"}, "valid engines: mujoco"),
        ({"seconds": 0}, "seconds=0"),
        ({"box": float("nan")}, "box=nan"),
        ({"robots": 0}, "robots=0"),
    ],
)
def test_bad_settings_get_one_line(kw, words):
    from imitwalk.envs import WalkConfig, build_setup

    with pytest.raises(ConfigError) as e:
        build_setup(WalkConfig(**kw))
    assert words in str(e.value) and "\n" not in str(e.value)


def test_unknown_robot_and_render_mode_get_one_line(residual_setup):
    from imitwalk.envs import WalkConfig, build_setup
    from imitwalk.errors import ImitwalkError

    with pytest.raises(ImitwalkError, match="valid: hoap2"):
        build_setup(WalkConfig(robot="asimo"))
    with pytest.raises(ConfigError, match="valid: rgb_array"):
        _env(residual_setup, render_mode="human")
