"""Clips too short for a gait cycle: a one-line error, never a hang (1- and 2-frame BVH)."""

from __future__ import annotations

import threading
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.cli import main
from imitwalk.mocap.cycles import _clean_runs


def _short_bvh(shared_mocap: Path, tmp_path: Path, frames: int) -> Path:
    """07_04.bvh cut to its hierarchy and first ``frames`` data lines (frame 0: the T-pose)."""
    lines = (shared_mocap / "cmu_bvh" / "07_04.bvh").read_text().splitlines()
    at = next(i for i, line in enumerate(lines) if line.startswith("Frames:"))
    kept = [*lines[:at], f"Frames: {frames}", lines[at + 1], *lines[at + 2 : at + 2 + frames]]
    out = tmp_path / f"f{frames}.bvh"
    out.write_text("\n".join(kept) + "\n")
    return out


@pytest.mark.parametrize("frames", [1, 2])
@pytest.mark.parametrize("command", ["retarget", "learn"])
def test_cli_refuses_a_clip_shorter_than_a_cycle(shared_mocap, tmp_path, capsys, frames, command):
    bvh = _short_bvh(shared_mocap, tmp_path, frames)
    out = tmp_path / ("x.npz" if command == "retarget" else "RUN")
    argv = [command, str(bvh), "--out", str(out)]
    assert main([*argv, "--no-search"] if command == "retarget" else argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert "Traceback" not in "\n".join(err)
    last = err[-1]
    assert last.startswith("error: no walking cycle found in ") and "only 1 frame " in last, err
    assert "need >= 48 frames" in last and "0.4 s" in last  # 120 fps: the minimum is named
    assert ("T-pose" in last) == (frames == 2)  # the 2nd frame is the only one after the T-pose
    assert not out.exists()


def _finishes(mask: np.ndarray, min_len: int) -> np.ndarray:
    """``_clean_runs(mask, min_len)``, failing the test if it runs for more than 10 s."""
    result: list[np.ndarray] = []
    worker = threading.Thread(target=lambda: result.append(_clean_runs(mask, min_len)), daemon=True)
    worker.start()
    worker.join(10.0)
    assert result, f"_clean_runs did not finish on {mask!r} (min_len {min_len})"
    return result[0]


DEGENERATE = [[], [True], [False], [True] * 3, [False] * 5, [True] * 20, [True, False]]


@pytest.mark.parametrize("mask", [*DEGENERATE, [False, True, False]])
@pytest.mark.parametrize("min_len", [0, 1, 6])
def test_clean_runs_terminates_on_degenerate_masks(mask, min_len):
    m = np.array(mask, dtype=bool)
    out = _finishes(m, min_len)
    assert out.dtype == bool and out.shape == m.shape
    if len(set(mask)) <= 1:  # empty or one run: nothing to merge into, kept as it is
        np.testing.assert_array_equal(out, m)
    if mask == [False, True, False] and min_len == 6:
        assert not out.any()  # a short inner run is merged into its neighbours


@settings(max_examples=200, deadline=None)
@given(st.lists(st.booleans(), max_size=60), st.integers(0, 12))
def test_clean_runs_keeps_ends_and_leaves_no_short_inner_run(mask, min_len):
    m = np.array(mask, dtype=bool)
    out = _finishes(m, min_len)
    if len(m):
        assert out[0] == m[0] and out[-1] == m[-1]  # the end runs are never flipped
    lengths = np.diff(np.flatnonzero(np.diff(np.r_[-1, out.astype(int), -1]) != 0))
    assert np.all(lengths[1:-1] >= min_len)
