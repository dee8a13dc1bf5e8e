"""Fuzzing the mocap readers with seeded mutations of the real files
(:mod:`tests.helpers.fuzz_mocap`).

Each case must end in a project error (:class:`~imitwalk.errors.ImitwalkError`) or in a
Motion that is finite and within the bounds of :mod:`imitwalk.mocap.bounds`, within a
time limit: any other exception, an implausible result or a hang fails the test. The
default run does :data:`DEFAULT_CASES` per format; ``-m slow`` does :data:`SLOW_CASES`
(the figures in BENCHMARKS.md come from its command line, ``python -m
tests.helpers.fuzz_mocap``, the same cases).
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

import pytest

from tests.helpers.fuzz_mocap import FORMATS, make_case, run_case, seeds

DEFAULT_CASES = 250
SLOW_CASES = 2000
LIMIT_S = 10.0  # per case


@cache
def _pool(folder: str):
    return seeds(Path(folder))


def _fuzz(shared: Path, tmp: Path, fmt: str, cases: range) -> None:
    pool = _pool(str(shared))
    bad = []
    for i in cases:
        case = make_case(fmt, i, pool)
        outcome, detail = run_case(case, tmp, LIMIT_S)
        if outcome not in ("error", "accepted"):
            bad.append(f"case {i} ({case.mutation}): {outcome}: {detail}")
    assert not bad, f"{len(bad)} of {len(cases)} {fmt} cases failed:\n" + "\n".join(bad[:20])


@pytest.mark.parametrize("fmt", FORMATS)
def test_fuzz(shared_mocap, tmp_path, fmt):
    _fuzz(shared_mocap, tmp_path, fmt, range(DEFAULT_CASES))


@pytest.mark.slow
@pytest.mark.parametrize("fmt", FORMATS)
def test_fuzz_slow(shared_mocap, tmp_path, fmt):
    _fuzz(shared_mocap, tmp_path, fmt, range(SLOW_CASES))


def test_a_hang_is_caught(tmp_path, monkeypatch):
    """The time limit interrupts a reader that never returns."""
    from tests.helpers import fuzz_mocap

    def forever(path):
        while True:
            pass

    monkeypatch.setattr(fuzz_mocap, "load_motion", forever)
    case = fuzz_mocap.Case({"x.bvh": b""}, "x.bvh", "none")
    assert run_case(case, tmp_path, 0.2) == ("hang", "> 0.2 s")
