"""The per-tick learner on a tiny budget: its run folder, and an interrupted run resumes to
exactly the uninterrupted one's end (metrics, learned law and log)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from imitwalk.balance.feedback import FeedbackLaw
from imitwalk.balance.tickconfig import TickLearnConfig
from imitwalk.balance.ticklearn import learn_tick
from imitwalk.balance.tickstore import TRIAL_GAINS, load_laws, unstack_episodes
from imitwalk.cli.main import main
from imitwalk.config import apply_overrides
from imitwalk.errors import RunError
from imitwalk.retarget import Reference
from imitwalk.runs import RunDir
from tests.conftest import TICK, sets, strip_log, strip_wall


def _config(extra=()) -> TickLearnConfig:
    return apply_overrides(TickLearnConfig(), [*TICK, *extra])


def _cut_and_resume(ref, robot, out, line: int) -> tuple[dict, dict]:
    """Learn into ``out``, interrupted at the ``line``-th progress line, then resume; the
    checkpoint it was cut at and the resumed run's summary."""
    count = []

    def interrupt(text):
        count.append(text)
        if len(count) == line:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        learn_tick(ref, robot, _config(), out, progress=interrupt)
    rd = RunDir(out)
    assert not rd.exists("metrics.json")
    cut = rd.read_json("checkpoint.json")
    return cut, learn_tick(ref, robot, _config(), out, resume=True)


def _same_law(a, b) -> None:
    a, b = RunDir(a).read_arrays("learned.npz"), RunDir(b).read_arrays("learned.npz")
    assert sorted(a) == sorted(b)
    for k in a:
        np.testing.assert_array_equal(a[k], b[k])


def test_a_tiny_run_writes_its_folder(tick_run):
    rd = RunDir(tick_run)
    for name in (
        "config.json",
        "reference.npz",
        "data.npz",
        "log.jsonl",
        "checkpoint.json",
        "learned.npz",
        "metrics.json",
    ):
        assert rd.exists(name), name
    m, cfg = rd.read_json("metrics.json"), _config()
    assert rd.read_json("config.json")["learner"] == m["learner"] == "tick"
    assert rd.read_json("checkpoint.json")["stage"] == "done"
    # the trial-picked gains, each one of its candidates, and the kept fraction of the law
    assert set(m["feedback_gains"]) == {g.name for g in TRIAL_GAINS}
    for name, value in m["feedback_gains"].items():
        assert value in getattr(cfg.trials, name)
    assert m["trust"] in cfg.lqr.trust
    assert list(m["reference_settings"]) == ["feedforward", "wait"]
    for name, value in m["reference_settings"].items():
        assert value in getattr(cfg.trials, name)
    assert m["scale_reached"] in cfg.scales() and m["scales_passed"] == sorted(m["scales_passed"])
    log = rd.read_log()
    assert [e["stage"] for e in log[:5]] == ["trials"] * 5 and log[-1]["stage"] == "trust"
    # how the reference is played first, with no feedback, then the gains
    for entry, name in zip(log, ("feedforward", "wait"), strict=False):
        assert (entry["gain"], entry["kept"]) == (name, m["reference_settings"][name])
        assert [r["value"] for r in entry["table"]] == list(getattr(cfg.trials, name))
        assert entry["protocol"] == cfg.trials.balance_protocol  # the balance gains' robots
    # ... whose last kept walks, with no feedback, are the pitch gain's first candidate's
    settled = next(r for r in log[1]["table"] if r["value"] == log[1]["kept"])
    assert log[2]["table"][0] == {**settled, "value": 0.0}
    for entry, g in zip(log[2:], TRIAL_GAINS, strict=False):
        assert (entry["gain"], entry["channel"], entry["feature"]) == (g.name, g.channel, g.feature)
        assert entry["protocol"] == (getattr(cfg.trials, g.protocol) if g.protocol else "eval")
        assert [r["value"] for r in entry["table"]] == list(getattr(cfg.trials, g.name))
        kept = next(r for r in entry["table"] if r["value"] == entry["kept"])
        assert kept["falls"] == min(r["falls"] for r in entry["table"])  # fewest falls first
        assert kept["robots"] == cfg.trials.robots  # the kept law walked every trial robot
        # the others walked until they could no longer be kept
        assert all(r["robots"] <= cfg.trials.robots for r in entry["table"])
    schedule = [e for e in log if e["stage"] == "schedule"]
    assert len(schedule) == m["iterations"] >= 2
    assert schedule[0]["explore"] == cfg.lqr.explore and schedule[0]["held_out"] is None
    assert all(e["held_out"]["ratio_to_persistence"] > 0 for e in schedule[1:])
    # the trial-picked law alone first, on the heading trials' robots, whose walks it reuses
    assert [r["fraction"] for r in log[-1]["table"]] == sorted(cfg.lqr.trust)
    alone = log[-1]["table"][0]
    heading = next(e for e in log if e["stage"] == "trials" and e["gain"] == "heading")
    assert alone == {
        "fraction": 0.0,
        **next(
            {k: v for k, v in r.items() if k != "value"}
            for r in heading["table"]
            if r["value"] == heading["kept"]
        ),
    }
    assert alone["robots"] == cfg.trials.heading_robots
    assert log[-1]["kept"] == m["trust"] and log[-1]["scale"] == max(m["scales_passed"])
    # every simulated second is accounted for: trials, schedule and trust
    # (each candidate's trials once: a candidate in two tables was walked once)
    tried = rd.read_json("checkpoint.json")["tried"]
    walked = [r["seconds"] for results in tried.values() for r in results]
    walked += [e["walked_s"] for e in schedule]
    assert m["sim_seconds_used_for_learning"] == pytest.approx(sum(walked))
    # every schedule episode is kept, at its scale; the learned law is the lqr's
    data = unstack_episodes(rd.read_arrays("data.npz"))
    assert [s for s, _ in data] == [e["scale"] for e in schedule for _ in range(cfg.robots)]
    law = FeedbackLaw.from_arrays(rd.read_arrays("learned.npz"), "")
    n = Reference.load(rd.file("reference.npz")).loops.shape[1]
    assert (law.channels, law.features, law.memory) == (cfg.lqr.channels, cfg.lqr.features, True)
    assert law.gains.shape == (n, 4, 2 * 5 + 4) and law.nominal.shape == (n, 5)


def test_the_controllers_a_run_builds(tick_run):
    laws = load_laws(tick_run)
    m = RunDir(tick_run).read_json("metrics.json")
    assert set(laws) == {"learned", "feedback", "fixed"}
    (base,) = laws["feedback"]
    for g in TRIAL_GAINS:
        assert base.gain(g.channel, g.feature) == m["feedback_gains"][g.name]
    assert laws["learned"][0] is base  # the model-based law acts on top of the trial-picked one
    learned = FeedbackLaw.from_arrays(RunDir(tick_run).read_arrays("learned.npz"), "")
    if m["trust"]:
        np.testing.assert_allclose(laws["learned"][1].gains, m["trust"] * learned.gains)
    else:
        assert len(laws["learned"]) == 1
    # the torso's pitch is measured against the nominal robot's, per loop tick; nothing else
    rd = RunDir(tick_run)
    profile = np.asarray(rd.read_json("checkpoint.json")["profiles"]["pitch"])
    n = Reference.load(rd.file("reference.npz")).loops.shape[1]
    assert profile.shape == (n,) and np.isfinite(profile).all() and np.ptp(profile) > 0
    pitch = base.features.index("pitch")
    np.testing.assert_array_equal(base.nominal[:, pitch], profile)
    assert not np.delete(base.nominal, pitch, axis=1).any()
    walks = [k for k in rd.read_json("checkpoint.json")["tried"] if k.startswith("nominal robot")]
    assert walks == ["nominal robot: pitch profile@6s"]
    (fixed,) = laws["fixed"]
    assert (fixed.channels, fixed.features) == (("ankle_pitch",), ("gyro_y",))
    assert fixed.gain("ankle_pitch", "gyro_y") == 0.05


@pytest.mark.parametrize(("line", "stage"), [(3, "trials"), (7, "trials"), (13, "trust")])
def test_an_interrupted_run_resumes_exactly(tick_reference, tick_run, robot, tmp_path, line, stage):
    ref = Reference.load(tick_reference)
    cut, resumed = _cut_and_resume(ref, robot, tmp_path / "cut", line)
    assert cut["stage"] == stage
    whole = RunDir(tick_run)
    assert strip_wall(resumed) == strip_wall(whole.read_json("metrics.json"))
    assert strip_log(RunDir(tmp_path / "cut").read_log()) == strip_log(whole.read_log())
    _same_law(tmp_path / "cut", tick_run)


@pytest.fixture(scope="module")
def cut_in_schedule(tick_reference, robot, tmp_path_factory):
    """A run interrupted in its second schedule iteration, resumed."""
    out = tmp_path_factory.mktemp("cut") / "run"
    cut, resumed = _cut_and_resume(Reference.load(tick_reference), robot, out, 10)
    assert cut["stage"] == "schedule" and cut["iteration"] == 1
    return out, resumed


def test_a_run_interrupted_in_its_schedule_resumes_to_the_same_law(cut_in_schedule, tick_run):
    out, resumed = cut_in_schedule
    assert strip_wall(resumed) == strip_wall(RunDir(tick_run).read_json("metrics.json"))
    _same_law(out, tick_run)
    falls = [(e["stage"], e.get("falls")) for e in RunDir(out).read_log()]
    assert falls == [(e["stage"], e.get("falls")) for e in RunDir(tick_run).read_log()]


def test_a_run_interrupted_in_its_schedule_resumes_to_the_same_log(cut_in_schedule, tick_run):
    out, _ = cut_in_schedule
    assert strip_log(RunDir(out).read_log()) == strip_log(RunDir(tick_run).read_log())


def test_a_run_refuses_other_settings_and_nothing_to_resume(
    tick_reference, tick_run, robot, tmp_path
):
    ref = Reference.load(tick_reference)
    with pytest.raises(RunError, match=r"nothing to resume in .*: no checkpoint\.json"):
        learn_tick(ref, robot, _config(), tmp_path / "none", resume=True)
    with pytest.raises(RunError, match="already holds a run; pass --resume"):
        learn_tick(ref, robot, _config(), tick_run)
    with pytest.raises(RunError, match="was started with other settings; resume with the same"):
        learn_tick(ref, robot, _config(["seed=1"]), tick_run, resume=True)


def test_cli_resume_with_other_settings_is_one_line(tick_reference, tick_run, capsys):
    argv = ["learn", "--reference", str(tick_reference), "--out", str(tick_run), "--resume"]
    assert main([*argv, *sets([*TICK, "trials.robots=3"])]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("error: ") and "other settings" in err[-1]
    assert sum(line.startswith("error") for line in err) == 1 and "Traceback" not in str(err)


def test_a_run_without_the_model_based_law_keeps_the_trial_picked_one(
    tick_reference, robot, tmp_path, capsys
):
    out = tmp_path / "run"
    argv = ["learn", "--reference", str(tick_reference), "--out", str(out), "--json"]
    assert main([*argv, *sets([*TICK, "lqr.enabled=false"])]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["variant"] == "extended" and res["run_dir"] == str(out)
    assert res["iterations"] == 0 and res["trust"] is None
    assert set(res["feedback_gains"]) == {"pitch", "roll", "heading", "torso", "tilt"}
    rd = RunDir(out)
    assert not rd.exists("learned.npz") and rd.read_json("checkpoint.json")["stage"] == "done"
    laws = load_laws(out)
    assert len(laws["learned"]) == 1 and laws["learned"][0] is laws["feedback"][0]
