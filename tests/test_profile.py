"""The nominal robot's profile a profiled gain is held to (:func:`ticktrials.profile`):
each loop tick's mean of the feature over one walk, its start-up and, if it fell, its
last half second left out."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from imitwalk.balance import ticktrials
from imitwalk.balance.channels import FEATURES
from imitwalk.balance.feedback import Episode
from imitwalk.balance.tickconfig import TickLearnConfig
from imitwalk.balance.tickrun import TickResult
from imitwalk.balance.ticktrials import Learner, TickProgress, profile

DT, START, LOOP = 0.01, 60, 40  # [s]; ticks of the start-up and of the loop
PITCH = FEATURES.index("pitch")


def _nominal(psi: np.ndarray) -> np.ndarray:
    return 0.1 * np.sin(2 * np.pi * psi / LOOP) - 0.05


def _learner(ticks: int, fell: bool, monkeypatch) -> Learner:
    """A learner whose one walk is made up: ``ticks`` ticks, the pitch the nominal profile
    in the loop and 9 (nonsense) in the start-up and, if it fell, its last half second."""

    def walk(job):
        k = np.arange(ticks)
        phase = (k - START) % LOOP
        features = np.zeros((ticks, len(FEATURES)))
        features[:, PITCH] = _nominal(phase)
        features[k < START, PITCH] = 9.0
        if fell:
            features[k >= ticks - round(0.5 / DT), PITCH] = 9.0
        ep = Episode(phase, features, np.zeros((ticks, 4)))
        t = ticks * DT
        return TickResult(job.seed, fell, t if fell else None, t, 1.0, 0.0, 0.1, ep)

    monkeypatch.setattr(ticktrials, "run_tick_episode", walk)
    lr = object.__new__(Learner)
    lr.cfg = TickLearnConfig(workers=1)
    lr.robot, lr.ref_path, lr.scales, lr.say = None, "", (1.0,), lambda _line: None
    lr.ref = SimpleNamespace(
        dt=DT, starts=np.zeros((3, START)), loops=np.zeros((3, LOOP)), sim_options=lambda: None
    )
    return lr


@settings(max_examples=30, deadline=None)
@given(st.integers(START + LOOP + round(0.5 / DT), START + 6 * LOOP), st.booleans())
@example(START + LOOP + round(0.5 / DT), True)  # a fall just after one whole loop
def test_the_profile_is_the_loops_own_pitch(ticks, fell):
    state = TickProgress()
    with pytest.MonkeyPatch.context() as mp:
        profile(_learner(ticks, fell, mp), state, "pitch")
    np.testing.assert_allclose(state.profiles["pitch"], _nominal(np.arange(LOOP)), atol=1e-12)
    (walk,) = state.tried.values()  # one walk, paid for and kept without its ticks
    assert state.sim_seconds == walk[0]["seconds"] and walk[0]["episode"] is None


def test_a_robot_that_falls_in_its_start_up_gives_what_it_walked(monkeypatch):
    """Nothing of the loop is left: the start-up's ticks before the last half second, each
    at its own loop tick, and 0 where no tick was seen."""
    lr, state = _learner(START - 5, True, monkeypatch), TickProgress()
    profile(lr, state, "pitch")
    seen = np.asarray(state.profiles["pitch"])
    assert np.count_nonzero(seen) == 5 and np.all(seen[seen != 0] == 9.0)
