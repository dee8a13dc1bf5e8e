"""The ``time`` step channel: its settings, its clock, and old runs without it."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.balance import STEP_CHANNELS, STEP_STATE, StepConfig, StepController
from imitwalk.errors import ConfigError
from imitwalk.learnconfig import TickConfig, preset
from imitwalk.models import stack_episodes, unstack_episodes

T = STEP_CHANNELS.index("time")


def test_time_is_off_by_default_and_its_box_is_zero_then():
    cfg = StepConfig()
    assert "time" not in cfg.channels
    ctrl = StepController(cfg, 100, 0.1)
    assert ctrl.box[T] == 0.0 and ctrl.rate(0) == 1.0


def test_unknown_channel_lists_the_valid_ones():
    with pytest.raises(ConfigError, match=r"unknown step channel 'tempo'.*time"):
        StepConfig(channels=("dx", "tempo"))


def test_c_max_needs_one_value_per_channel():
    with pytest.raises(ConfigError, match=r"step\.c_max has 3 values"):
        StepConfig(c_max=(0.1, 0.1, 0.1))


def test_a_run_written_before_the_time_channel_loads_with_time_off():
    cfg = StepConfig(c_max=(0.015, 0.012, 0.04, 0.008, 0.01))
    assert len(cfg.c_max) == len(STEP_CHANNELS) and cfg.c_max[T] == 0.0
    A_old = np.c_[np.ones((4, 5)), np.full(4, 0.7)]  # five channels and the scale
    data = unstack_episodes(stack_episodes({"step": [(np.zeros((4, 8)), A_old)]}))
    A = data["step"][0][1]
    assert A.shape == (4, len(STEP_CHANNELS) + 1)
    assert np.all(A[:, T] == 0.0) and np.all(A[:, -1] == 0.7) and np.all(A[:, :5] == 1.0)


def test_time_needs_the_tick_search_off():
    step = StepConfig(channels=(*STEP_CHANNELS,))
    preset("extended", step=step)  # the extended variant has it off
    with pytest.raises(ConfigError, match=r"tick\.enabled=false"):
        preset("extended", step=step, tick=TickConfig(enabled=True))


@given(st.floats(-0.15, 0.15))
def test_rate_is_one_over_one_plus_time(tau):
    ctrl = StepController(StepConfig(channels=STEP_CHANNELS), 100, 0.1)
    ctrl.decide(np.zeros(len(STEP_STATE)), 0)
    ctrl.actions[-1][T] = tau
    assert ctrl.rate(0) == pytest.approx(1.0 / (1.0 + tau))
    assert ctrl.rate(1) == 1.0  # not decided yet


class _Fixed(StepController):
    """Decides the same ``time`` for every step."""

    def __init__(self, tau: float, *args, **kw):
        super().__init__(*args, **kw)
        self.tau = tau

    def decide(self, state_raw, k):
        c = super().decide(state_raw, k)
        c[T] = self.tau
        return c


@settings(max_examples=5, deadline=None)
@given(st.sampled_from([-0.1, 0.0, 0.12]))
def test_the_plan_runs_on_its_own_clock(tiny_reference, tau):
    from imitwalk.gait import GaitModel

    ref, _ = tiny_reference
    gait = GaitModel(ref, (0.3, 0.4), preset("extended").gait)
    cfg = StepConfig(channels=STEP_CHANNELS)
    calls = []
    from imitwalk.policy import WalkPolicy

    policy = WalkPolicy(
        gait,
        0.4,
        steps=_Fixed(tau, cfg, gait.n_ticks, 0.1),
        channel_ik=lambda k, off: calls.append(k) or np.zeros(ref.loops.shape[-1]),
    )
    obs = SimpleNamespace(
        gyro=np.zeros(3), accel=np.array([0, 0, 9.81]), foot_force=np.ones((2, 4))
    )
    c0, n = policy._clock0, gait.n_ticks
    qs = [policy(k, obs) for k in range(c0 + 2 * n)]
    # before the feet step: the reference, tick for tick
    np.testing.assert_allclose(qs[c0 - 1], policy._reference(c0 - 1))
    # then the plan's clock advances 1 / (1 + τ) ticks per control tick, from the clock's start
    v = np.asarray(calls)
    np.testing.assert_allclose(np.diff(v), 1.0 / (1.0 + tau), rtol=1e-12)
    # and the targets are the reference, linear between its ticks
    for k in (c0 + 7, c0 + n + 3):
        x = v[k - c0]
        k0 = int(np.floor(x))
        a = x - k0
        want = (1 - a) * policy._reference(k0) + a * policy._reference(k0 + 1)
        np.testing.assert_allclose(qs[k], want, atol=1e-12)


def test_online_ik_plan_is_linear_between_ticks(robot, tiny_reference):
    from imitwalk.retarget.online import OnlineIK

    ref, _ = tiny_reference
    ik = OnlineIK(robot, ref, 0.4)
    n_loop = ref.loops.shape[1]
    n_total = ref.starts.shape[1] + n_loop
    for k in (5, n_total - 1, n_total + n_loop + 3):  # start-up, the wrap, a later loop
        a, b, mid = ik._tick_plan(k), ik._tick_plan(k + 1), ik._tick_plan(k + 0.25)
        for key in ("l_sole", "r_sole", "com", "pelvis_z", "yaw"):
            np.testing.assert_allclose(
                getattr(mid, key), 0.75 * getattr(a, key) + 0.25 * getattr(b, key)
            )
        for u in a.upper:
            np.testing.assert_allclose(mid.upper[u], 0.75 * a.upper[u] + 0.25 * b.upper[u])
