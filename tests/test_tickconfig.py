"""Settings of the per-tick learner: every range checked in one line that gives it."""

from __future__ import annotations

from itertools import pairwise

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.balance.tickconfig import LqrConfig, TickLearnConfig, TrialConfig
from imitwalk.config import apply_overrides, from_dict, to_dict
from imitwalk.errors import ConfigError

#: (setting, a value outside its range, the range the message gives)
OUT_OF_RANGE = [
    ("trials.pitch", "0,0.6", "-0.5..0.5"),
    ("trials.roll", "-0.7", "-0.5..0.5"),
    ("trials.heading", "0,2.5", "-2..2"),
    ("trials.torso", "0,-1.5", "-1..1"),
    ("trials.tilt", "0,1.5", "-1..1"),
    ("trials.box", "0.6", "0.001..0.5"),
    ("trials.box", "0", "0.001..0.5"),
    ("trials.robots", "0", "1..1000"),
    ("trials.seconds", "0.5", "1..600"),
    ("lqr.explore", "0.3", "0..0.2"),
    ("lqr.box", "-0.1", "0.001..0.5"),
    ("lqr.action_cost", "-1", "1e-06..1e+06"),
    ("lqr.change_cost", "-1", "0..1e+06"),
    ("lqr.ridge", "-1", "0..1000"),
    ("lqr.state_cost", "1,1,-1,1,1", "0..1e+06"),
    ("workers", "0", "1..256"),
    ("lqr.trust", "0,5", "0..2"),
    ("lqr.width", "0", "0.1..100"),
    ("lqr.horizon", "1001", "1..1000"),
    ("iterations", "0", "1..100"),
    ("robots", "1001", "1..1000"),
    ("seconds", "700", "1..600"),
]


@pytest.mark.parametrize(("key", "value", "valid"), OUT_OF_RANGE)
def test_a_setting_out_of_its_range_is_refused_with_the_range(key, value, valid):
    with pytest.raises(ConfigError) as err:
        apply_overrides(TickLearnConfig(), [f"{key}={value}"])
    msg = str(err.value)
    assert len(msg.splitlines()) == 1
    assert msg.startswith(f"{key}: ") and f"outside the valid range {valid}" in msg


@pytest.mark.parametrize("key", ["trials.pitch", "trials.heading", "lqr.trust"])
def test_no_candidates_is_refused(key):
    with pytest.raises(ConfigError, match=rf"{key}: give at least one value in -?[\d.]+\.\.[\d.]+"):
        apply_overrides(TickLearnConfig(), [f"{key}="])


@pytest.mark.parametrize(
    "sets",
    [["start=0"], ["start=0.9", "stop=0.8"], ["stop=2.5"], ["step=0"], ["step=-0.1"]],
)
def test_a_schedule_that_cannot_be_walked_is_refused(sets):
    with pytest.raises(ConfigError, match=r"expected 0 < start <= stop <= 2 and step > 0"):
        apply_overrides(TickLearnConfig(), sets)


def test_names_are_checked_with_the_valid_ones_listed():
    with pytest.raises(ConfigError, match=r"engine 'physx'; valid: "):
        TickLearnConfig(engine="physx")
    with pytest.raises(
        ConfigError, match=r"unknown protocol 'harder'; valid: bullet, cross, eval, hard"
    ):
        TickLearnConfig(train_protocol="harder")
    with pytest.raises(ConfigError, match=r"unknown protocol 'srvo'; valid: .*servo"):
        apply_overrides(TickLearnConfig(), ["trials.balance_protocol=srvo"])
    with pytest.raises(ConfigError, match=r"unknown protocol 'slop'; valid: .*slope"):
        apply_overrides(TickLearnConfig(), ["trials.tilt_protocol=slop"])
    with pytest.raises(ConfigError, match=r"unknown setting 'lqr\.gain'; valid: .*lqr\.trust"):
        apply_overrides(TickLearnConfig(), ["lqr.gain=1"])


@pytest.mark.parametrize(
    ("key", "message"),
    [
        ("lqr.channels=knee", r"unknown lqr channel 'knee'; valid: ankle_pitch"),
        ("lqr.features=yaw,roll,pitch,gyro_x,gyro_y", r"unknown lqr feature 'yaw'; valid: gyro_x"),
    ],
)
def test_the_model_based_laws_names_are_checked_up_front(key, message):
    with pytest.raises(ConfigError, match=message):
        apply_overrides(TickLearnConfig(), [key])


def test_one_state_cost_per_feature():
    with pytest.raises(ConfigError, match=r"lqr.state_cost has 2 weights for 5 features \(gyro_x"):
        apply_overrides(TickLearnConfig(), ["lqr.state_cost=1,1"])
    two = LqrConfig(features=("gyro_x", "roll"), state_cost=(1.0, 2.0))
    assert two.features == ("gyro_x", "roll") and two.state_cost == (1.0, 2.0)


def test_the_model_based_laws_features_can_be_changed_from_the_cli():
    two = apply_overrides(TickLearnConfig(), ["lqr.features=gyro_x,roll", "lqr.state_cost=1,2"])
    assert two.lqr.features == ("gyro_x", "roll") and two.lqr.state_cost == (1.0, 2.0)


@settings(max_examples=40, deadline=None)
@given(
    start=st.floats(0.05, 2.0),
    span=st.floats(0.0, 1.0),
    step=st.floats(0.01, 1.0),
)
def test_the_schedule_climbs_from_start_to_stop(start, span, step):
    stop = min(2.0, start + span)
    scales = TickLearnConfig(start=start, step=step, stop=stop).scales()
    assert scales[0] == pytest.approx(start, abs=1e-6)
    assert all(b > a for a, b in pairwise(scales))
    assert all(start - 1e-6 <= s <= stop + 1e-6 for s in scales)
    assert scales[-1] >= stop - step / 2 - 1e-6


def test_the_settings_round_trip_through_the_run_folders_json():
    cfg = apply_overrides(
        TickLearnConfig(),
        ["trials.pitch=0,0.1", "lqr.trust=0,1", "lqr.enabled=false", "seed=3", "start=0.5"],
    )
    assert from_dict(TickLearnConfig, to_dict(cfg)) == cfg
    assert from_dict(TickLearnConfig, to_dict(TickLearnConfig())) == TickLearnConfig()
    assert TrialConfig().box == LqrConfig().box  # the defaults are the measured best


def test_overrides_that_check_each_other_apply_in_any_order():
    from imitwalk.retarget import RetargetConfig

    # elites must not pass the population: each order is checked on the final values
    keys = ["search_config.population=2", "search_config.elites=1"]
    for order in (keys, keys[::-1]):
        cfg = apply_overrides(RetargetConfig(), order).search_config
        assert (cfg.population, cfg.elites) == (2, 1)
    with pytest.raises(ConfigError, match=r"elites: 3 is not in 1\.\.2"):
        apply_overrides(RetargetConfig(), ["search_config.population=2"])
    # a later value of one key wins
    assert apply_overrides(TickLearnConfig(), ["robots=3", "robots=5"]).robots == 5
