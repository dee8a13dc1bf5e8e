"""Where no candidate walks any trial robot at the top scale, the trials go on lower: a
table that cannot tell its candidates apart is walked again one scale of the schedule
lower, and the trials after it stay there. A robot that walks at the top scale is never
walked lower."""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace

import pytest

from imitwalk.balance import ticktrials
from imitwalk.balance.tickconfig import TickLearnConfig, TrialConfig
from imitwalk.balance.tickrun import TickResult, Trial, best, blind
from imitwalk.balance.ticktrials import Learner, TickProgress

N = 4  # trial robots
SCALES = (0.3, 0.4, 0.5, 0.6)


@dataclass(frozen=True)
class _Draw:
    seed: int
    options: object = None


def _learner(highest: dict, monkeypatch) -> Learner:
    """A learner whose walks are looked up: under the feedforward ``ff`` every robot walks
    at scales up to ``highest[ff]`` and falls above it, the sooner the larger ``ff``."""

    def walk(job):
        fell = job.scale > highest[job.feedforward] + 1e-9
        t = 2.0 + job.feedforward if fell else 10.0
        return TickResult(job.seed, fell, t if fell else None, t, 1.0, 0.0, 0.1)

    monkeypatch.setattr(ticktrials, "run_tick_episode", walk)
    lr = object.__new__(Learner)
    lr.cfg = TickLearnConfig(workers=1, trials=TrialConfig(robots=N))
    lr.robot, lr.ref_path, lr.scales = None, "", SCALES
    lr.ref = SimpleNamespace(sim_options=lambda: None)
    lr.protocol = SimpleNamespace(draw=lambda seed, *_: _Draw(seed))
    lr.say = lambda _line: None
    return lr


def _pick(lr: Learner, state: TickProgress, values) -> tuple[float, list]:
    def walk(value, most):
        return ticktrials.trial(lr, state, "law", [], settings={"feedforward": value}, most=most)

    table = ticktrials._table(lr, state, values, walk)
    return best(table)[0], table


def test_a_table_blind_at_the_top_is_walked_again_lower_until_a_candidate_walks(monkeypatch):
    # at 0.6 and 0.5 everything falls; at 0.4 only 0.5 walks (the longest walked at the
    # top, 1.0, would have been kept there)
    lr = _learner({0.0: 0.3, 0.5: 0.4, 1.0: 0.3}, monkeypatch)
    state = TickProgress()
    kept, table = _pick(lr, state, [0.0, 0.5, 1.0])
    assert (kept, state.trial_scale, lr.trial_scale(state)) == (0.5, 0.4, 0.4)
    assert not blind(table)
    assert [t.summary().falls for _, t in table] == [N, 0, 0]
    assert [len(t.results) for _, t in table] == [N, N, 0]  # 1.0 could at best tie
    scales = {k.rsplit(" at ", 1)[1] if " at " in k else "top" for k in state.tried}
    assert scales == {"top", "0.5", "0.4"}  # each scale's walks kept under its own key
    # the next table starts where this one ended, and does not go back up
    kept, _ = _pick(lr, state, [0.0, 0.5])
    assert (kept, state.trial_scale) == (0.5, 0.4)


def test_a_robot_that_walks_at_the_top_is_never_walked_lower(monkeypatch):
    lr = _learner({0.0: 0.3, 0.5: 0.6, 1.0: 0.3}, monkeypatch)
    state = TickProgress()
    kept, _ = _pick(lr, state, [0.0, 0.5, 1.0])
    assert (kept, state.trial_scale) == (0.5, None)
    assert not any(" at " in k for k in state.tried)


def test_blind_at_every_scale_ends_at_the_first_and_ranks_by_time_walked(monkeypatch):
    lr = _learner({0.0: 0.2, 1.0: 0.2}, monkeypatch)
    state = TickProgress()
    kept, table = _pick(lr, state, [0.0, 1.0])
    assert (kept, state.trial_scale) == (1.0, SCALES[0])
    assert blind(table)
    walks = len(SCALES) * 2 * N
    assert state.sim_seconds == pytest.approx(walks / 2 * (2.0 + 3.0))


def test_one_candidate_alone_is_never_blind(monkeypatch):
    lr = _learner({0.0: 0.2}, monkeypatch)
    state = TickProgress()
    kept, table = _pick(lr, state, [0.0])
    assert (kept, state.trial_scale) == (0.0, None)
    assert not blind(table) and not blind([])


def test_blind_needs_every_planned_robot_walked_and_fallen():
    fell = TickResult(0, True, 2.0, 2.0, 1.0, 0.0, float("inf"))
    up = TickResult(0, False, None, 10.0, 1.0, 0.0, 0.1)
    assert blind([(0.0, Trial([fell] * N, N)), (0.5, Trial([fell] * N, N))])
    assert not blind([(0.0, Trial([fell] * N, N)), (0.5, Trial([fell] * (N - 1) + [up], N))])
    assert not blind([(0.0, Trial([fell] * N, N)), (0.5, Trial([], N))])  # not walked
