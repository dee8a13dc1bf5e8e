"""The per-tick learner's log: typed entries that write the lines the learner always
wrote and read them back."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from imitwalk.balance.ticklog import (
    ScheduleEntry,
    TrialsEntry,
    TrustEntry,
    WalkSummary,
    entry_from_dict,
)
from imitwalk.errors import RunError

_num = st.floats(allow_nan=False, allow_infinity=False, width=32)
_walks = st.builds(
    WalkSummary, st.integers(0, 40), st.integers(1, 40), _num, _num, _num, _num, _num
)
_row = st.fixed_dictionaries({"value": _num, "falls": st.integers(0, 40)})
_entries = st.one_of(
    st.builds(ScheduleEntry, _num, st.integers(0, 5), _num, _walks, st.none()),
    st.builds(
        TrialsEntry,
        st.sampled_from(["pitch", "feedforward"]),
        _num,
        _num,
        st.sampled_from(["eval", "servo"]),
        st.lists(_row, max_size=3),
        st.sampled_from([None, "ankle_pitch"]),
        st.sampled_from([None, "gyro_y"]),
    ),
    st.builds(TrustEntry, _num, _num, st.lists(_row, max_size=3)),
)


@given(_entries)
def test_an_entry_reads_back_as_written(entry):
    line = entry.to_dict()
    assert line["stage"] == entry.STAGE
    assert entry_from_dict(line) == entry


def test_a_schedule_line_keeps_the_learners_keys_in_order():
    walks = WalkSummary(1, 4, 0.5, 40.0, 1.2, 3.0, 0.5)
    line = ScheduleEntry(0.8, 2, 0.0, walks, {"ratio_to_persistence": 0.3}).to_dict()
    assert list(line) == [
        "stage",
        "scale",
        "iteration",
        "explore",
        *walks.to_dict(),
        "held_out",
    ]


@pytest.mark.parametrize(
    "line, message",
    [
        ({"stage": "warmup"}, "stage 'warmup'; expected one of trials, schedule, trust"),
        ({"stage": "trust", "scale": 1.0}, "a trust line of the learning log lacks 'kept'"),
    ],
)
def test_a_line_of_another_kind_is_refused_in_one_line(line, message):
    with pytest.raises(RunError, match=message.replace("(", r"\(")):
        entry_from_dict(line)
