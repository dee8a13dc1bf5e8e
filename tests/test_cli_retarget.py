"""`imitwalk retarget` and `imitwalk playback` from the command line, bad input included."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from imitwalk.cli.main import main
from imitwalk.mocap.vicon import read_c3d
from tests.test_mocap_c3d import C3D, PIG_MARKERS, _cols, write_c3d


def _fails_in_one_line(capsys, argv, out, match):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("error: ") and match in err[-1], err
    assert "Traceback" not in "\n".join(err)
    assert not out.exists()  # no half-written output


def test_retarget_default_clip_json(tmp_path, capsys):
    out = tmp_path / "traj.npz"
    argv = ["retarget", "--out", str(out), "--json", "--no-search", "--set", "scales=[0.5,1.0]"]
    assert main(argv) == 0
    stats = json.loads(capsys.readouterr().out)
    for key in (
        "frames",
        "fps",
        "cycles_found",
        "cycle_period_s",
        "ik_residual_mm_mean",
        "ik_residual_mm_max",
        "clipped_fraction",
        "foot_skate_mm_per_step",
        "frames_per_second_solved",
        "stance_tilt_deg_max",
        "swing_clearance_mm_min",
        "loop_closure_rad_max",
    ):
        assert key in stats
    assert stats["frames"] == 39 and stats["fps"] == 30.0 and stats["cycles_found"] >= 1
    assert stats["cycles_used"].startswith("frames ")  # which frames, and why
    with np.load(out) as z:
        assert z["q"].shape[1] == 25 and "residual_mm" in z.files


def test_playback_json(tmp_path, capsys):
    out = tmp_path / "traj.npz"
    assert main(["retarget", "--out", str(out), "--no-search", "--set", "scales=[0.5]"]) == 0
    capsys.readouterr()
    argv = ["playback", str(out), "--scale", "0.5", "--seconds", "3", "--models", "2", "--json"]
    assert main(argv) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["models"] == 2 and len(res["runs"]) == 2
    assert {"fell", "forward_speed_mps", "progress_ratio", "yaw_drift_deg", "walked"} <= set(
        res["runs"][0]
    )


def test_truncated_bvh(shared_mocap, tmp_path, capsys):
    lines = (shared_mocap / "cmu_bvh" / "07_04.bvh").read_text().splitlines()
    bad = tmp_path / "cut.bvh"
    bad.write_text("\n".join(lines[: len(lines) // 2]) + "\n1.0 2.0\n")
    out = tmp_path / "o.npz"
    _fails_in_one_line(capsys, ["retarget", str(bad), "--out", str(out)], out, "line")


def test_amc_not_matching_its_asf(shared_mocap, tmp_path, capsys):
    src = shared_mocap / "cmu_asf_amc"
    shutil.copy(src / "test.asf", tmp_path / "s.asf")
    amc = (src / "test.amc").read_text().replace("lfemur", "lfemurX", 3)
    (tmp_path / "m.amc").write_text(amc)
    out = tmp_path / "o.npz"
    argv = [
        "retarget",
        str(tmp_path / "m.amc"),
        "--skeleton",
        str(tmp_path / "s.asf"),
        "--out",
        str(out),
    ]
    _fails_in_one_line(capsys, argv, out, "lfemurX")


def test_c3d_with_nan_markers(shared_mocap, tmp_path, capsys):
    m = read_c3d(shared_mocap / C3D)
    pts = np.stack([m.data[:, _cols(m, lab)] for lab in PIG_MARKERS], axis=1)
    pts[:, PIG_MARKERS.index("LKNE")] = np.nan
    bad = write_c3d(tmp_path / "nan.c3d", list(PIG_MARKERS), pts, m.fps)
    out = tmp_path / "o.npz"
    _fails_in_one_line(capsys, ["retarget", str(bad), "--out", str(out)], out, "LKNE")


def test_unknown_extension(tmp_path, capsys):
    bad = tmp_path / "walk.fbx"
    bad.write_text("x")
    out = tmp_path / "o.npz"
    _fails_in_one_line(capsys, ["retarget", str(bad), "--out", str(out)], out, ".bvh")


def test_clip_without_a_walking_cycle(shared_mocap, tmp_path, capsys):
    lines = (shared_mocap / "cmu_bvh" / "07_04.bvh").read_text().splitlines()
    head = lines.index("MOTION")
    frame = lines[head + 4]
    still = lines[: head + 1] + ["Frames: 240", "Frame Time: .0083333"] + [frame] * 240
    bad = tmp_path / "still.bvh"
    bad.write_text("\n".join(still) + "\n")
    out = tmp_path / "o.npz"
    _fails_in_one_line(capsys, ["retarget", str(bad), "--out", str(out)], out, "no walking cycle")


def test_unknown_setting(tmp_path, capsys):
    out = tmp_path / "o.npz"
    argv = ["retarget", "--out", str(out), "--set", "search_config.generationz=2"]
    _fails_in_one_line(capsys, argv, out, "valid:")


@pytest.mark.slow
@pytest.mark.parametrize("clip", ["default", "cmu_bvh/07_04.bvh", "cmu_bvh/07_06.bvh"])
def test_reference_walks_open_loop_at_half_scale(shared_mocap, tmp_path, capsys, clip):
    """The issue's dynamics criterion: with its searched parameters, the reference walks
    open loop at scale 0.5 on at least 5 of 6 robots (nominal + 5 perturbed), 20 s each."""
    out = tmp_path / "traj.npz"
    argv = ["retarget", "--out", str(out)] + (
        [] if clip == "default" else [str(shared_mocap / clip)]
    )
    assert main(argv) == 0
    capsys.readouterr()
    argv = ["playback", str(out), "--scale", "0.5", "--seconds", "20", "--models", "6", "--json"]
    assert main(argv) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["walked"] >= 5, res
