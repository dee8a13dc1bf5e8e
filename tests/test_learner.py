"""The learning loop: determinism, checkpoint/resume, and the run folder."""

from __future__ import annotations

import json

import numpy as np
import pytest

from conftest import TINY, strip_wall
from imitwalk.cli import main
from imitwalk.config import apply_overrides
from imitwalk.learnconfig import preset
from imitwalk.learner import learn
from imitwalk.runs import RunDir


@pytest.mark.parametrize("variant", ["faithful", "extended"])
def test_same_seed_same_result(tmp_path, robot, tiny_reference, variant):
    ref, _ = tiny_reference
    cfg = apply_overrides(preset(variant), [*TINY, "train_models=2", "cadences=1,1.12"])
    a = learn(ref, robot, cfg, tmp_path / "a")
    b = learn(ref, robot, cfg, tmp_path / "b")
    assert strip_wall(a) == strip_wall(b)
    if variant == "extended":  # the gain trials ran on their own robots, every candidate
        from imitwalk.perturb import trial_seeds

        trials = a["gain_trials"]
        assert trials["seeds"] == list(trial_seeds(2)) and a["channel_gain"] == trials["gain"]
        assert [r["gain"] for r in trials["table"]] == list(cfg.gains)
        cad = a["cadence_trials"]  # then the cadence, with the gain kept, on the same robots
        assert cad["seeds"] == trials["seeds"] and a["cadence"] == cad["cadence"]
        assert [r["cadence"] for r in cad["table"]] == list(cfg.cadences)
    else:
        assert a["gain_trials"] is None and a["channel_gain"] == 1.0
        assert a["cadence_trials"] is None and a["cadence"] == 1.0
    la, lb = RunDir(tmp_path / "a").read_log(), RunDir(tmp_path / "b").read_log()
    strip = lambda log: [{k: v for k, v in e.items() if k != "wall_seconds"} for e in log]  # noqa: E731
    assert strip(la) == strip(lb)


def test_stratified_trials_run_on_robots_that_cover_the_friction_range(
    tmp_path, robot, tiny_reference
):
    from imitwalk.perturb import trial_seeds

    ref, _ = tiny_reference
    over = [*TINY, "train_models=2", "gain_robots=4", "gains=0,1", "stratify_trials=true"]
    cfg = apply_overrides(preset("extended"), over)
    trials = learn(ref, robot, cfg, tmp_path / "run")["gain_trials"]
    assert trials["seeds"] == list(trial_seeds(4, True, (0.7, 1.0))) != list(trial_seeds(4))


def test_interrupted_run_resumes_to_the_same_end(tmp_path, robot, tiny_reference):
    ref, _ = tiny_reference
    cfg = apply_overrides(preset("extended"), [*TINY, "train_models=2"])
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
    # fresh training robots every iteration, the same ones after a resume
    seeds = [e["seeds"] for e in rd.read_log()]
    assert seeds == [e["seeds"] for e in RunDir(tmp_path / "whole").read_log()]
    assert all(s[0] == 0 for s in seeds) and seeds[0][1:] != seeds[1][1:]


@pytest.mark.parametrize(("line", "key"), [("channel gain 0.5", "gain"), ("cadence 1:", "cadence")])
def test_a_run_interrupted_in_its_trials_resumes_to_the_same_end(
    tmp_path, robot, tiny_reference, line, key
):
    ref, _ = tiny_reference
    sets = [*TINY, "train_models=2", "schedule.stop=0.3", "cadences=1,1.12"]
    cfg = apply_overrides(preset("extended"), sets)
    whole = learn(ref, robot, cfg, tmp_path / "whole")

    def interrupt(text):
        if text.startswith(line):
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        learn(ref, robot, cfg, tmp_path / "cut", progress=interrupt)
    assert key not in RunDir(tmp_path / "cut").read_json("checkpoint.json")
    resumed = learn(ref, robot, cfg, tmp_path / "cut", resume=True)
    assert strip_wall(resumed) == strip_wall(whole)


def test_training_robot_draws_never_overlap_or_meet_an_evaluation_robot():
    from imitwalk.perturb import TRAIN_SEED_BASE, train_seeds

    draws = [train_seeds(6, d) for d in range(50)]
    assert draws[0] == (0, 1001, 1002, 1003, 1004, 1005)
    perturbed = [s for d in draws for s in d[1:]]
    assert len(set(perturbed)) == len(perturbed) and min(perturbed) > TRAIN_SEED_BASE


def test_run_folder_contents(tmp_path, robot, tiny_reference):
    ref, _ = tiny_reference
    cfg = apply_overrides(preset("faithful"), TINY)
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
    assert len(log) == summary["iterations"] >= 2
    for e in log:
        assert {
            "scale",
            "iteration",
            "falls",
            "cost_measured",
            "cost_predicted",
            "prediction",
        } <= set(e)
    assert summary["sim_seconds_used_for_learning"] == pytest.approx(
        sum(e["sim_seconds"] for e in log)
    )
    # the faithful variant's model is judged against the no-action baseline
    reports = [e["prediction"]["tick"] for e in log if "tick" in e["prediction"]]
    assert reports and {"rmse", "baseline_rmse", "ratio"} <= set(reports[0])


def test_refuses_to_overwrite_and_to_resume_nothing(tmp_path, robot, tiny_reference):
    from imitwalk.errors import RunError

    ref, _ = tiny_reference
    cfg = apply_overrides(preset("faithful"), [*TINY, "schedule.stop=0.3", "schedule.iterations=1"])
    with pytest.raises(RunError, match="nothing to resume"):
        learn(ref, robot, cfg, tmp_path / "x", resume=True)
    learn(ref, robot, cfg, tmp_path / "x")
    with pytest.raises(RunError, match="already holds a run"):
        learn(ref, robot, cfg, tmp_path / "x")


def test_cli_learn_and_evaluate(tmp_path, capsys, tiny_reference):
    _, path = tiny_reference
    out = tmp_path / "run"
    argv = ["learn", "--reference", str(path), "--out", str(out), "--json"]
    argv += [a for s in TINY for a in ("--set", s)]
    assert main(argv) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["iterations"] >= 2 and res["run_dir"] == str(out)
    argv = ["evaluate", str(out), "--seconds", "6", "--seeds", "2", "--json", "--workers", "1"]
    assert main(argv) == 0
    ev = json.loads(capsys.readouterr().out)
    keys = {
        "falls",
        "forward_distance_m",
        "forward_speed_mps",
        "progress_ratio",
        "lateral_drift_m",
        "yaw_drift_deg",
        "gyro_rms",
        "joint_rms_error_rad",
        "cycle_period_s",
        "scale_reached",
        "sim_seconds_used_for_learning",
        "wall_seconds_for_learning",
        "iterations",
    }
    assert keys <= set(ev["learned"]) and keys <= set(ev["open_loop"])
    for k in ("progress_ratio", "yaw_drift_deg"):
        assert set(ev["learned"][k]) == {"mean", "min", "max"}
    assert RunDir(out).exists("evaluation.json")
    assert np.isfinite(ev["open_loop"]["forward_distance_m"]["mean"])
    cmp = ev["comparison"]
    assert cmp["robots"] == 2 and 0.0 < cmp["mcnemar_p"] <= 1.0
    assert cmp["learned_fall_rate"] == ev["learned"]["falls"] / 2
    # the channel gain the trials kept is the one evaluation replays
    from imitwalk.evaluate import load_gait

    kept = RunDir(out).read_json("metrics.json")["channel_gain"]
    assert kept in (0.0, 0.5, 1.0) and load_gait(out).config.step.gain == kept
    # so is the cadence: the learned controller plays the loop at it, open loop as retargeted
    rd = RunDir(out)
    rd.write_json("metrics.json", {**rd.read_json("metrics.json"), "cadence": 1.12})
    lg = load_gait(out)
    n = lg.ref.loops.shape[1]
    assert lg.gait.n_ticks == round(n / 1.12) < n and lg.gait.ref.period < lg.ref.period
    assert main([*argv, "--seeds", "1"]) == 0
    fast = json.loads(capsys.readouterr().out)
    assert fast["learned"]["cycle_period_s"] == pytest.approx(lg.gait.ref.period)
    assert fast["open_loop"]["cycle_period_s"] == pytest.approx(lg.ref.period)
    # judged at another scale: its own file, the scale recorded
    argv += ["--scale", "0.3"]
    assert main(argv) == 0
    at = json.loads(capsys.readouterr().out)
    assert at["settings"]["scale"] == 0.3 and RunDir(out).exists("evaluation_scale0.3.json")
    # judged with another channel gain: gain 0 is the reference played open loop
    rd.write_json("metrics.json", {**rd.read_json("metrics.json"), "cadence": 1.0})
    assert main([*argv[:-2], "--gain", "0"]) == 0
    g0 = json.loads(capsys.readouterr().out)
    assert g0["settings"]["channel_gain"] == 0.0 and rd.exists("evaluation_gain0.json")
    for a, b in zip(g0["learned"]["per_seed"], g0["open_loop"]["per_seed"], strict=True):
        assert a["progress_ratio"] == pytest.approx(b["progress_ratio"], abs=1e-6)
    assert main([*argv[:-2], "--gain", "3"]) == 2
    err = capsys.readouterr().err.strip()
    assert "step.gain=3.0: expected 0 <= gain <= 2" in err and len(err.splitlines()) == 1


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
    from imitwalk.controller import stability_cost
    from imitwalk.evaluate import load_gait
    from imitwalk.models import Models, build_policy
    from imitwalk.sim import MujocoPlant, run

    ref, _ = tiny_reference
    cfg = apply_overrides(
        preset("faithful"),
        ["schedule.stop=0.3", "schedule.iterations=3", "schedule.seconds=8", "workers=1"],
    )
    learn(ref, robot, cfg, tmp_path / "run")
    lg = load_gait(tmp_path / "run")
    n = round(8.0 / ref.dt)

    def cost(policy):
        ro = run(MujocoPlant(robot), policy, n, q0=policy.q0, stop_on_fall=False)
        assert not ro.fell
        return float(stability_cost(ro.gyro[len(policy.start) :], np.ones(3)).mean())

    learned = cost(lg.policy(robot))
    nominal = cost(build_policy(lg.gait, lg.scale, lg.config, Models()))
    assert learned < 0.9 * nominal
