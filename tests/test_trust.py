"""Picking the channel gain from measured trials (pure NumPy)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.perturb import TRAIN_SEED_BASE, TRIAL_SEED_BASE, train_seeds, trial_seeds
from imitwalk.trust import select_gain, tune_gain

SECONDS = 24.0

episode = st.builds(
    lambda fell, t, yaw: {
        "fell": fell,
        "fall_time_s": t if fell else None,
        "seconds": t if fell else SECONDS,
        "yaw_drift_deg": yaw,
    },
    st.booleans(),
    st.floats(0.5, SECONDS - 0.5),
    st.floats(-40.0, 40.0),
)


@settings(max_examples=80, deadline=None)
@given(
    st.integers(1, 8).flatmap(
        lambda n: st.lists(st.lists(episode, min_size=n, max_size=n), min_size=1, max_size=4)
    )
)
def test_the_kept_gain_has_the_fewest_falls_then_the_longest_time_up(trials):
    gains = [0.25 * i for i in range(len(trials))]
    best, table = select_gain(gains, trials)
    assert [r["gain"] for r in table] == gains
    falls = [r["falls"] for r in table]
    assert falls[best] == min(falls)
    tied = [r for r in table if r["falls"] == falls[best]]
    assert table[best]["mean_time_up_s"] == max(r["mean_time_up_s"] for r in tied)


def test_on_an_exact_tie_the_first_listed_gain_is_kept():
    runs = [{"fell": False, "fall_time_s": None, "seconds": 10.0, "yaw_drift_deg": 3.0}] * 3
    assert select_gain([0.0, 0.5, 1.0], [runs, runs, runs])[0] == 0


def test_less_heading_drift_decides_between_walks_that_stay_up():
    up = lambda yaw: {"fell": False, "fall_time_s": None, "seconds": 10.0, "yaw_drift_deg": yaw}  # noqa: E731
    best, table = select_gain([0.0, 1.0], [[up(20.0), up(-15.0)], [up(2.0), up(-3.0)]])
    assert best == 1 and table[1]["mean_abs_yaw_deg"] == pytest.approx(2.5)


def test_tune_gain_runs_every_candidate_on_the_same_robots():
    seen = []

    def run(gain, seeds):
        seen.append((gain, seeds))
        fell = gain > 0.6  # the full correction falls on the second robot
        return [
            {
                "fell": fell and s != 0,
                "fall_time_s": 3.0,
                "seconds": 3.0 if fell and s else 8.0,
                "yaw_drift_deg": 10.0 * (1 - gain),
            }
            for s in seeds
        ]

    choice = tune_gain(run, (0.0, 0.5, 1.0), trial_seeds(2))
    assert [g for g, _ in seen] == [0.0, 0.5, 1.0] and {s for _, s in seen} == {trial_seeds(2)}
    assert choice.gain == 0.5 and choice.sim_seconds == pytest.approx(8 * 2 * 2 + 8 + 3)
    assert [r["falls"] for r in choice.table] == [0, 0, 1]


def test_trial_robots_are_neither_training_nor_evaluation_robots():
    trial = set(trial_seeds(40)[1:])
    learning = {s for d in range(2000) for s in train_seeds(6, d)[1:]}
    assert min(trial) > TRIAL_SEED_BASE > max(learning) > TRAIN_SEED_BASE > 99
    assert trial_seeds(1) == (0,)


@settings(max_examples=15, deadline=None)
@given(
    n=st.integers(3, 30),
    lo=st.floats(0.3, 1.0),
    width=st.floats(0.05, 0.6),
)
def test_stratified_trial_robots_cover_the_friction_range_one_per_band(n, lo, width):
    from imitwalk.perturb import perturbed

    hi = lo + width
    seeds = trial_seeds(n, stratify=True, friction_range=(lo, hi))
    assert seeds[0] == 0 and len(set(seeds)) == n and min(seeds[1:]) > TRIAL_SEED_BASE
    assert seeds == trial_seeds(n, stratify=True, friction_range=(lo, hi))  # deterministic
    f = [perturbed(s, disturbance=True, friction_range=(lo, hi)).friction for s in seeds[1:]]
    bands = sorted(min(int((v - lo) / (hi - lo) * (n - 1)), n - 2) for v in f)
    assert bands == list(range(n - 1))


def test_unstratified_trial_robots_are_unchanged():
    assert trial_seeds(5, stratify=False) == (0, *range(TRIAL_SEED_BASE + 1, TRIAL_SEED_BASE + 5))
    assert trial_seeds(2, stratify=True) == trial_seeds(2)  # one band: nothing to stratify
    assert trial_seeds(6, stratify=True, friction_range=(0.9, 0.9)) == trial_seeds(6)


def test_a_mismatched_trial_list_is_refused():
    with pytest.raises(ValueError, match="one list of trials per candidate"):
        select_gain([0.0, 1.0], [[]])


def test_gain_settings_from_the_command_line():
    from imitwalk.config import apply_overrides
    from imitwalk.errors import ConfigError
    from imitwalk.learnconfig import preset

    assert preset("extended").gains == (0.0, 0.5, 1.0) and preset("faithful").gains == ()
    assert apply_overrides(preset("extended"), ["gains="]).gains == ()
    assert apply_overrides(preset("extended"), ["gains=0.5,1"]).gains == (0.5, 1.0)
    with pytest.raises(ConfigError, match="0 <= gain <= 2"):
        apply_overrides(preset("extended"), ["gains=0,3"])


def test_the_same_trials_pick_a_cadence_under_its_own_name():
    def runs(rate, seeds):  # the faster cadence keeps every robot up
        return [
            {"fell": rate < 1.1, "fall_time_s": 5.0, "seconds": 5.0, "yaw_drift_deg": 1.0}
            if rate < 1.1
            else {"fell": False, "fall_time_s": None, "seconds": SECONDS, "yaw_drift_deg": 1.0}
            for _ in seeds
        ]

    choice = tune_gain(runs, (1.0, 1.12), (0, 1), key="cadence")
    d = choice.to_dict()
    assert d["cadence"] == 1.12 and "gain" not in d
    assert [r["cadence"] for r in d["table"]] == [1.0, 1.12]
