"""Fuzzing what imitwalk reads back and writes (:mod:`tests.helpers.fuzz_files`, issue
60): reference ``.npz`` files, run-folder files and output paths.

Each case must end in a one-line project error (:class:`~imitwalk.errors.ImitwalkError`)
or in a usable result (a reference that plays, a run file read as its record, an output
path then written), within a time limit; a refused output path leaves nothing behind.
The default run does :data:`DEFAULT_CASES` per input; ``-m slow`` does
:data:`SLOW_CASES`.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from imitwalk.cli.main import main
from tests.helpers.fuzz_files import INPUTS, OUTCOMES, fuzz, make_case

DEFAULT_CASES = 300
SLOW_CASES = 2000


@pytest.fixture(scope="module")
def seed(tmp_path_factory) -> bytes:
    """A real reference's bytes (retargeted without its search, one scale)."""
    out = tmp_path_factory.mktemp("ref") / "ref.npz"
    assert main(["retarget", "--out", str(out), "--no-search", "--set", "scales=[0.5]"]) == 0
    return out.read_bytes()


def _clean(report: dict, kind: str) -> None:
    assert set(report["counts"]) == set(OUTCOMES)
    bad = {k: v for k, v in report["counts"].items() if k not in ("error", "accepted") and v}
    assert not bad, (kind, bad, report["failures"][:10])
    assert report["counts"]["error"] > 0 and report["counts"]["accepted"] > 0, report


def test_the_mutations_are_seeded_and_varied(seed):
    for kind in INPUTS:
        a = [make_case(kind, i, seed) for i in range(40)]
        assert a == [make_case(kind, i, seed) for i in range(40)]
        assert len({c.mutation for c in a}) > 5, kind


@pytest.mark.parametrize("kind", INPUTS)
def test_fuzz(seed, tmp_path: Path, kind):
    _clean(fuzz(kind, range(DEFAULT_CASES), seed, tmp_path / "case"), kind)


@pytest.mark.slow
@pytest.mark.parametrize("kind", INPUTS)
def test_fuzz_slow(seed, tmp_path: Path, kind):
    _clean(fuzz(kind, range(SLOW_CASES), seed, tmp_path / "case"), kind)
