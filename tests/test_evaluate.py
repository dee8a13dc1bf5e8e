"""The paired fall comparison of a learned run against open-loop playback (pure NumPy)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.paper.evaluate import compare_falls, wilson


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 200).flatmap(lambda n: st.tuples(st.integers(0, n), st.just(n))))
def test_the_wilson_interval_holds_the_observed_rate(kn):
    k, n = kn
    lo, hi = wilson(k, n)
    assert 0.0 <= lo <= hi <= 1.0
    if n:
        assert lo <= k / n <= hi


def test_wilson_matches_a_textbook_value():
    # 2 of 10: 95 % Wilson interval 0.057–0.510 (Newcombe 1998, method 3)
    assert wilson(2, 10) == pytest.approx((0.0567, 0.5098), abs=5e-4)


def test_ten_robots_cannot_tell_none_from_two_falls():
    out = compare_falls([False] * 10, [True, True] + [False] * 8)
    assert (out["learned_only"], out["open_only"]) == (0, 2)
    assert out["mcnemar_p"] == pytest.approx(0.5)
    assert out["learned_fall_rate"] == 0.0 and out["open_loop_fall_rate"] == 0.2


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.booleans(), st.booleans()), min_size=1, max_size=60))
def test_the_comparison_is_symmetric_and_counts_only_discordant_robots(pairs):
    a = [p[0] for p in pairs]
    b = [p[1] for p in pairs]
    ab, ba = compare_falls(a, b), compare_falls(b, a)
    assert (ab["learned_only"], ab["open_only"]) == (ba["open_only"], ba["learned_only"])
    assert ab["mcnemar_p"] == pytest.approx(ba["mcnemar_p"])
    assert 0.0 < ab["mcnemar_p"] <= 1.0
    assert ab["learned_only"] - ab["open_only"] == sum(a) - sum(b)


def test_lists_of_different_robots_are_refused():
    with pytest.raises(ValueError, match="same robots"):
        compare_falls([True], [True, False])
