"""A candidate's trials stop once it can no longer be kept (it has fallen more often than
the best so far, or as often where a tie loses): every pick is the one the full trials
give, the walks cost less, and a cut trial is finished where a later use of it needs the
rest."""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.balance import ticktrials
from imitwalk.balance.tickconfig import TickLearnConfig, TrialConfig
from imitwalk.balance.tickrun import TickResult, Trial, best, most_falls
from imitwalk.balance.ticktrials import Learner, TickProgress, trial

N = 8  # trial robots


@dataclass(frozen=True)
class _Draw:
    seed: int
    options: object = None


def _learner(falls: dict, monkeypatch, yaw: dict | None = None) -> Learner:
    """A learner whose walks are looked up, not simulated: robot ``seed`` falls under the
    feedforward ``ff`` if ``falls[ff][seed - first]`` and drifts ``yaw[ff][seed - first]``
    degrees (default 0); a fallen walk lasts 2 s."""
    first = ticktrials.TRIAL_SEED_BASE + 1

    def walk(job):
        i = job.seed - first
        fell = bool(falls[job.feedforward][i])
        drift = 0.0 if yaw is None else float(yaw[job.feedforward][i])
        return TickResult(
            job.seed, fell, 2.0 if fell else None, 2.0 if fell else 10.0, 1.0, drift, 0.1
        )

    monkeypatch.setattr(ticktrials, "run_tick_episode", walk)
    lr = object.__new__(Learner)
    lr.cfg = TickLearnConfig(workers=1, trials=TrialConfig(robots=N))
    lr.robot, lr.ref_path, lr.scales = None, "", (1.0,)
    lr.ref = SimpleNamespace(sim_options=lambda: None)
    lr.protocol = SimpleNamespace(draw=lambda seed, *_: _Draw(seed))
    return lr


def _pick(lr: Learner, state: TickProgress, values, limit=None) -> tuple[float, list]:
    table: list = []
    for v in values:
        table.append(
            (
                v,
                trial(
                    lr,
                    state,
                    "law",
                    [],
                    settings={"feedforward": v},
                    most=most_falls(table, v, limit),
                ),
            )
        )
    return best(table, limit)[0], table


def _walk(fell: bool, drift: float = 0.0) -> TickResult:
    return TickResult(0, fell, None, 2.0 if fell else 10.0, 1.0, drift, 0.1)


falls_per_robot = st.lists(st.booleans(), min_size=N, max_size=N)
yaw_per_robot = st.lists(st.sampled_from([0.0, 5.0, 20.0]), min_size=N, max_size=N)


@settings(max_examples=80, deadline=None)
@given(
    st.lists(st.tuples(falls_per_robot, yaw_per_robot), min_size=2, max_size=4),
    st.sampled_from([None, 10.0]),
    st.booleans(),
)
def test_the_cut_keeps_the_full_trials_pick_at_less_cost(rows, limit, descending):
    """Candidates in either order of |value|, with and without the heading's yaw limit."""
    values = [0.25 * i for i in range(len(rows))][:: -1 if descending else 1]
    falls = {v: f for v, (f, _) in zip(values, rows, strict=True)}
    yaw = {v: y for v, (_, y) in zip(values, rows, strict=True)}
    with pytest.MonkeyPatch.context() as mp:
        lr = _learner(falls, mp, yaw)
        state = TickProgress()
        kept, table = _pick(lr, state, values, limit)
        full = [
            (v, Trial([_walk(f, y) for f, y in zip(falls[v], yaw[v], strict=True)])) for v in values
        ]
        assert kept == best(full, limit)[0]
        paid = sum(2.0 if f else 10.0 for v in values for f in falls[v])
        assert state.sim_seconds <= paid
        least = dict(full)[kept].summary().falls
        for (v, t), (_, whole) in zip(table, full, strict=True):
            assert [r.fell for r in t.results] == [r.fell for r in whole.results[: len(t.results)]]
            if len(t.results) < N:  # cut: worse than the pick, which walked them all
                falls_so_far = t.summary().falls
                assert v != kept
                assert falls_so_far > least or (falls_so_far == least and abs(v) > abs(kept))


def test_a_candidate_that_could_at_best_tie_is_not_walked(monkeypatch):
    """Against a best with no falls, a larger value could only tie, and a tie keeps the
    smaller: it is not walked, and the log says so."""
    falls = {0.0: [0] * N, 0.5: [0] * N}
    lr = _learner(falls, monkeypatch)
    state = TickProgress()
    kept, table = _pick(lr, state, [0.0, 0.5])
    assert kept == 0.0 and table[1][1].results == []
    assert np.isclose(state.sim_seconds, N * 10.0)
    lines: list = []
    lr.say = lines.append
    ticktrials.say_table(lr, "trials:", table)
    assert "[0.5: not walked]" in lines[0]


def test_a_smaller_value_is_walked_until_it_falls_more(monkeypatch):
    """Walked after a larger one, a smaller value wins ties, so only more falls stop it."""
    falls = {0.5: [0] * N, 0.0: [0] * N}
    lr = _learner(falls, monkeypatch)
    state = TickProgress()
    kept, table = _pick(lr, state, [0.5, 0.0])
    assert kept == 0.0 and len(table[1][1].results) == N


def test_a_cut_trial_is_finished_when_it_is_needed_whole(monkeypatch):
    falls = {0.0: [0] * N, 0.5: [1, 1, 0, 0, 0, 0, 0, 1]}
    lr = _learner(falls, monkeypatch)
    state = TickProgress()
    _pick(lr, state, [0.0, 0.5])
    key = next(k for k in state.tried if "feedforward 0.5" in k)
    assert len(state.tried[key]) == 0  # 0.0 did not fall: 0.5 could at best tie, and lose
    whole = trial(lr, state, "law", [], settings={"feedforward": 0.5})
    assert [r.fell for r in whole.results] == [bool(f) for f in falls[0.5]]
    assert np.isclose(state.sim_seconds, 8 * 10.0 + 2.0 * 3 + 10.0 * 5)
