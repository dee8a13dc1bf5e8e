"""PPO on the environment (``imitwalk rl``): the run folder, resume, the judge playing the
policy through NumPy alone, the network's round trip, and bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

from imitwalk.errors import ConfigError, RunError

pytest.importorskip("stable_baselines3")

#: A tiny run: one rollout of 1,024 ticks in one process.
TINY = ["--budget", "10", "--envs", "1", "--seconds", "3"]


def _cli(argv, capsys):
    from imitwalk.cli import main

    code = main(argv)
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.fixture(scope="module")
def residual_run(tmp_path_factory):
    from imitwalk.cli import main

    out = tmp_path_factory.mktemp("rl") / "run"
    assert main(["rl", "--out", str(out), "--residual", "--protocol", "eval", *TINY]) == 0
    return out


def test_a_run_holds_what_the_judge_needs(residual_run):
    for name in (
        "config.json",
        "style.json",
        "gains.json",
        "actor.json",
        "policy.npz",
        "ppo.zip",
        "log.jsonl",
        "metrics.json",
        "checkpoint.json",
    ):
        assert (residual_run / name).is_file(), name
    metrics = json.loads((residual_run / "metrics.json").read_text())
    assert metrics["learner"] == "rl" and metrics["sim_seconds_used_for_learning"] >= 10


def test_the_judge_plays_the_policy_beside_the_stepping_gait(residual_run):
    from imitwalk.judge.replay import load_run
    from imitwalk.judge.verdict import judge_protocol
    from imitwalk.robots import load_robot
    from imitwalk.sim.protocol import load_protocol

    loaded = load_run(residual_run)
    assert loaded.controllers() == ("rl", "default")
    robot = load_robot("hoap2")
    out = judge_protocol(str(residual_run), robot, load_protocol("eval"), 2, 2.0, workers=1)
    assert set(out.controllers) == {"rl", "default"} and "rl" in out.comparison


def test_an_exported_policy_walks_through_the_runtime_as_the_judge_walks_it(residual_run, tmp_path):
    """``imitwalk export`` of a residual policy: the runtime, handed only sensor vectors,
    commands what the judge's policy commands, tick for tick."""
    from imitwalk.judge.export import export_run
    from imitwalk.judge.replay import load_run
    from imitwalk.robots import load_robot
    from imitwalk.runtime import Controller
    from imitwalk.sim.mujoco import make_plant, run

    robot = load_robot("hoap2")
    out = export_run(residual_run, robot, tmp_path / "policy")
    ctl = Controller.load(out)
    assert ctl.bundle.kind == "rl-residual"
    loaded = load_run(residual_run)
    opts = loaded.step_gait.sim_options()
    judged = run(make_plant(robot, opts), loaded.policy("rl", robot), 200)

    def policy(k, obs):
        v = ctl.sensors.vector(obs)
        return ctl.reset(v) if k == 0 else ctl.step(v)

    mine = run(make_plant(robot, opts), policy, 200, q0=ctl.q0)
    assert np.array_equal(mine.q_cmd, judged.q_cmd)


def test_a_kick_is_walked_with_the_policy(residual_run):
    """Push recovery walks the policy like any controller (one kick, one walk)."""
    from imitwalk.judge.pushes import PushJob, survives
    from imitwalk.robots import load_robot

    job = PushJob(str(residual_run), load_robot("hoap2"), "rl", 1.0, "left", 0, 0.05)
    assert survives(job) in (True, False)


def test_the_policy_in_numpy_is_the_trained_one(residual_run):
    """The judge's network (NumPy) gives the PPO model's own deterministic action."""
    import torch
    from stable_baselines3 import PPO

    from imitwalk.rl.network import MLP

    model = PPO.load(residual_run / "ppo.zip", device="cpu")
    net = MLP.load(residual_run / "policy.npz")
    x = np.random.default_rng(0).normal(size=(5, net.sizes[0])).astype(np.float32)
    with torch.no_grad():
        mean = model.policy.get_distribution(torch.as_tensor(x)).distribution.mean.numpy()
    np.testing.assert_allclose(np.stack([net(r) for r in x]), mean, atol=1e-5)


def test_the_actor_commands_what_the_environment_commands(residual_run):
    """Tick for tick on one robot, the judge's actor and the environment (with the
    policy's actions) send the same joint targets."""
    from dataclasses import replace

    import gymnasium as gym

    from imitwalk.envs.setup import WalkConfig, build_setup
    from imitwalk.envs.walk import WalkEnv
    from imitwalk.judge.replay import load_run
    from imitwalk.sim.mujoco import MujocoPlant, run

    cfg = json.loads((residual_run / "config.json").read_text())
    loaded = load_run(residual_run)
    env = WalkEnv(setup=build_setup(WalkConfig.from_dict(cfg["env"])))
    _, net = loaded.actor
    wrapped = gym.wrappers.RescaleAction(env, -1.0, 1.0)
    obs, _ = wrapped.reset(options={"robot_seed": 4})
    sent = []
    for _ in range(60):
        u = np.clip(net(obs), -1, 1).astype(np.float32)
        targets = (
            np.clip(
                env.setup.low + (u + 1) * (env.setup.high - env.setup.low) / 2,
                env.setup.low,
                env.setup.high,
            )
            + env.base
        )
        sent.append(targets)
        obs, *_ = wrapped.step(u)
    s = env.setup
    draw = s.protocol.draw(4, s.robot, seconds=s.config.seconds)
    plant = MujocoPlant(s.robot, replace(draw.options, control_hz=1.0 / s.dt))
    ro = run(plant, loaded.policy("rl", s.robot), len(sent))
    np.testing.assert_allclose(ro.q_cmd, s.robot.clip(np.array(sent)), atol=1e-5)


def test_resume_continues_and_refuses_other_settings(tmp_path, capsys):
    import torch

    out = tmp_path / "run"
    args = ["rl", "--out", str(out), "--protocol", "eval", *TINY]
    threads = torch.get_num_threads()
    assert _cli(args, capsys)[0] == 0
    assert torch.get_num_threads() == threads  # trained on one thread, the caller's restored
    first = (out / "log.jsonl").read_text().splitlines()
    code, _, err = _cli(args, capsys)
    assert code == 2 and "already holds a run" in err
    more = [a if a != "10" else "25" for a in args]  # a larger budget, resumed
    assert _cli([*more, "--resume"], capsys)[0] == 0
    lines = (out / "log.jsonl").read_text().splitlines()
    assert lines[: len(first)] == first and len(lines) > len(first)
    steps = [json.loads(x)["timesteps"] for x in lines]
    assert steps == sorted(steps) and steps[-1] >= 2500
    code, _, err = _cli([*more, "--resume", "--seed", "3"], capsys)
    assert code == 2 and "other settings" in err


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--budget", "0"], "budget=0"),
        (["--budget", "nan"], "budget=nan"),
        (["--protocol", "nowhere"], "valid: "),
        (["--protocol", "bullet"], "valid engines: mujoco"),
        (["--robot", "asimo"], "valid: hoap2"),
        (["--base", "x"], "pass --residual too"),
        (["--envs", "0"], "envs=0"),
        (["no/such/clip.bvh"], "no/such/clip.bvh"),
    ],
)
def test_bad_input_gets_one_line_and_status_2(extra, words, tmp_path, capsys):
    code, _, err = _cli(["rl", "--out", str(tmp_path / "r"), *extra], capsys)
    assert code == 2 and words in err and err.count("\n") == 1
    assert not (tmp_path / "r").exists()


def test_a_damaged_policy_is_refused_in_one_line(residual_run, tmp_path):
    import shutil

    from imitwalk.judge.replay import load_run

    bad = tmp_path / "bad"
    shutil.copytree(residual_run, bad)
    (bad / "policy.npz").write_bytes(b"not a zip")
    with pytest.raises(RunError, match="expected a policy network"):
        load_run(bad)
    (bad / "policy.npz").unlink()
    shutil.copy(residual_run / "policy.npz", bad / "policy.npz")
    (bad / "actor.json").write_text("[]")
    with pytest.raises(RunError, match="not an object: a policy's spec"):
        load_run(bad)


def test_the_network_round_trips(tmp_path):
    from imitwalk.rl.network import MLP

    rng = np.random.default_rng(1)
    net = MLP((rng.normal(size=(4, 3)), rng.normal(size=(2, 4))), (np.zeros(4), np.ones(2)))
    path = net.save(tmp_path / "n.npz")
    back = MLP.load(path)
    x = rng.normal(size=3)
    np.testing.assert_array_equal(net(x), back(x))
    with pytest.raises(ConfigError, match="valid: relu, tanh"):
        MLP(net.weights, net.biases, "sigmoid")


@pytest.mark.slow
def test_a_short_ppo_run_is_judged_like_any_other(tmp_path, capsys):
    """Two processes of PPO residual on the stepping gait, then `imitwalk evaluate`: the
    verdict puts the policy beside the gait it adds to, on the same robots."""
    out = tmp_path / "run"
    code, _, err = _cli(["rl", "--out", str(out), "--residual", "--budget", "150"], capsys)
    assert code == 0, err
    code, text, err = _cli(
        ["evaluate", str(out), "--seeds", "4", "--seconds", "10", "--json"], capsys
    )
    assert code == 0, err
    verdict = json.loads(text)
    assert set(verdict["controllers"]) == {"rl", "default"}
    assert verdict["controllers"]["rl"]["robots"] == 4
    log = [json.loads(x) for x in (out / "log.jsonl").read_text().splitlines()]
    assert log[-1]["sim_seconds"] >= 150 and log[-1]["episode_return"] is not None


@pytest.mark.slow
def test_a_ppo_run_has_a_report(residual_run):
    from imitwalk.evidence.report import write_report

    page = write_report(residual_run, seconds=4.0).read_text()
    assert "PPO policy" in page and "stepping gait" in page and "<video" in page
