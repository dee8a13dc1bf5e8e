"""The paper's learning loop (the faithful variant): determinism, checkpoint/resume, the run
folder, and learn + evaluate through the CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest

from imitwalk.cli.main import main
from imitwalk.config import apply_overrides
from imitwalk.paper.learnconfig import LearnConfig
from imitwalk.paper.learner import learn
from imitwalk.runs import RunDir
from tests.conftest import TINY, sets, strip_log, strip_wall


def test_same_seed_same_result(tmp_path, robot, tiny_reference):
    ref, _ = tiny_reference
    cfg = apply_overrides(LearnConfig(), [*TINY, "train_models=2"])
    a = learn(ref, robot, cfg, tmp_path / "a")
    b = learn(ref, robot, cfg, tmp_path / "b")
    assert strip_wall(a) == strip_wall(b)
    la, lb = RunDir(tmp_path / "a").read_log(), RunDir(tmp_path / "b").read_log()
    assert strip_log(la) == strip_log(lb)


def test_interrupted_run_resumes_to_the_same_end(tmp_path, robot, tiny_reference):
    ref, _ = tiny_reference
    cfg = apply_overrides(LearnConfig(), [*TINY, "train_models=2"])
    whole = learn(ref, robot, cfg, tmp_path / "whole")
    calls = []

    def interrupt(line):
        calls.append(line)
        if len(calls) == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        learn(ref, robot, cfg, tmp_path / "cut", progress=interrupt)
    rd = RunDir(tmp_path / "cut")
    assert rd.read_json("checkpoint.json")["total_iterations"] == 2
    assert not rd.exists("metrics.json")
    resumed = learn(ref, robot, cfg, tmp_path / "cut", resume=True)
    assert strip_wall(resumed) == strip_wall(whole)
    log_w = [e["falls"] for e in RunDir(tmp_path / "whole").read_log()]
    assert [e["falls"] for e in rd.read_log()] == log_w
    assert strip_log(rd.read_log()) == strip_log(RunDir(tmp_path / "whole").read_log())
    # the same training robots after a resume, the nominal one first
    seeds = [e["seeds"] for e in rd.read_log()]
    assert seeds == [e["seeds"] for e in RunDir(tmp_path / "whole").read_log()]
    assert all(s[0] == 0 for s in seeds)


def test_training_robot_draws_never_overlap_or_meet_an_evaluation_robot():
    from imitwalk.sim.perturb import train_seeds
    from imitwalk.sim.seeds import TRAIN_SEED_BASE

    draws = [train_seeds(6, d) for d in range(50)]
    assert draws[0] == (0, 1001, 1002, 1003, 1004, 1005)
    perturbed = [s for d in draws for s in d[1:]]
    assert len(set(perturbed)) == len(perturbed) and min(perturbed) > TRAIN_SEED_BASE


def test_run_folder_contents(tmp_path, robot, tiny_reference):
    ref, _ = tiny_reference
    cfg = apply_overrides(LearnConfig(), TINY)
    summary = learn(ref, robot, cfg, tmp_path / "run")
    rd = RunDir(tmp_path / "run")
    for name in (
        "config.json",
        "reference.npz",
        "data.npz",
        "log.jsonl",
        "checkpoint.json",
        "metrics.json",
    ):
        assert rd.exists(name), name
    log = rd.read_log()
    assert len(log) == summary.iterations >= 2
    for e in log:
        assert {
            "scale",
            "iteration",
            "falls",
            "cost_measured",
            "cost_predicted",
            "prediction",
        } <= set(e)
    assert summary.sim_seconds_used_for_learning == pytest.approx(
        sum(e["sim_seconds"] for e in log)
    )
    # the faithful variant's model is judged against the no-action baseline
    reports = [e["prediction"] for e in log if e["prediction"]]
    assert reports and {"rmse", "baseline_rmse", "ratio"} <= set(reports[0])


def test_refuses_to_overwrite_and_to_resume_nothing(tmp_path, robot, tiny_reference):
    from imitwalk.errors import RunError

    ref, _ = tiny_reference
    cfg = apply_overrides(LearnConfig(), [*TINY, "schedule.stop=0.3", "schedule.iterations=1"])
    with pytest.raises(RunError, match="nothing to resume"):
        learn(ref, robot, cfg, tmp_path / "x", resume=True)
    learn(ref, robot, cfg, tmp_path / "x")
    with pytest.raises(RunError, match="already holds a run"):
        learn(ref, robot, cfg, tmp_path / "x")


def test_cli_learn_and_evaluate(tmp_path, capsys, tiny_reference):
    _, path = tiny_reference
    out = tmp_path / "run"
    argv = ["learn", "--reference", str(path), "--out", str(out), "--json"]
    argv += ["--variant", "faithful", *sets(TINY)]
    assert main(argv) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["iterations"] >= 2 and res["run_dir"] == str(out)
    assert res["variant"] == "faithful" and res["learner"] == "faithful"
    argv = ["evaluate", str(out), "--seconds", "6", "--seeds", "2", "--json", "--workers", "1"]
    assert main(argv) == 0
    ev = json.loads(capsys.readouterr().out)
    assert set(ev["controllers"]) == {"learned", "open_loop"}
    keys = {
        "robots",
        "survived",
        "falls",
        "survival",
        "survival_ci95",
        "distance_m",
        "speed_mps",
        "abs_yaw_deg",
        "progress_ratio_min",
        "falls_by_furthest_factor",
        "per_seed",
    }
    for side in ev["controllers"].values():
        assert keys <= set(side) and side["robots"] == 2
        assert [r["seed"] for r in side["per_seed"]] == [0, 1]
    assert RunDir(out).exists("protocol_eval.json")
    assert np.isfinite(ev["controllers"]["open_loop"]["distance_m"])
    cmp = ev["comparison"]["learned"]
    assert cmp["robots"] == 2 and 0.0 < cmp["mcnemar_p"] <= 1.0
    assert cmp["learned_fall_rate"] == ev["controllers"]["learned"]["falls"] / 2
    assert cmp["open_loop_fall_rate"] == ev["controllers"]["open_loop"]["falls"] / 2
    # judged at another scale: its own file, the scale recorded
    argv += ["--scale", "0.3"]
    assert main(argv) == 0
    at = json.loads(capsys.readouterr().out)
    assert at["settings"]["scale"] == 0.3 and RunDir(out).exists("protocol_eval_scale0.3.json")


def test_evaluate_a_folder_that_is_not_a_run(tmp_path, capsys):
    assert main(["evaluate", str(tmp_path)]) == 2
    assert "not found" in capsys.readouterr().err


@pytest.mark.xfail(
    strict=True,
    reason="measured: the paper's per-tick learner does not lower Γ(ω) on this robot once "
    "both controllers start from the same posture (1.08× and 1.01× of nominal, seeds 0 and 1)",
)
def test_a_short_faithful_run_lowers_the_measured_gyro_cost(tmp_path, robot, tiny_reference):
    """The paper's claim at its smallest: after a few iterations at scale 0.3 the learned
    controller's measured eq.-6 cost Γ(ω) is lower than that of the same representation
    following the nominal loop without the search (nominal robot, same 8 s, both from the
    start-up's first posture, as in learning and evaluation). It passed while learning
    started from the standing keyframe and this comparison from the keyframe too; with
    the same start everywhere it does not: a known failure, kept strict so that a learner
    that does lower the cost is noticed."""
    from imitwalk.paper.controller import stability_cost
    from imitwalk.paper.evaluate import load_gait
    from imitwalk.paper.models import build_policy
    from imitwalk.sim.mujoco import MujocoPlant, run

    ref, _ = tiny_reference
    cfg = apply_overrides(
        LearnConfig(),
        ["schedule.stop=0.3", "schedule.iterations=3", "schedule.seconds=8", "workers=1"],
    )
    learn(ref, robot, cfg, tmp_path / "run")
    lg = load_gait(tmp_path / "run")
    n = round(8.0 / ref.dt)

    def cost(policy):
        ro = run(MujocoPlant(robot), policy, n, q0=policy.q0, stop_on_fall=False)
        assert not ro.fell
        return float(stability_cost(ro.gyro[len(policy.start) :], np.ones(3)).mean())

    learned = cost(lg.policy())
    nominal = cost(build_policy(lg.gait, lg.scale, lg.config, None))
    assert learned < 0.9 * nominal
