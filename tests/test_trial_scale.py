"""Where no candidate walks any trial robot at the top scale, the trials go on lower: a
table that cannot tell its candidates apart is walked again one scale of the schedule
lower, and the trials after it stay there. A robot that walks at the top scale is never
walked lower."""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
import pytest

from imitwalk.balance import ticktrials
from imitwalk.balance.tickconfig import TickLearnConfig, TrialConfig
from imitwalk.balance.ticklog import entry_from_dict
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


def _whole_learner(run_dir, monkeypatch, say) -> Learner:
    """A learner for the whole trial stage whose walks are made up: every robot falls
    above 0.35; at 0.3 robot ``seed`` falls without the feedforward if ``seed`` is even."""
    from imitwalk.balance.channels import FEATURES
    from imitwalk.balance.feedback import Episode
    from imitwalk.config import apply_overrides
    from imitwalk.runs import RunDir

    def walk(job):
        fell = job.scale > 0.35 or (job.feedforward == 0.0 and job.seed % 2 == 0)
        t = 1.0 + 0.01 * (job.seed % 7) if fell else job.seconds
        ticks = round(t / 0.01)
        k = np.arange(ticks)
        ep = Episode((k - 6) % 4, np.full((ticks, len(FEATURES)), 0.01), np.zeros((ticks, 4)))
        return TickResult(job.seed, fell, t if fell else None, t, 1.0, 0.0, 0.1, ep)

    monkeypatch.setattr(ticktrials, "run_tick_episode", walk)
    protocol = SimpleNamespace(draw=lambda seed, *_: _Draw(seed))
    monkeypatch.setattr(ticktrials, "load_protocol", lambda _name: protocol)
    lr = object.__new__(Learner)
    lr.cfg = apply_overrides(
        TickLearnConfig(), ["workers=1", "trials.robots=3", "trials.heading_robots=2"]
    )
    lr.robot, lr.ref_path, lr.scales, lr.say = None, "", (0.3, 0.4, 0.5), say
    lr.ref = SimpleNamespace(
        dt=0.01,
        starts=np.zeros((3, 6)),
        loops=np.zeros((3, 4)),
        plan=True,
        sim_options=lambda: None,
    )
    lr.protocol, lr.rd = protocol, RunDir(run_dir)
    lr.rd.path.mkdir()
    return lr


@pytest.mark.parametrize("line", [2, 3, 5, 8])
def test_trials_interrupted_across_a_lowered_scale_resume_exactly(tmp_path, line):
    """Cut at the ``line``-th progress line (the second is the drop to 0.3), then resumed
    from the checkpoint: the same state and log as the trials run through."""
    from dataclasses import asdict

    with pytest.MonkeyPatch.context() as mp:
        whole = _whole_learner(tmp_path / "whole", mp, lambda _line: None)
        done, log = TickProgress(), []
        ticktrials.trials(whole, done, log)
    assert done.trial_scale == 0.3 and done.settings["feedforward"] == 0.5

    lines: list = []

    def cut(text):
        lines.append(text)
        if len(lines) == line:
            raise KeyboardInterrupt

    with pytest.MonkeyPatch.context() as mp:
        lr = _whole_learner(tmp_path / "cut", mp, cut)
        with pytest.raises(KeyboardInterrupt):
            ticktrials.trials(lr, TickProgress(), [])
        rd = lr.rd
        saved = rd.read_json("checkpoint.json") if rd.exists("checkpoint.json") else {}
        if line >= 5:  # cut after the settings' checkpoint: the run resumes at 0.3
            assert saved["trial_scale"] == 0.3 and saved["settings"]
        state, again = TickProgress(**saved), [entry_from_dict(e) for e in rd.read_log()]
        lr.say = lambda _line: None
        ticktrials.trials(lr, state, again)
    wall = {"wall_seconds": 0.0}  # the only thing that differs
    assert {**asdict(state), **wall} == {**asdict(done), **wall} and again == log
