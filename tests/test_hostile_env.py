"""Hostile input to the environment, the plants and the flat API: each is refused in one
line (an :class:`~imitwalk.errors.ImitwalkError`) before it can reach the physics, and a
refused call leaves the walk as it was."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from imitwalk.errors import ConfigError, MocapError


@pytest.fixture(scope="module")
def setup():
    from imitwalk.envs import WalkConfig, build_setup

    return build_setup(WalkConfig(action="residual", seconds=1.0))


def _env(setup):
    from imitwalk.envs.walk import WalkEnv

    return WalkEnv(setup=setup)


def _one_line(exc: pytest.ExceptionInfo) -> str:
    text = str(exc.value)
    assert text and "\n" not in text, text
    return text


def _bad_actions(n: int) -> dict[str, object]:
    nan = np.zeros(n)
    nan[3] = np.nan
    return {
        "nan": nan,
        "inf": np.full(n, np.inf),
        "-inf": np.full(n, -np.inf),
        "None": None,
        "string": "a",
        "strings": ["0.1"] * n,
        "bools": np.ones(n, bool),
        "scalar": 0.1,
        "one": np.array([0.1]),
        "column": np.zeros((n, 1)),
        "row": np.zeros((1, n)),
        "n+1": np.zeros(n + 1),
        "two rows": np.zeros((2, n)),
        "empty": np.zeros(0),
    }


@pytest.mark.parametrize(
    "kind",
    [
        "nan",
        "inf",
        "-inf",
        "None",
        "string",
        "strings",
        "bools",
        "scalar",
        "one",
        "column",
        "row",
        "n+1",
        "two rows",
        "empty",
    ],
)
def test_a_bad_action_is_refused_in_one_line_naming_the_shape(setup, kind):
    env = _env(setup)
    env.reset(seed=0)
    n = setup.robot.dof
    with pytest.raises(ConfigError) as e:
        env.step(_bad_actions(n)[kind])
    assert f"({n},)" in _one_line(e)


def test_a_refused_action_leaves_the_walk_as_it_was(setup):
    """A NaN action is refused before it reaches the plant: the walk then goes on exactly
    as one that never saw it, with finite rewards (no NaN held over as the last action)."""
    n = setup.robot.dof
    runs = []
    for hostile in (False, True):
        env = _env(setup)
        env.reset(seed=5)
        rows = []
        for k in range(5):
            if hostile and k == 2:
                with pytest.raises(ConfigError, match=r"action\[3\] = nan"):
                    env.step(_bad_actions(n)["nan"])
            obs, r, *_ = env.step(np.full(n, 0.01))
            rows.append(np.append(obs, r))
        runs.append(np.array(rows))
    assert np.all(np.isfinite(runs[1]))
    np.testing.assert_array_equal(runs[0], runs[1])


def test_good_actions_of_any_number_type_still_walk(setup):
    n = setup.robot.dof
    env = _env(setup)
    env.reset(seed=1)
    for a in (np.zeros(n, np.float32), [0.0] * n, np.zeros(n, int), np.full(n, 5.0)):
        _, r, *_ = env.step(a)  # the last: finite, outside the box, clipped to it
        assert np.isfinite(r)


@pytest.mark.parametrize(
    ("kw", "words"),
    [
        ({"foo": 1}, "unknown keyword argument 'foo'; valid: "),
        ({"weights": {"a": 1}}, "unknown reward term 'a'; valid: "),
        ({"weights": {"pose": "x"}}, "reward weight pose='x'"),
        ({"weights": {"pose": True}}, "reward weight pose=True"),
        ({"weights": "pose"}, "weights='pose'"),
        ({"seconds": 1e12}, "at most 3600 s"),
        ({"seconds": True}, "seconds=True"),
        ({"box": True}, "box=True"),
        ({"robots": True}, "robots=True"),
        ({"first_robot": False}, "first_robot=False"),
        ({"previous_action": "no"}, "previous_action='no'"),
    ],
)
def test_bad_make_arguments_are_refused_at_make_time(kw, words):
    """Each is refused by ``gym.make`` itself (before any setup is built), in one line."""
    import gymnasium as gym

    import imitwalk.envs  # noqa: F401

    with pytest.raises(ConfigError) as e:
        gym.make("imitwalk/Walk-v0", **kw)
    assert words in _one_line(e)


def test_the_unknown_keyword_message_lists_every_setting():
    from dataclasses import fields

    from imitwalk.envs import WalkConfig
    from imitwalk.envs.walk import WalkEnv

    with pytest.raises(ConfigError) as e:
        WalkEnv(foo=1)
    text = _one_line(e)
    for name in (*(f.name for f in fields(WalkConfig)), "render_mode", "setup"):
        assert name in text


def test_weights_given_as_a_dictionary_are_converted():
    from imitwalk.envs import RewardWeights, WalkConfig

    cfg = WalkConfig(weights={"pose": 1.0, "alive": 2})
    assert cfg.weights == RewardWeights(pose=1.0, alive=2.0)
    assert WalkConfig.from_dict(cfg.to_dict()) == cfg
    assert cfg.reward_weights.to_dict()["alive"] == 2.0


def test_the_longest_episode_is_one_simulated_hour():
    from imitwalk.envs import WalkConfig
    from imitwalk.envs.setup import MAX_SECONDS

    assert MAX_SECONDS == 3600.0
    assert WalkConfig(seconds=MAX_SECONDS).seconds == MAX_SECONDS
    with pytest.raises(ConfigError):
        WalkConfig(seconds=MAX_SECONDS + 1)


@pytest.mark.parametrize("seed", [-5, "x", 1.7, True, None, np.float64(2.0)])
def test_a_bad_robot_seed_is_refused_in_one_line(setup, seed):
    env = _env(setup)
    with pytest.raises(ConfigError) as e:
        env.reset(options={"robot_seed": seed})
    assert "whole number ≥ 0" in _one_line(e)


def test_a_robot_seed_may_be_a_numpy_integer_and_an_unknown_option_is_refused(setup):
    env = _env(setup)
    assert env.reset(options={"robot_seed": np.int64(3)})[1]["robot_seed"] == 3
    with pytest.raises(ConfigError) as e:
        env.reset(options={"robot_sed": 3})
    assert "valid: robot_seed" in _one_line(e)
    with pytest.raises(ConfigError) as e:
        env.reset(options=["robot_seed"])
    assert "a dictionary" in _one_line(e)


@pytest.mark.parametrize("engine", ["mujoco", "bullet"])
def test_a_plant_refuses_targets_that_are_not_finite_or_of_another_length(robot, engine):
    """MuJoCo would zero a NaN control silently (driving its joint to 0 rad); the plants
    refuse it, and a wrong length or a posture of another robot, in one line."""
    from imitwalk.sim.mujoco import make_plant

    plant = make_plant(robot, engine=engine)
    plant.reset()
    n = len(plant.joint_names)
    nan = robot.stand.copy()
    nan[3] = np.nan
    bad = [nan, np.full(n, np.inf), np.zeros(n + 1), np.zeros(n - 7), np.zeros((1, n)), "a"]
    for targets in bad:
        with pytest.raises(ConfigError) as e:
            plant.command(targets)
        assert f"expected {n} finite numbers" in _one_line(e)
    with pytest.raises(ConfigError, match=f"{robot.joint_names[3]} is nan"):
        plant.command(nan)
    for q in (np.zeros(n - 7), nan):
        with pytest.raises(ConfigError) as e:
            plant.reset(q)
        assert "posture" in _one_line(e)
    plant.command(list(robot.stand))  # a list of the right length is fine
    assert np.all(np.isfinite(plant.step().joints))


def test_retarget_stays_the_function_whatever_is_imported_first():
    """Importing the subpackage ``imitwalk.retarget`` (as gait_from_motion, learn and the
    pipeline do) used to replace ``iw.retarget`` by the module."""
    code = (
        "import sys, imitwalk as iw\n"
        "iw.gait_from_motion\n"
        "import imitwalk.retarget.pipeline, imitwalk.retarget.search\n"
        "from imitwalk.retarget import Reference\n"
        "fn = sys.modules['imitwalk.retarget.pipeline'].retarget\n"
        "assert callable(iw.retarget) and iw.retarget is fn, iw.retarget\n"
        "from imitwalk import retarget\n"
        "assert retarget is fn\n"
    )
    light = "import sys, imitwalk\nassert 'mujoco' not in sys.modules\n"  # still light
    first = "import imitwalk.retarget.pipeline\n"  # the subpackage before imitwalk's names
    for prog in (light + code, first + code):
        out = subprocess.run([sys.executable, "-c", prog], capture_output=True, text=True)
        assert out.returncode == 0, out.stderr.strip().splitlines()[-1]


def test_gait_from_motion_of_no_frames_is_one_line(robot):
    from dataclasses import replace

    import imitwalk as iw

    m = iw.load_motion(iw.default_clip())
    empty = replace(m, data=m.data[:0], keypoints={k: v[:0] for k, v in m.keypoints.items()})
    with pytest.raises(MocapError) as e:
        iw.gait_from_motion(empty, robot)
    assert "no frames" in _one_line(e)


def test_a_stepping_controller_without_a_style_is_one_line(robot):
    import imitwalk as iw

    with pytest.raises(ConfigError) as e:
        iw.SteppingController(robot, None, iw.StepGains(), 0.01)
    assert "GaitStyle" in _one_line(e)


def test_playback_of_another_robots_reference_is_one_line(
    tiny_reference, shared_robots, tmp_path, capsys
):
    """A hoap2 reference played on op3 (18 joints, not 25): exit 2, one line, no NumPy
    broadcast traceback."""
    from imitwalk.cli.main import main

    _, ref = tiny_reference
    op3 = tmp_path / "op3.json"
    xml = shared_robots / "robotis_op3" / "op3.xml"
    assert main(["robot", "import", str(xml), "--out", str(op3)]) == 0
    capsys.readouterr()
    argv = ["playback", str(ref), "--robot", str(op3), "--scale", "0.4", "--seconds", "1"]
    assert main([*argv, "--models", "1", "--workers", "1"]) == 2
    err = [line for line in capsys.readouterr().err.splitlines() if line.startswith("error")]
    assert len(err) == 1 and "'hoap2', not 'op3'" in err[0], err
