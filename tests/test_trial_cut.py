"""A candidate's trials stop once it has fallen more often than the best so far: every
pick is the one the full trials give, the walks cost less, and a cut trial is finished
where a later use of it needs the rest."""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.balance import ticktrials
from imitwalk.balance.tickconfig import TickLearnConfig, TrialConfig
from imitwalk.balance.tickrun import TickResult, Trial
from imitwalk.balance.ticktrials import Learner, TickProgress, best, fewest_falls, trial

N = 8  # trial robots


@dataclass(frozen=True)
class _Draw:
    seed: int
    options: object = None


def _learner(falls: dict, monkeypatch) -> Learner:
    """A learner whose walks are looked up, not simulated: robot ``seed`` falls under the
    feedforward ``ff`` if ``falls[ff][seed - first]``; a fallen walk lasts 2 s."""
    first = ticktrials.TRIAL_SEED_BASE + 1

    def walk(job):
        fell = bool(falls[job.feedforward][job.seed - first])
        return TickResult(job.seed, fell, 2.0 if fell else None, 2.0 if fell else 10.0,
                          1.0, 0.0, 0.1)  # fmt: skip

    monkeypatch.setattr(ticktrials, "run_tick_episode", walk)
    lr = object.__new__(Learner)
    lr.cfg = TickLearnConfig(workers=1, trials=TrialConfig(robots=N))
    lr.robot, lr.ref_path, lr.scales = None, "", (1.0,)
    lr.ref = SimpleNamespace(sim_options=lambda: None)
    lr.protocol = SimpleNamespace(draw=lambda seed, *_: _Draw(seed))
    return lr


def _pick(lr: Learner, state: TickProgress, values) -> tuple[float, list]:
    table: list = []
    for v in values:
        table.append((v, trial(lr, state, "law", [], settings={"feedforward": v},
                               fewest=fewest_falls(table))))  # fmt: skip
    return best(table)[0], table


def _walk(fell: bool) -> TickResult:
    return TickResult(0, fell, None, 2.0 if fell else 10.0, 1.0, 0.0, 0.1)


falls_per_robot = st.lists(st.booleans(), min_size=N, max_size=N)


@settings(max_examples=60, deadline=None)
@given(st.lists(falls_per_robot, min_size=2, max_size=4))
def test_the_cut_keeps_the_full_trials_pick_at_less_cost(rows):
    values = [0.25 * i for i in range(len(rows))]
    falls = dict(zip(values, rows, strict=True))
    with pytest.MonkeyPatch.context() as mp:
        lr = _learner(falls, mp)
        state = TickProgress()
        kept, table = _pick(lr, state, values)
        full = [(v, Trial([_walk(f) for f in falls[v]])) for v in values]
        assert kept == best(full)[0]
        paid = sum(2.0 if f else 10.0 for v in values for f in falls[v])
        assert state.sim_seconds <= paid
        least = dict(full)[kept].summary().falls
        for (v, t), (_, whole) in zip(table, full, strict=True):
            assert [r.fell for r in t.results] == [r.fell for r in whole.results[: len(t.results)]]
            if len(t.results) < N:  # cut: already worse than the pick, which walked them all
                assert t.summary().falls > least and v != kept


def test_a_cut_trial_is_finished_when_it_is_needed_whole(monkeypatch):
    falls = {0.0: [0] * N, 0.5: [1, 1, 0, 0, 0, 0, 0, 1]}
    lr = _learner(falls, monkeypatch)
    state = TickProgress()
    _pick(lr, state, [0.0, 0.5])
    key = next(k for k in state.tried if "feedforward 0.5" in k)
    assert len(state.tried[key]) == 1  # cut after its first fall: 1 > 0
    whole = trial(lr, state, "law", [], settings={"feedforward": 0.5})
    assert [r.fell for r in whole.results] == [bool(f) for f in falls[0.5]]
    assert np.isclose(state.sim_seconds, 8 * 10.0 + 2.0 * 3 + 10.0 * 5)
