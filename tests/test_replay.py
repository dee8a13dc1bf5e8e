"""A finished run loaded to replay: its controllers by name, for either learner."""

from __future__ import annotations

import numpy as np
import pytest

from imitwalk.balance.feedback import TickPolicy
from imitwalk.config import apply_overrides
from imitwalk.errors import ConfigError, RunError
from imitwalk.judge.replay import OPEN_LOOP, load_run
from imitwalk.paper.learnconfig import LearnConfig
from imitwalk.paper.learner import learn
from imitwalk.paper.policy import WalkPolicy
from imitwalk.runs import RunDir
from tests.conftest import TINY


@pytest.fixture(scope="module")
def faithful_run(robot, tiny_reference, tmp_path_factory):
    out = tmp_path_factory.mktemp("faithful") / "run"
    learn(tiny_reference[0], robot, apply_overrides(LearnConfig(), TINY), out)
    return out


def test_a_per_tick_run_builds_learned_feedback_fixed_and_open_loop(tick_run, robot):
    lr = load_run(tick_run)
    m = RunDir(tick_run).read_json("metrics.json")
    assert lr.learner == "tick" and lr.engine == "mujoco" and lr.gait is None
    assert lr.controllers() == ("learned", "feedback", "fixed", OPEN_LOOP)
    assert lr.scale == m["scale_reached"] and lr.metrics.to_dict() == m
    for name in ("learned", "feedback", "fixed"):
        policy = lr.policy(name, robot, seconds=4.0)
        assert isinstance(policy, TickPolicy) and policy.laws == lr.laws[name]
        assert policy.explore == 0.0  # a replay does not explore
        np.testing.assert_array_equal(policy.q_ref, lr.ref.trajectory(lr.scale, 4.0))


def test_the_learned_controllers_add_the_kept_feedforward(tick_run, robot):
    from dataclasses import replace

    from imitwalk.retarget.feedforward import walk_offsets

    lr = load_run(tick_run)
    assert lr.settings == lr.metrics.tick().reference_settings
    lr = replace(lr, settings={"feedforward": 0.5, "wait": 0.0})
    off = walk_offsets(lr.ref, robot, lr.scale, 4.0, 1.0)[: len(lr.ref.trajectory(lr.scale, 4.0))]
    for name in ("learned", "feedback", "fixed"):
        policy = lr.policy(name, robot, seconds=4.0)
        want = 0.0 if name == "fixed" else 0.5  # the hand-set baseline plays it as it is
        np.testing.assert_allclose(policy.q_cmd, policy.q_ref + want * off)
        np.testing.assert_array_equal(policy.q_ref, lr.ref.trajectory(lr.scale, 4.0))
    # a law equal to another's is its twin only with the same feedforward
    twin = replace(lr, laws={**lr.laws, "fixed": lr.laws["feedback"]})
    assert twin.twin("fixed") == "fixed"
    assert replace(twin, settings=None).twin("fixed") in ("learned", "feedback")


def test_open_loop_is_the_reference_played_as_it_is(tick_run, robot):
    lr = load_run(tick_run)
    q = lr.ref.trajectory(0.8, 3.0)
    policy = lr.policy(OPEN_LOOP, robot, scale=0.8, seconds=3.0)
    np.testing.assert_array_equal(policy.q0, q[0])
    for k in (0, 1, 150, len(q) - 1):
        np.testing.assert_array_equal(policy(k, None), q[k])
    np.testing.assert_array_equal(policy(len(q) + 10, None), q[-1])  # it holds the last


def test_an_unknown_controller_lists_the_runs_own(tick_run, faithful_run, robot):
    with pytest.raises(ConfigError) as err:
        load_run(tick_run).policy("nosuch", robot)
    assert str(err.value) == (
        "unknown controller 'nosuch'; valid: feedback, fixed, learned, open_loop"
    )
    with pytest.raises(ConfigError, match=r"unknown controller 'feedback'; valid: learned, open_"):
        load_run(faithful_run).policy("feedback", robot)


def test_a_faithful_run_builds_the_papers_controller(faithful_run, robot):
    lr = load_run(faithful_run)
    assert lr.learner == "faithful" and lr.laws is None and lr.gait is not None
    assert lr.controllers() == ("learned", OPEN_LOOP)
    policy = lr.policy("learned", robot, scale=0.4)
    assert isinstance(policy, WalkPolicy) and policy.scale == 0.4
    assert policy.selector is not None  # the search of eqs. 5-13 with the fitted model
    assert lr.scale == (lr.metrics.scale_reached or 0.3)


def test_a_folder_that_is_not_a_run_is_said_in_one_line(tmp_path):
    with pytest.raises(RunError, match=r"config\.json not found: is .* a finished imitwalk run"):
        load_run(tmp_path)


def test_an_incomplete_metrics_file_is_a_one_line_error(tmp_path, capsys):
    from imitwalk.cli.main import main

    rd = RunDir(tmp_path)
    rd.write_json("config.json", {"learner": "tick", "learn": {}})
    rd.write_json("metrics.json", {"learner": "tick", "scale_reached": 1.0})
    with pytest.raises(RunError, match=r"metrics\.json lacks scales_passed, iterations"):
        load_run(tmp_path)
    assert main(["evaluate", str(tmp_path), "--seeds", "1", "--seconds", "1"]) == 2
    errors = [x for x in capsys.readouterr().err.splitlines() if x.startswith("error:")]
    assert len(errors) == 1 and "lacks" in errors[0] and not rd.exists("protocol_eval.json")
