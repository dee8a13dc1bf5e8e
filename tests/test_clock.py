"""The reference's clock made by the sole forces (the phase wait), on its own (the
per-tick policy's use of it: tests/test_feedforward.py)."""

from __future__ import annotations

import itertools

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from imitwalk.balance.clock import MAX_WAIT_S, LoadClock

DT = 0.01


def _plan(n_steps: int, period: int) -> np.ndarray:
    """``(T, 2)`` feet down: double support, then one foot lifted in turn."""
    down = np.ones((n_steps * period, 2), dtype=bool)
    for i in range(n_steps):
        down[i * period + period // 2 : (i + 1) * period, i % 2] = False
    return down


@given(st.integers(2, 6), st.integers(8, 40), st.floats(0.05, 0.9))
def test_an_unloaded_lifting_sole_never_holds_the_clock(n_steps, period, wait):
    down = _plan(n_steps, period)
    clock = LoadClock(down, wait, DT)
    for k in range(len(down)):
        force = np.full((2, 1), 50.0)
        if k:  # at tick k the clock steps over the reference's ticks k - 1 → k
            force[down[k - 1] & ~down[k]] = 0.0  # the sole about to lift carries nothing
        assert clock.tick(k, force) == k


@given(st.integers(2, 6), st.integers(8, 40), st.floats(0.05, 0.45))
def test_a_loaded_lifting_sole_holds_the_clock_at_most_max_wait_per_lift_off(n_steps, period, wait):
    down = _plan(n_steps, period)
    lift_offs = int(np.sum(down[:-1] & ~down[1:]))
    loaded = LoadClock(down, wait, DT)
    ticks = [loaded.tick(k, np.array([[50.0], [50.0]])) for k in range(2 * len(down))]
    assert ticks[0] == 0 and all(0 <= b - a <= 1 for a, b in itertools.pairwise(ticks))
    held = 2 * len(down) - 1 - ticks[-1]
    assert held <= lift_offs * round(MAX_WAIT_S / DT)
    assert held > 0  # both soles carry half: a lift-off waits
    free = LoadClock(down, 0.95, DT)  # a share never above 0.95 of two equal loads
    assert [free.tick(k, np.array([[50.0], [50.0]])) for k in range(len(down))] == list(
        range(len(down))
    )
