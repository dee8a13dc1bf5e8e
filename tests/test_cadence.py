"""The reference's loop at another cadence (pure NumPy, on a real retargeted clip)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.errors import ConfigError
from imitwalk.retarget.cadence import with_cadence


@settings(max_examples=15, deadline=None)
@given(rate=st.floats(0.8, 1.3))
def test_the_loop_is_resampled_and_stays_closed(tiny_reference, rate):
    ref, _ = tiny_reference
    out = with_cadence(ref, rate)
    n = ref.loops.shape[1]
    n2 = out.loops.shape[1]
    assert n2 == round(n / rate) and out.period == pytest.approx(n2 * ref.dt)
    if n2 == n:
        assert out is ref
        return
    assert out.settings["cadence"] == pytest.approx(n / n2)
    # the start-up keeps the human's cadence and still flows into the loop's first tick
    m2 = out.starts.shape[1]
    np.testing.assert_array_equal(out.starts, ref.starts)
    np.testing.assert_array_equal(out.start_travel, ref.start_travel)
    np.testing.assert_allclose(out.loops[:, 0], ref.loops[:, 0])
    # linear resampling of a closed loop: every value lies between the loop's extremes, and
    # the last tick is as close to the first as a tick of the original loop
    lo, hi = ref.loops.min(axis=1), ref.loops.max(axis=1)
    assert np.all(out.loops >= lo[:, None] - 1e-12) and np.all(out.loops <= hi[:, None] + 1e-12)
    step = np.abs(np.diff(ref.loops, axis=1, append=ref.loops[:, :1])).max()
    assert np.abs(out.loops[:, -1] - out.loops[:, 0]).max() <= step * max(rate, 1.0) + 1e-9
    # the plan keeps its shape: the feet still advance by one stride per loop
    for key, arr in out.plan.items():
        assert arr.shape[1] == m2 + n2 and arr.shape[2:] == ref.plan[key].shape[2:]
    sole = out.plan["l_sole"][:, m2:, 0]
    assert np.all(sole[:, -1] - sole[:, 0] <= ref.strides + 1e-9)
    assert np.all(np.diff(out.phase) > 0) and 0.0 <= out.phase.min() and out.phase.max() < 1.0
    assert out.stance.shape == (n2, 2) and out.residual_mm.shape == (len(ref.scales), m2 + n2)
    # same strides, shorter cycles: the commanded speed grows by N / N'
    speed = lambda r: r.expected_distance(0.4, 60.0) - r.expected_distance(0.4, 40.0)  # noqa: E731
    assert speed(out) / speed(ref) == pytest.approx(n / n2, rel=0.02)


def test_rate_one_is_the_reference_itself(tiny_reference):
    ref, _ = tiny_reference
    assert with_cadence(ref, 1.0) is ref


@pytest.mark.parametrize("rate", [0.0, 0.3, 2.5, float("nan")])
def test_an_impossible_rate_is_refused(tiny_reference, rate):
    ref, _ = tiny_reference
    with pytest.raises(ConfigError, match=r"0\.5 <= rate <= 2"):
        with_cadence(ref, rate)


def test_retarget_can_play_the_clip_at_another_cadence(robot, tiny_reference):
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.retarget import GaitParams, RetargetConfig, retarget

    ref, _ = tiny_reference
    cfg = RetargetConfig(
        search=False, scales=(0.3, 0.4), params=GaitParams(sway=0.9, ds=0.1), cadence=1.12
    )
    res = retarget(load_motion(default_clip()), robot, cfg)
    fast = res.reference
    assert fast.loops.shape[1] == round(ref.loops.shape[1] / 1.12)
    assert res.stats()["cadence"] == fast.settings["cadence"] > 1.1
    np.testing.assert_allclose(fast.loops, with_cadence(ref, 1.12).loops)


def test_rates_compound_relative_to_the_human(tiny_reference):
    ref, _ = tiny_reference
    twice = with_cadence(with_cadence(ref, 1.12), 1.12)
    n, n3 = ref.loops.shape[1], twice.loops.shape[1]
    assert twice.settings["cadence"] == pytest.approx(n / n3)
