"""The back-off (``LearnConfig.back_off_to``): give back scale when the gain trials at the
top scale still fall (:func:`imitwalk.tuning.back_off`), or when its consolidation does
(``back_off_when``, :func:`imitwalk.tuning.give_back_scale`)."""

from __future__ import annotations

from dataclasses import replace

import pytest

from conftest import TINY, strip_wall
from imitwalk import tuning
from imitwalk.config import apply_overrides
from imitwalk.errors import ConfigError
from imitwalk.learnconfig import preset
from imitwalk.runs import RunDir
from imitwalk.trust import GainChoice

GAINS = (0.0, 0.5, 1.0)


def _trials(falls: tuple[int, ...], scale: float | None = None) -> dict:
    """Gain trials as the learner keeps them: the best of ``falls`` (per gain) kept."""
    table = [{"gain": g, "falls": f} for g, f in zip(GAINS, falls, strict=True)]
    kept = GAINS[falls.index(min(falls))]
    out = GainChoice(kept, (0, 100001), table, sim_seconds=60.0, wall_seconds=2.0).to_dict()
    return out if scale is None else {"scale": scale, **out}


def _fake_tune(falls_by_scale: dict, calls: list):
    def tune(gait, robot, config, data, scale, key, values, gain, progress):
        calls.append((scale, key, tuple(values)))
        t = _trials(falls_by_scale[scale])
        return GainChoice(t["gain"], tuple(t["seeds"]), t["table"], 60.0, 2.0, key)

    return tune


def _state(top_falls: tuple[int, ...]) -> dict:
    passed = [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9]
    return {"passed": passed, "gain": _trials(top_falls), "sim_seconds": 0.0, "wall_seconds": 0.0}


def test_kept_falls_reads_the_kept_gains_row():
    assert tuning.kept_falls(_trials((2, 1, 4))) == 1
    assert tuning.kept_falls(_trials((0, 3, 3))) == 0


@pytest.mark.parametrize(
    ("falls_by_scale", "floor", "settled", "tried"),
    [
        ({0.8: (3, 0, 2)}, 0.8, 0.8, [0.8]),  # fewer falls one scale down: settle there
        ({0.8: (3, 2, 2)}, 0.8, 0.9, [0.8]),  # as many: keep the top (ties: higher scale)
        ({0.8: (3, 1, 0), 0.7: (2, 0, 0)}, 0.7, 0.8, [0.8]),  # none fall at 0.8: stop there
        ({0.8: (3, 2, 1), 0.7: (2, 0, 0)}, 0.7, 0.7, [0.8, 0.7]),  # still falls: go on lower
        ({0.8: (3, 2, 1), 0.7: (2, 0, 0)}, 0.8, 0.8, [0.8]),  # never below back_off_to
    ],
)
def test_back_off_settles_where_the_trials_fall_least(
    monkeypatch, falls_by_scale, floor, settled, tried
):
    calls: list = []
    monkeypatch.setattr(tuning, "tune", _fake_tune(falls_by_scale, calls))
    cfg = preset("extended", gains=GAINS, back_off_to=floor)
    state = _state((2, 2, 3))  # the kept gain falls on 2 trial robots at the top, 0.9
    top_trials = state["gain"]
    assert tuning.back_off(None, None, cfg, {}, state, None) == settled
    assert [c[0] for c in calls] == tried and all(c[1:] == ("gain", GAINS) for c in calls)
    record = state["back_off"]
    assert record["from"] == 0.9 and record["scale"] == settled
    assert [t["scale"] for t in record["trials"]] == tried
    assert state["sim_seconds"] == 60.0 * len(tried)  # the trials' cost is counted
    if settled == 0.9:
        assert state["gain"] == top_trials
    else:
        assert state["gain"]["scale"] == settled
        assert state["gain"]["gain"] == _trials(falls_by_scale[settled])["gain"]
    # a second call (a resume after the back-off was checkpointed) runs no trials
    assert tuning.back_off(None, None, cfg, {}, state, None) == settled
    assert len(calls) == len(tried)


def test_no_back_off_when_the_top_scale_walks_on_every_trial_robot(monkeypatch):
    monkeypatch.setattr(tuning, "tune", None)  # never called
    state = _state((1, 0, 2))
    cfg = preset("extended", back_off_to=0.5)
    assert tuning.back_off(None, None, cfg, {}, state, None) == 0.9
    assert state["back_off"] == {"from": 0.9, "scale": 0.9, "trials": [], "consolidation": []}


def test_back_off_settings():
    assert preset("extended").back_off_to is None
    assert apply_overrides(preset("extended"), ["back_off_to=0.8"]).back_off_to == 0.8
    with pytest.raises(ConfigError, match="back_off_to needs the gain trials"):
        preset("extended", gains=(), back_off_to=0.8)
    with pytest.raises(ConfigError, match="back_off_to needs the gain trials"):
        preset("faithful", back_off_to=0.8)
    with pytest.raises(ConfigError, match=r"back_off_to=3\.0: expected a scale"):
        preset("extended", back_off_to=3.0)


def test_a_run_that_backs_off_is_used_and_evaluated_at_the_scale_it_settled_at(
    monkeypatch, tmp_path, robot, tiny_reference
):
    from imitwalk import plots
    from imitwalk.evaluate import load_gait
    from imitwalk.learner import learn

    ref, _ = tiny_reference
    sets = [*TINY, "train_models=2", "gains=0,0.5,1", "back_off_to=0.3"]
    cfg = apply_overrides(preset("extended"), sets)
    calls: list = []  # the trials are faked: the kept gain falls at 0.4, not at 0.3
    monkeypatch.setattr(tuning, "tune", _fake_tune({0.4: (2, 1, 3), 0.3: (1, 0, 0)}, calls))
    summary = learn(ref, robot, cfg, tmp_path / "run")
    assert summary["scales_passed"] == [0.3, 0.4]
    assert [c[0] for c in calls] == [0.4, 0.3]
    assert summary["scale_reached"] == 0.3 and summary["channel_gain"] == 0.5
    assert summary["back_off"]["from"] == 0.4 and summary["gain_trials"]["scale"] == 0.3
    lg = load_gait(tmp_path / "run")
    assert lg.scale == 0.3 and lg.config.step.gain == 0.5

    # interrupted in the back-off, a resume ends where the whole run did
    def interrupt(text):
        if text.startswith("back-off: the kept gain fell"):
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        learn(ref, robot, cfg, tmp_path / "cut", progress=interrupt)
    resumed = learn(ref, robot, cfg, tmp_path / "cut", resume=True)
    assert strip_wall(resumed) == strip_wall(summary)
    fig = plots.fig7_schedule(lg.gait, summary["scales_passed"], None, lg.scale)
    title = "Motion pattern scaling: reached 0.3 of the schedule (passed 0.4, backed off)"
    assert fig.axes[0].get_title() == title


def test_the_report_names_the_back_off_and_the_trials_that_decided_it():
    from imitwalk.media import gain

    metrics = {
        "channel_gain": 0.5,
        "gain_trials": _trials((2, 0, 0), scale=0.9),
        "back_off": {"from": 1.0, "scale": 0.9, "trials": [_trials((2, 0, 0), scale=0.9)]},
    }
    text = gain(metrics)
    assert text.startswith("backed off from scale 1 to 0.9; channel gain 0.5")
    assert "trials at scale 0.9 on 2 robots: 0: 2 fell, 0.5: 0 fell, 1: 0 fell" in text
    kept_top = {**metrics, "back_off": {"from": 1.0, "scale": 1.0, "trials": []}}
    assert "backed off" not in gain(kept_top)


def _consolidation_log(falls_by_scale: dict, consolidate: int = 2) -> list[dict]:
    """The last ``consolidate`` log entries of a consolidation at each scale, in order."""
    return [
        {"scale": s, "falls": f, "robots": 6, "consolidation": True}
        for s, f in falls_by_scale.items()
        for _ in range(consolidate)
    ]


@pytest.mark.parametrize(
    ("when", "floor", "falls", "next_scale"),
    [
        (("consolidation", "trials"), 0.8, 1, 0.8),  # it fell: consolidate one scale down
        (("consolidation",), 0.8, 0, None),  # it walked: settle here
        (("trials",), 0.8, 1, None),  # the trials only (the default): settle here
        (("consolidation",), 0.9, 1, None),  # never below back_off_to
    ],
)
def test_a_consolidation_that_falls_gives_its_scale_back(when, floor, falls, next_scale):
    cfg = preset("extended", back_off_to=floor, back_off_when=when)
    state = _state((1, 0, 0))
    log = [{"scale": 0.9, "falls": 3, "robots": 6}, *_consolidation_log({0.9: falls})]
    assert tuning.give_back_scale(cfg, state, log) == next_scale
    assert state["settled"] == 0.9
    assert state["consolidated"] == [{"scale": 0.9, "falls": 2 * falls, "robots": 12}]


def test_without_back_off_a_consolidation_is_recorded_and_kept():
    state = _state((1, 0, 0))
    assert tuning.give_back_scale(preset("extended"), state, _consolidation_log({0.9: 2})) is None
    assert state["settled"] == 0.9


def test_the_trials_start_from_the_scale_the_consolidation_settled_at(monkeypatch):
    calls: list = []
    monkeypatch.setattr(tuning, "tune", _fake_tune({0.7: (3, 0, 2)}, calls))
    cfg = preset("extended", back_off_to=0.7, back_off_when=("consolidation", "trials"))
    state = {**_state((2, 1, 1)), "settled": 0.8}  # consolidated down from 0.9 to 0.8
    state["consolidated"] = [{"scale": 0.9, "falls": 1, "robots": 12}]
    state["consolidated"].append({"scale": 0.8, "falls": 0, "robots": 12})
    assert tuning.back_off(None, None, cfg, {}, state, None) == 0.7
    assert [c[0] for c in calls] == [0.7]
    assert state["back_off"]["from"] == 0.9 and state["back_off"]["consolidation"][0]["falls"] == 1
    # with the consolidation alone as evidence, no trials run below the scale it settled at
    calls.clear()
    state = {**_state((2, 1, 1)), "settled": 0.8}
    cfg = replace(cfg, back_off_when=("consolidation",))
    assert tuning.back_off(None, None, cfg, {}, state, None) == 0.8
    assert calls == []


def test_back_off_when_settings():
    assert preset("extended").back_off_when == ("trials",)
    sets = ["back_off_to=0.8", "back_off_when=consolidation,trials"]
    cfg = apply_overrides(preset("extended"), sets)
    assert cfg.back_off_when == ("consolidation", "trials")
    with pytest.raises(ConfigError, match=r"unknown back_off_when 'falls'; valid: consolidation"):
        apply_overrides(preset("extended"), ["back_off_when=falls"])
    with pytest.raises(ConfigError, match="back_off_when needs back_off_to"):
        preset("extended", back_off_when=("consolidation",))
    with pytest.raises(ConfigError, match="back_off_when is empty"):
        preset("extended", back_off_to=0.8, back_off_when=())
    with pytest.raises(ConfigError, match=r"needs schedule\.consolidate"):
        apply_overrides(cfg, ["schedule.consolidate=0"])


def test_a_run_whose_consolidation_falls_settles_one_scale_down(
    monkeypatch, tmp_path, robot, tiny_reference
):
    from imitwalk import learner
    from imitwalk.evaluate import load_gait

    ref, _ = tiny_reference
    sets = [*TINY, "train_models=2", "gains=0,0.5,1", "back_off_to=0.3"]
    cfg = apply_overrides(preset("extended"), [*sets, "back_off_when=consolidation,trials"])
    calls: list = []
    monkeypatch.setattr(tuning, "tune", _fake_tune({0.3: (1, 0, 0)}, calls))
    run, log_entry = RunDir(tmp_path / "run"), learner._iteration_log

    def consolidation_falls_at_the_top(scale, it, results, reports, t0):
        entry = log_entry(scale, it, results, reports, t0)
        done = run.read_json("checkpoint.json") if run.exists("checkpoint.json") else {}
        if scale == 0.4 and 0.4 in done.get("passed", []):  # consolidating at 0.4: one falls
            entry["falls"], entry["fell"] = 1, [True, *entry["fell"][1:]]
        return entry

    monkeypatch.setattr(learner, "_iteration_log", consolidation_falls_at_the_top)
    summary = learner.learn(ref, robot, cfg, tmp_path / "run")
    assert summary["scales_passed"] == [0.3, 0.4]
    assert summary["scale_reached"] == 0.3 and [c[0] for c in calls] == [0.3]
    back = summary["back_off"]
    assert back["from"] == 0.4 and back["scale"] == 0.3 and back["trials"] == []
    assert [(c["scale"], c["falls"]) for c in back["consolidation"]] == [(0.4, 2), (0.3, 0)]
    assert load_gait(tmp_path / "run").scale == 0.3
    entries = [e for e in run.read_log() if e["consolidation"]]
    assert [e["scale"] for e in entries] == [0.4, 0.4, 0.3, 0.3]


def test_the_report_says_why_the_consolidation_gave_scale_back():
    from imitwalk.media import gain

    back = {"from": 0.9, "scale": 0.8, "trials": []}
    back["consolidation"] = [{"scale": 0.9, "falls": 2, "robots": 12}]
    metrics = {"channel_gain": 0.5, "gain_trials": _trials((2, 0, 0), 0.8), "back_off": back}
    assert gain(metrics).startswith(
        "backed off from scale 0.9 to 0.8 (its consolidation fell on 2 of 12 at 0.9); "
    )
