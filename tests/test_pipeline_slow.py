"""End-to-end: learn and evaluate on every real walk (the C3D treadmill one too), and the
demo (slow; CI runs them)."""

from __future__ import annotations

import json

import pytest

from imitwalk.balance.tickconfig import LqrConfig, TrialConfig
from imitwalk.cli.main import main
from tests.conftest import TICK, sets

#: A small reference search.
SEARCH = [
    "retarget.search_config.generations=1",
    "retarget.search_config.population=4",
    "retarget.search_config.seconds=6",
    "retarget.search_config.models=2",
]
#: A short learning run of each variant.
QUICK = {
    "faithful": [
        "schedule.stop=0.5",
        "schedule.iterations=2",
        "schedule.seconds=8",
        "train_models=2",
    ],
    "extended": [
        "stop=0.5",
        "iterations=2",
        "robots=2",
        "seconds=8",
        "trials.robots=3",
        "trials.seconds=8",
        "choice.robots=3",
        "choice.seconds=10",
    ],
}


@pytest.mark.slow
@pytest.mark.parametrize("variant", ["faithful", "extended"])
@pytest.mark.parametrize(
    "clip", ["default", "cmu_bvh/07_04.bvh", "cmu_bvh/07_06.bvh", "c3d/treadmill_events.c3d"]
)
def test_learn_and_evaluate_every_walk(shared_mocap, tmp_path, capsys, clip, variant):
    out = tmp_path / "run"
    argv = ["learn", "--out", str(out), "--variant", variant, "--json"]
    argv += [] if clip == "default" else [str(shared_mocap / clip)]
    argv += sets([*SEARCH, *QUICK[variant]])
    assert main(argv) == 0
    learned = json.loads(capsys.readouterr().out)
    assert learned["variant"] == variant and learned["iterations"] >= 2
    assert ("reference_choice" in learned) == (variant == "extended")
    assert main(["evaluate", str(out), "--seconds", "10", "--seeds", "3", "--json"]) == 0
    ev = json.loads(capsys.readouterr().out)
    sides = ev["controllers"]
    assert sides["learned"]["robots"] == sides["open_loop"]["robots"] == 3
    assert ev["settings"]["scale"] == learned["scale_reached"]
    assert ev["comparison"]["learned"]["robots"] == 3
    if variant == "extended":  # every trial-picked gain is one of its candidates
        trials = TrialConfig()
        assert set(learned["feedback_gains"]) == {"pitch", "roll", "heading", "torso", "tilt"}
        for name, value in learned["feedback_gains"].items():
            assert value in getattr(trials, name), name
        assert learned["trust"] in LqrConfig().trust
        assert set(sides) == {"learned", "feedback", "fixed", "open_loop"}


@pytest.mark.slow
@pytest.mark.parametrize(
    "clip", ["default", "cmu_bvh/07_04.bvh", "cmu_bvh/07_06.bvh", "c3d/treadmill_events.c3d"]
)
def test_the_stepping_gait_learns_and_walks_every_walk(shared_mocap, tmp_path, capsys, clip):
    """The default learner on every walking clip, on a small budget: it learns, and the
    learned gains walk eval's first robots without a fall at the clip's full stride."""
    out = tmp_path / "run"
    argv = ["learn", "--out", str(out), "--json"]
    argv += [] if clip == "default" else [str(shared_mocap / clip)]
    argv += sets(["generations=2", "population=4", "robots=2", "seconds=6", "final_robots=2"])
    assert main(argv) == 0
    learned = json.loads(capsys.readouterr().out)
    assert learned["learner"] == "step" and learned["iterations"] == 2
    assert main(["evaluate", str(out), "--seconds", "15", "--seeds", "4", "--json"]) == 0
    ev = json.loads(capsys.readouterr().out)
    assert set(ev["controllers"]) == {"learned", "default"}
    assert ev["controllers"]["learned"]["falls"] == 0
    assert ev["controllers"]["learned"]["progress_ratio_min"] > 0.6


@pytest.mark.slow
def test_demo_writes_a_report(tmp_path, capsys):
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    page = (out / "report.html").read_text()
    assert res["report"] == str(out / "report.html")
    for part in ("The human and the robot", "cadence", "<video", "Evaluation", "Learning"):
        assert part in page, part
    assert "Protocol <b>eval</b>" in page and (out / "protocol_eval.json").is_file()
    assert json.loads((out / "protocol_eval.json").read_text())["robot"]["name"] == "hoap2"
    assert res["learned_falls"].endswith("/8") and res["default_falls"].endswith("/8")
    assert (out / "before_after.mp4").stat().st_size > 10_000
    assert (out / "filmstrip.png").is_file()


@pytest.mark.slow
def test_learn_and_evaluate_on_bullet(tmp_path, capsys):
    """The whole method on the second engine: search, learn and judge on Bullet."""
    out = tmp_path / "run"
    argv = ["learn", "--variant", "extended", "--out", str(out), "--json", "--set", "engine=bullet"]
    argv += ["--set", "retarget.search_config.engine=bullet"]
    argv += sets([*SEARCH, *TICK, "start=0.3", "step=0.1", "stop=0.4", "choice.robots=2"])
    assert main(argv) == 0
    learned = json.loads(capsys.readouterr().out)
    assert learned["iterations"] >= 2
    assert json.loads((out / "config.json").read_text())["learn"]["engine"] == "bullet"
    assert json.loads((out / "choice.json").read_text())["kept"] in ("searched", "closed")
    argv = ["evaluate", str(out), "--seconds", "10", "--seeds", "2", "--json"]
    assert main([*argv, "--protocol", "bullet"]) == 0
    ev = json.loads(capsys.readouterr().out)
    assert ev["settings"]["engine"] == "bullet"
    assert (out / "protocol_bullet.json").is_file() and ev["controllers"]["learned"]["robots"] == 2
