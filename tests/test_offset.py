"""The channel offset (``step.offset``) and its trials when the schedule stalls
(``LearnConfig.offsets``)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk import tuning
from imitwalk.balance import STEP_CHANNELS, STEP_STATE, StepConfig, StepController
from imitwalk.errors import ConfigError
from imitwalk.learnconfig import preset
from imitwalk.predictor import SensoryMotorModel
from imitwalk.trust import GainChoice

DX = STEP_CHANNELS.index("dx")


def _offset(dx: float, channel: str = "dx") -> tuple[float, ...]:
    return tuple(dx if c == channel else 0.0 for c in STEP_CHANNELS)


def test_without_a_model_every_step_takes_the_offset():
    ctrl = StepController(StepConfig(offset=_offset(-0.005)), 100, 0.1)
    for k in range(4):
        c = ctrl.decide(np.zeros(len(STEP_STATE)), k)
        np.testing.assert_array_equal(c, _offset(-0.005))
    # it lands the swing foot 5 mm short, like any dx
    assert ctrl.offsets(49)[3] == pytest.approx(-0.005, rel=0.05)


def _model(rng):
    S = [rng.normal(0, 0.05, (30, len(STEP_STATE))) for _ in range(4)]
    A = [
        np.c_[rng.uniform(-1, 1, (30, len(STEP_CHANNELS))) * StepConfig().c_max, np.ones(30)]
        for _ in range(4)
    ]
    model = SensoryMotorModel(angle_action=False, linear=True, n_centers=4, ridge=1e-3)
    return model.fit(list(zip(S, A, strict=True)))


@settings(max_examples=10, deadline=None)
@given(st.floats(-0.01, 0.01), st.sampled_from([0.0, 0.5, 1.0]))
def test_the_search_corrects_around_the_offset_within_the_limits(dx, gain):
    rng = np.random.default_rng(3)
    cfg = StepConfig(offset=_offset(dx), gain=gain)
    ctrl = StepController(cfg, 100, 0.1, model=_model(rng))
    c_max = np.asarray(cfg.c_max) * ctrl.mask
    for k in range(6):
        c = ctrl.decide(rng.normal(0, 0.05, len(STEP_STATE)), k)
        assert np.all(c <= c_max + 1e-12) and np.all(c >= ctrl.c_min - 1e-12)
        if gain == 0.0:  # no correction: the offset itself
            np.testing.assert_allclose(c, _offset(dx) * ctrl.mask, atol=1e-15)


def test_a_zero_offset_decides_exactly_as_no_offset():
    a = StepController(StepConfig(), 100, 0.1, model=_model(np.random.default_rng(0)))
    b = StepController(
        StepConfig(offset=_offset(0.0)), 100, 0.1, model=_model(np.random.default_rng(0))
    )
    rng = np.random.default_rng(1)
    for k in range(6):
        s = rng.normal(0, 0.05, len(STEP_STATE))
        np.testing.assert_array_equal(a.decide(s, k), b.decide(s, k))


@pytest.mark.parametrize(
    "offset, words",
    [
        ((0.0, 0.0), "one per channel"),
        (_offset(0.02), "dx=0.02: outside -0.015..0.015"),
        (_offset(-0.004, "dy"), "dy=-0.004: outside 0..0.012"),
        (_offset(0.05, "time"), "time=0.05: not in step.channels"),
    ],
)
def test_a_bad_offset_is_refused_in_one_line(offset, words):
    with pytest.raises(ConfigError, match=words):
        StepConfig(offset=offset)


def test_offset_trials_settings():
    cfg = preset("extended", offsets=(-0.005, 0.0))
    assert cfg.with_offset(-0.005).step.offset == _offset(-0.005)
    assert cfg.with_offset(None) is cfg
    with pytest.raises(ConfigError, match="unknown offset_channel 'time'; valid: dx, dy"):
        preset("extended", offsets=(0.1,), offset_channel="time")
    with pytest.raises(ConfigError, match=r"step\.offset for dx=0\.03"):
        preset("extended", offsets=(0.03,))


def _fake_tune(kept: float, calls: list):
    def tune(gait, robot, config, data, scale, key, values, gain, progress):
        calls.append((scale, key, list(values), config.step.offset_vector[DX]))
        table = [{key: v, "falls": 0 if v == kept else 3} for v in values]
        return GainChoice(kept, (1, 2), table, sim_seconds=48.0, wall_seconds=1.0, key=key)

    return tune


def test_a_stalled_schedule_goes_on_with_the_offset_that_measures_better(monkeypatch):
    calls: list = []
    monkeypatch.setattr(tuning, "tune", _fake_tune(-0.005, calls))
    cfg = preset("extended", offsets=(-0.005, -0.0025, 0.0))
    state = {"failures": 7, "sim_seconds": 0.0, "wall_seconds": 0.0}
    assert tuning.retry_with_offset(None, None, cfg, {}, 0.9, state, None)
    assert state["offset"] == -0.005 and state["failures"] == 0
    # the current value is tried first (it wins ties), then by distance from it
    assert calls == [(0.9, "offset", [0.0, -0.0025, -0.005], 0.0)]
    assert state["offset_trials"][0]["scale"] == 0.9 and state["sim_seconds"] == 48.0
    # once per scale: at 0.9 the schedule now stops; at 1.0 the trials start from -0.005
    assert not tuning.retry_with_offset(None, None, cfg, {}, 0.9, state, None)
    monkeypatch.setattr(tuning, "tune", _fake_tune(-0.005, calls))
    assert not tuning.retry_with_offset(None, None, cfg, {}, 1.0, state, None)
    assert calls[-1] == (1.0, "offset", [-0.005, -0.0025, 0.0], -0.005)


def test_without_offsets_a_stalled_schedule_stops(monkeypatch):
    monkeypatch.setattr(tuning, "tune", None)  # never called
    state = {"failures": 7}
    assert not tuning.retry_with_offset(None, None, preset("extended"), {}, 0.9, state, None)
    assert state == {"failures": 7}


def test_a_run_tries_offsets_at_the_scale_reached_and_evaluates_with_the_kept_one(
    tmp_path, robot, tiny_reference
):
    from conftest import TINY
    from imitwalk.config import apply_overrides
    from imitwalk.evaluate import load_gait
    from imitwalk.learner import learn
    from imitwalk.perturb import trial_seeds
    from imitwalk.runs import RunDir

    ref, _ = tiny_reference
    sets = [*TINY, "train_models=2", "schedule.stop=0.3", "offsets=-0.005,0"]
    cfg = apply_overrides(preset("extended"), sets)
    calls = []

    def interrupt(text):  # cut in the offset trials: a resume ends where a whole run does
        if text.startswith("channel offset -0.005"):
            calls.append(text)
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        learn(ref, robot, cfg, tmp_path / "cut", progress=interrupt)
    resumed = learn(ref, robot, cfg, tmp_path / "cut", resume=True)
    whole = learn(ref, robot, cfg, tmp_path / "whole")
    assert calls and resumed["offset_trials"] == [
        {**t, "wall_seconds": resumed["offset_trials"][0]["wall_seconds"]}
        for t in whole["offset_trials"]
    ]
    (trial,) = whole["offset_trials"]  # once, at the scale reached, on the trial robots
    assert trial["scale"] == 0.3 and trial["seeds"] == list(trial_seeds(2))
    assert [r["offset"] for r in trial["table"]] == [0.0, -0.005]  # the current one first
    kept = whole["channel_offset"]
    assert kept is None if trial["offset"] == 0.0 else kept == {"dx": trial["offset"]}
    # evaluation rebuilds the learned controller with the offset the run kept
    rd = RunDir(tmp_path / "whole")
    metrics = rd.read_json("metrics.json")
    rd.write_json("metrics.json", {**metrics, "channel_offset": {"dx": -0.005}})
    assert load_gait(rd.path).config.step.offset_vector[DX] == -0.005


def test_the_report_names_the_offset_and_its_trials():
    from imitwalk.media import gain

    table = [{"offset": 0.0, "falls": 2}, {"offset": -0.005, "falls": 1}]
    metrics = {
        "channel_gain": 0.5,
        "channel_offset": {"dx": -0.005},
        "offset_trials": [{"scale": 0.9, "seeds": [1, 2], "table": table}],
    }
    text = gain(metrics)
    assert "channel offset dx -0.005 (trials at scale 0.9 on 2 robots: 0: 2 fell" in text
    assert "channel offset" not in gain({"channel_gain": 0.5})
