"""How the trials rank candidates (pure: made-up walk results)."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.balance.tickrun import TickResult, Trial, best


def _walks(falls: int, robots: int = 8, yaw: float | tuple = 2.0, cost: float = 1.0) -> Trial:
    """``robots`` walks, the first ``falls`` fallen; ``yaw``: every walk's drift [deg], or
    one per walk."""
    yaws = yaw if isinstance(yaw, tuple) else (yaw,) * robots
    return Trial(
        [
            TickResult(
                j,
                j < falls,
                3.0 if j < falls else None,
                3.0 if j < falls else 10.0,
                1.0,
                yaws[j],
                float("inf") if j < falls else cost,
            )
            for j in range(len(yaws))
        ]
    )


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(st.integers(0, 8), st.floats(0.0, 1.0), st.floats(0.1, 3.0)),
        min_size=1,
        max_size=6,
    )
)
def test_the_fewest_falls_win_then_the_smallest_gain_whatever_the_cost(rows):
    table = [(round(0.05 * i, 2), _walks(f, cost=c)) for i, (f, _, c) in enumerate(rows)]
    kept = best(table)
    fewest = min(t.summary().falls for _, t in table)
    assert kept[1].summary().falls == fewest
    assert kept[0] == min(v for v, t in table if t.summary().falls == fewest)


def test_the_heading_gain_is_the_smallest_that_keeps_the_drift_under_its_limit():
    limit = 10.0  # deg, over the heading's whole walks
    table = [(0.0, _walks(0, yaw=12.0)), (-0.25, _walks(0, yaw=8.0)), (-0.5, _walks(0, yaw=3.0))]
    pick = lambda t: best(t, limit)[0]  # noqa: E731
    assert pick(table) == -0.25  # the least steering within the limit, not the least drift
    assert pick([(v, _walks(0, yaw=y)) for v, y in ((0.0, 9.0), (-0.5, 1.0))]) == 0.0
    assert pick([(v, _walks(0, yaw=y)) for v, y in ((0.0, 19.0), (-0.5, 15.0))]) == -0.5
    assert pick([(0.0, _walks(0, yaw=19.0)), (-0.5, _walks(1, yaw=1.0))]) == 0.0  # falls first


def test_a_drift_just_under_the_limit_must_hold_by_one_standard_error():
    limit = 10.0
    pick = lambda t: best(t, limit)[0]  # noqa: E731
    wide = _walks(0, yaw=(1.0, 2.0, 3.0, 10.0, 15.0, 17.0))  # mean 8.0, standard error 2.9
    narrow = _walks(0, yaw=(7.0, 8.0, 8.0, 8.0, 8.0, 9.0))  # mean 8.0, standard error 0.3
    steered = _walks(0, yaw=(4.0, 5.0, 5.0, 5.0, 5.0, 6.0))
    assert pick([(0.0, wide), (-0.25, steered)]) == -0.25
    assert pick([(0.0, narrow), (-0.25, steered)]) == 0.0
    # the sign of a drift does not count, only its size
    signed = _walks(0, yaw=(-1.0, 2.0, -3.0, 10.0, -15.0, 17.0))
    assert wide.summary().abs_yaw_se_deg == signed.summary().abs_yaw_se_deg


def test_where_every_robot_fell_the_longest_walked_wins():
    def fell_at(t: float) -> Trial:
        return Trial([TickResult(j, True, t, t, 0.1, 1.0, float("inf")) for j in range(4)])

    table = [(0.0, fell_at(2.2)), (0.5, fell_at(2.3)), (1.0, fell_at(6.0))]
    assert best(table)[0] == 1.0
    # but a robot that stays up outranks any fall time, and with one up the walk's
    # length does not count
    table += [(2.0, _walks(3, robots=4)), (3.0, _walks(3, robots=4))]
    assert best(table)[0] == 2.0
