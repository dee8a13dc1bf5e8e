"""The robot loader fuzzed: mutated hoap2 joint maps and MJCF give a one-line project
error naming the file or a valid robot within the plausibility bounds, never another
exception, a NaN, an implausible robot, or a hang (issues 34, 60)."""

from __future__ import annotations

import pytest

from tests.helpers.fuzz_robot import OUTCOMES, cases, fuzz

#: Cases of the default run (half per input) and of the slow one (2,000 per input).
DEFAULT, SLOW = 300, 4000


def _clean(report: dict) -> None:
    for kind, counts in report["counts"].items():
        assert set(counts) == set(OUTCOMES)
        bad = {k: v for k, v in counts.items() if k not in ("project_error", "accepted") and v}
        assert not bad, (kind, bad, report["failures"][:5])


def test_the_mutations_are_seeded_and_cover_both_inputs():
    a, b = list(cases(40, seed=3)), list(cases(40, seed=3))
    assert a == b and {c.kind for c in a} == {"map", "mjcf"}
    assert len({c.how for c in a}) > 20  # many different mutations


def test_fuzzed_robot_files_give_an_error_or_a_valid_robot():
    report = fuzz(DEFAULT, seed=0, timeout=20.0)
    _clean(report)
    for counts in report["counts"].values():
        assert counts["project_error"] > 0 and counts["accepted"] > 0


@pytest.mark.slow
def test_fuzzed_robot_files_slow():
    report = fuzz(SLOW, seed=1, timeout=20.0)
    _clean(report)
    assert sum(sum(c.values()) for c in report["counts"].values()) == SLOW
