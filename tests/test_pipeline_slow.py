"""End-to-end: learn and evaluate on every real walk, and the demo (slow; CI runs them)."""

from __future__ import annotations

import json

import pytest

from imitwalk.cli import main

QUICK = [
    "retarget.search_config.generations=1",
    "retarget.search_config.population=4",
    "retarget.search_config.seconds=6",
    "retarget.search_config.models=2",
    "schedule.stop=0.5",
    "schedule.iterations=2",
    "schedule.seconds=8",
    "train_models=2",
    "gain_robots=3",
    "gain_seconds=8",
]


@pytest.mark.slow
@pytest.mark.parametrize("variant", ["faithful", "extended"])
@pytest.mark.parametrize("clip", ["default", "cmu_bvh/07_04.bvh", "cmu_bvh/07_06.bvh"])
def test_learn_and_evaluate_every_walk(shared_mocap, tmp_path, capsys, clip, variant):
    out = tmp_path / "run"
    argv = ["learn", "--out", str(out), "--variant", variant, "--json"]
    argv += [] if clip == "default" else [str(shared_mocap / clip)]
    argv += [a for s in QUICK for a in ("--set", s)]
    assert main(argv) == 0
    learned = json.loads(capsys.readouterr().out)
    assert learned["variant"] == variant and learned["iterations"] >= 2
    assert main(["evaluate", str(out), "--seconds", "10", "--seeds", "3", "--json"]) == 0
    ev = json.loads(capsys.readouterr().out)
    assert ev["learned"]["seeds"] == ev["open_loop"]["seeds"] == 3
    assert ev["open_loop"]["scale_reached"] == learned["scale_reached"]
    assert ev["comparison"]["robots"] == 3
    if variant == "extended" and learned["scale_reached"] > 0:
        assert learned["channel_gain"] == learned["gain_trials"]["gain"] in (0.0, 0.5, 1.0)


@pytest.mark.slow
def test_demo_writes_a_report(tmp_path, capsys):
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    page = (out / "report.html").read_text()
    assert res["report"] == str(out / "report.html")
    for part in ("Fig. 3", "Fig. 4", "Fig. 6", "Fig. 7", "Fig. 8", "<video", "Evaluation"):
        assert part in page, part
    assert (out / "before_after.mp4").stat().st_size > 10_000
    assert (out / "filmstrip.png").is_file()


@pytest.mark.slow
def test_learn_and_evaluate_on_bullet(tmp_path, capsys):
    """The whole method on the second engine: search, learn and judge on Bullet."""
    out = tmp_path / "run"
    argv = ["learn", "--out", str(out), "--json", "--set", "engine=bullet"]
    argv += ["--set", "retarget.search_config.engine=bullet"]
    argv += [a for s in QUICK for a in ("--set", s)]
    assert main(argv) == 0
    learned = json.loads(capsys.readouterr().out)
    assert learned["iterations"] >= 2
    assert main(["evaluate", str(out), "--seconds", "10", "--seeds", "2", "--json"]) == 0
    ev = json.loads(capsys.readouterr().out)
    assert ev["settings"]["engine"] == "bullet"  # the engine the run learned on
    assert (out / "evaluation.json").is_file() and ev["learned"]["seeds"] == 2
