"""C3D reader on the real treadmill trial, and copies written with the c3d package."""

from __future__ import annotations

import warnings
from functools import cache
from pathlib import Path

import c3d
import numpy as np
import pytest

from imitwalk.errors import MocapError
from imitwalk.mocap import LOWER_BODY, leg_angles
from imitwalk.mocap.vicon import read_c3d

C3D = "c3d/treadmill_events.c3d"
PIG_MARKERS = ["LASI", "RASI", "LPSI", "RPSI", "C7", "CLAV"] + [
    f"{s}{m}" for s in "LR" for m in ("THI", "KNE", "TIB", "ANK", "TOE")
]


@cache
def _trial(path: str):
    return read_c3d(path)


@pytest.fixture
def trial(shared_mocap):
    return _trial(str(shared_mocap / C3D))


def _cols(m, label: str) -> slice:
    i = m.channels.index(f"{label}.x")
    return slice(i, i + 3)


def write_c3d(path: Path, labels: list[str], points: np.ndarray, rate: float) -> Path:
    """Write ``(T, N, 3)`` points [mm] to a C3D file; NaN samples are marked invalid."""
    w = c3d.Writer(point_rate=rate)
    w.set_point_labels(labels)
    for frame in points:
        pts = np.zeros((len(labels), 5), np.float32)
        bad = ~np.isfinite(frame).all(axis=1)
        pts[:, :3] = np.where(bad[:, None], 0.0, frame)
        pts[bad, 3] = -1.0
        w.add_frames([(pts, np.zeros((0, 0)))])
    with path.open("wb") as handle, warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="No analog data", category=UserWarning)
        w.write(handle)
    return path


def pig_markers_only(m, tmp_path: Path, edit=None) -> Path:
    """A copy of the trial with just the Plug-in-Gait markers (no model outputs)."""
    pts = np.stack([m.data[:, _cols(m, lab)] for lab in PIG_MARKERS], axis=1)  # (T, N, 3) mm
    labels = list(PIG_MARKERS)
    if edit is not None:
        labels, pts = edit(labels, pts.copy())
    return write_c3d(tmp_path / "pig.c3d", labels, pts, m.fps)


def test_prefers_plugin_gait_outputs(trial):
    m = trial
    assert (m.n_frames, m.fps, m.meta["units"], m.meta["up_axis"]) == (1206, 100.0, "mm", "z")
    assert m.meta["hip_method"] == "plug-in-gait outputs" and m.filled == ()
    arms = {f"{s}_{j}" for s in "lr" for j in ("shoulder", "elbow", "wrist")}
    assert set(m.meta["missing_keypoints"]) == arms | {"head"}  # no arm / head markers
    assert "neck" in m.keypoints and not (arms & set(m.keypoints))
    np.testing.assert_allclose(m.keypoints["l_knee"], m.data[:, _cols(m, "LFEO")] / 1000)
    np.testing.assert_allclose(m.keypoints["r_hip"], m.data[:, _cols(m, "RFEP")] / 1000)


def test_knee_flexion_matches_plugin_gait_angles(trial):
    for s in "LR":
        _, knee = leg_angles(trial, s.lower())
        ref = trial.data[:, trial.channels.index(f"{s}KneeAngles.x")]  # deg
        assert np.corrcoef(np.degrees(knee), ref)[0, 1] > 0.99
        assert np.mean(np.abs(np.degrees(knee) - ref)) < 3.0


def test_events_are_read(trial):
    ev = trial.meta["events"]
    assert len(ev) == 43 and {e[1] for e in ev} == {"Foot Strike", "Foot Off"}
    assert {e[0] for e in ev} == {"Left", "Right"}
    assert all(0 <= e[3] < trial.n_frames for e in ev)


def test_markers_only_close_to_plugin_gait(trial, tmp_path):
    m = read_c3d(pig_markers_only(trial, tmp_path))
    assert m.meta["hip_method"] == "harrington2007" and m.n_frames == trial.n_frames
    err = {
        k: np.linalg.norm(m.keypoints[k] - trial.keypoints[k], axis=1).mean() for k in LOWER_BODY
    }
    # Harrington (2007) and Plug-in-Gait's Davis hip regression differ by a few cm; the
    # chord rule for knees / ankles is Plug-in-Gait's own, given the hips.
    assert max(err["l_hip"], err["r_hip"]) < 0.04
    assert max(err[k] for k in ("l_knee", "r_knee", "l_ankle", "r_ankle")) < 0.015
    assert err["l_toe"] < 1e-6


def test_short_gap_is_filled_and_reported(trial, tmp_path):
    def gap(labels, pts):
        pts[200:205, labels.index("LTOE")] = np.nan
        return labels, pts

    m = read_c3d(pig_markers_only(trial, tmp_path, gap))
    assert len(m.filled) == 1 and "LTOE: frames 200-204" in m.filled[0]
    assert np.isnan(m.data[200:205, _cols(m, "LTOE")]).all()
    err = np.linalg.norm(m.keypoints["l_toe"][200:205] - trial.keypoints["l_toe"][200:205], axis=1)
    assert err.max() < 0.01


def _one_line(fn, match: str) -> None:
    with pytest.raises(MocapError, match=match) as info:
        fn()
    assert "\n" not in str(info.value)


def test_long_gap_names_the_marker(trial, tmp_path):
    def gap(labels, pts):
        pts[300:330, labels.index("RANK")] = np.nan  # 0.3 s
        return labels, pts

    path = pig_markers_only(trial, tmp_path, gap)
    _one_line(lambda: read_c3d(path), r"marker RANK is missing in frames 300-329 \(0.3 s\)")
    assert read_c3d(path, max_gap=0.5).filled  # a longer allowance fills it


def test_all_invalid_required_marker(trial, tmp_path):
    def dead(labels, pts):
        pts[:, labels.index("LTOE")] = np.nan
        return labels, pts

    _one_line(lambda: read_c3d(pig_markers_only(trial, tmp_path, dead)), "marker LTOE has no valid")


def test_absent_required_marker(trial, tmp_path):
    def drop(labels, pts):
        i = labels.index("LASI")
        return labels[:i] + labels[i + 1 :], np.delete(pts, i, axis=1)

    path = pig_markers_only(trial, tmp_path, drop)
    _one_line(lambda: read_c3d(path), r"required marker LASI not found \(tried LASI, LASIS, LFWT\)")


def test_not_a_c3d(tmp_path):
    path = tmp_path / "x.c3d"
    path.write_bytes(b"\0" * 600)
    _one_line(lambda: read_c3d(path), "not a C3D file: byte 2 of its header is 0")
