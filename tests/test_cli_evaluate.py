"""The learn and evaluate commands: what they write, and what they refuse in one line
(exit status 2) before any work."""

from __future__ import annotations

import json
import shutil

import pytest

from imitwalk.cli.main import main
from imitwalk.judge import pushes
from imitwalk.runs import RunDir


@pytest.fixture
def run(tick_run, tmp_path):
    """A copy of the tiny per-tick run (evaluate writes into it)."""
    out = tmp_path / "run"
    shutil.copytree(tick_run, out)
    return out


def _one_line_error(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert err and err[-1].startswith("error: "), err
    assert sum(line.startswith("error") for line in err) == 1 and "Traceback" not in str(err)
    return err[-1]


def test_evaluate_judges_every_controller_and_writes_the_protocols_file(run, capsys):
    argv = ["evaluate", str(run), "--seconds", "3", "--seeds", "2", "--workers", "1", "--json"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert list(out["controllers"]) == ["learned", "feedback", "fixed", "open_loop"]
    assert out == RunDir(run).read_json("protocol_eval.json")
    assert out["protocol"] == {"name": "eval", "version": 1, "path": "eval"}
    assert main([*argv, "--controllers", "learned,open_loop", "--protocol", "hard"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert list(out["controllers"]) == ["learned", "open_loop"] and list(out["comparison"]) == [
        "learned"
    ]
    assert RunDir(run).exists("protocol_hard.json")


def test_evaluate_explains_the_falls_when_asked(run, capsys):
    argv = [
        "evaluate",
        str(run),
        "--seconds",
        "4",
        "--seeds",
        "2",
        "--workers",
        "1",
        "--protocol",
        "hard",
        "--controllers",
        "fixed",
        "--explain-falls",
        "--json",
    ]
    assert main(argv) == 0
    cap = capsys.readouterr()
    side = json.loads(cap.out)["controllers"]["fixed"]
    assert side["falls"] > 0 and "falls saved by one factor at nominal:" in cap.err
    assert sum(r["saved_by"] is not None for r in side["per_seed"]) == side["falls"]
    assert (
        side["falls_no_single_factor"] + sum(side["falls_saved_by_factor"].values())
        >= side["falls"]
    )


@pytest.mark.parametrize(
    ("args", "expect"),
    [
        (
            ["--protocol", "nosuch"],
            "unknown protocol 'nosuch'; valid: bullet, cross, eval, hard, servo, slope",
        ),
        (
            ["--controllers", "nosuch"],
            "unknown controller 'nosuch'; valid: feedback, fixed, learned, open_loop",
        ),
        (
            ["--push-recovery", "--controllers", "learned,nosuch"],
            "unknown controller 'nosuch'; valid: feedback, fixed, learned, open_loop",
        ),
        (["--seeds", "0"], "--seeds 0: expected >= 1"),
        (["--seconds", "inf"], "--seconds inf: expected a finite number of seconds >= 0.1"),
        (["--seconds", "0.001"], "--seconds 0.001: expected a finite number of seconds >= 0.1"),
        (["--scale", "nan"], "--scale nan: expected a stride scale in (0, 1.5]"),
        (["--scale", "-1"], "--scale -1: expected a stride scale in (0, 1.5]"),
        (["--workers", "0"], "--workers 0: expected >= 1 processes (default: one per core)"),
        (
            ["--joint-map", "nosuch.json"],
            "--joint-map nosuch.json needs --robot (the MJCF it maps); without both, the "
            "robot the run records is used",
        ),
        (
            ["--push-recovery", "--explain-falls"],
            "--push-recovery and --explain-falls: push recovery kicks the nominal robot (no "
            "protocol's falls to explain); give one of them",
        ),
    ],
)
def test_evaluate_refuses_in_one_line(run, capsys, args, expect):
    workers = [] if "--workers" in args else ["--workers", "1"]
    assert main(["evaluate", str(run), *workers, *args]) == 2
    assert _one_line_error(capsys) == f"error: {expect}"
    assert not list(run.glob("protocol_*.json")) and not RunDir(run).exists("push_recovery.json")


def test_evaluate_push_recovery_writes_its_table(run, capsys, monkeypatch):
    monkeypatch.setattr(pushes, "survives", lambda job: job.speed < 0.2)
    argv = ["evaluate", str(run), "--push-recovery", "--controllers", "fixed", "--workers", "1"]
    assert main([*argv, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out == RunDir(run).read_json("push_recovery.json")
    assert list(out["controllers"]) == ["fixed"]
    least = out["controllers"]["fixed"]["min_by_direction"]
    assert all(0.2 - out["settings"]["resolution_mps"] <= v < 0.2 for v in least.values())


def test_learn_refuses_a_setting_out_of_range_before_any_work(tick_reference, tmp_path, capsys):
    out = tmp_path / "run"
    argv = ["learn", "--reference", str(tick_reference), "--out", str(out), "--set", "lqr.trust=5"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err == "error: lqr.trust: 5 is outside the valid range 0..2"
    assert not out.exists()


@pytest.mark.parametrize(
    "config", [None, {"format": 1, "learner": "step", "learn": {"robots": 5}, "robot": "hoap2"}]
)
def test_the_demo_refuses_a_finished_run_that_is_not_its_own(tmp_path, capsys, config):
    """A user's own run (or files) is not judged as the demo's and its verdict kept."""
    out = tmp_path / "run"
    out.mkdir()
    (out / "metrics.json").write_text('{"format": 1}\n')
    if config is not None:
        (out / "config.json").write_text(json.dumps(config))
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    assert main(["demo", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert (
        err.startswith(f"error: --out {out} holds a run that is not the demo's") and "\n" not in err
    )
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before


@pytest.mark.parametrize("command", ["learn", "demo"])
def test_an_out_that_is_a_file_is_refused_before_any_work(tmp_path, capsys, command):
    out = tmp_path / "taken"
    out.write_text("not a run\n")
    argv = [command, "--out", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"error: {out} is a file, not a run folder; choose another --out"
    assert out.read_text() == "not a run\n"  # untouched, and nothing retargeted or learned
