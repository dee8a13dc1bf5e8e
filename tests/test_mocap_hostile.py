"""One regression test per defect class of hostile mocap input (issue 34), on real files.

Each bad file gives a one-line MocapError naming the file and the line or field (or,
where the value moves nothing the pipeline uses, a warning naming it); none hangs.
"""

from __future__ import annotations

import json
import re
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from imitwalk.errors import MocapError, MocapWarning
from imitwalk.mocap import load_motion
from imitwalk.mocap.amc import read_amc
from imitwalk.mocap.bounds import FPS_RANGE, LEG_RANGE_M
from tests.test_cli_retarget import _fails_in_one_line

BVH = "cmu_bvh/07_04.bvh"
ASF, AMC = "cmu_asf_amc/test.asf", "cmu_asf_amc/test.amc"
C3D = "c3d/treadmill_events.c3d"
WALK = "deepmimic/humanoid3d_walk.txt"


class _Hang(BaseException):
    pass


def refused(path: Path, match: str, **kw) -> str:
    """The file is refused in one line matching ``match``, within 20 s."""

    def alarm(signum, frame):
        raise _Hang

    old = signal.signal(signal.SIGALRM, alarm)
    signal.alarm(20)
    try:
        with pytest.raises(MocapError, match=match) as info:
            load_motion(path, **kw)
    except _Hang:
        pytest.fail(f"reading {path.name} hangs")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    msg = str(info.value)
    assert "\n" not in msg and path.stem in msg, msg  # names the file (or its ASF)
    return msg


def edited(shared: Path, rel: str, tmp: Path, edit, name: str | None = None) -> Path:
    out = tmp / (name or Path(rel).name)
    out.write_text(edit((shared / rel).read_text()))
    return out


def bvh_with(shared: Path, tmp: Path, old: str, new: str, count: int = 1) -> Path:
    return edited(shared, BVH, tmp, lambda t: t.replace(old, new, count))


# --- numbers read with no finiteness check


@pytest.mark.parametrize("value", ["nan", "inf", "1e400", "4.5", "-3"])
def test_bvh_frames_not_a_count(shared_mocap, tmp_path, value):
    path = bvh_with(shared_mocap, tmp_path, "Frames: 450", f"Frames: {value}")
    refused(path, rf"line 186: Frames: '{value}' is not an integer in 0-")


@pytest.mark.parametrize("value", ["nan", "1e400", "7", "-1"])
def test_bvh_channels_not_a_count(shared_mocap, tmp_path, value):
    path = bvh_with(shared_mocap, tmp_path, "CHANNELS 3", f"CHANNELS {value}")
    refused(path, rf"line \d+: CHANNELS count '{value}' is not an integer in 0-6")


@pytest.mark.parametrize(
    ("value", "match"),
    [
        ("nan", r"line 187: non-finite value in 'nan'"),
        ("1e-320", r"line 187: Frame Time 1e-320: frame rate .* fps is outside 1-1000 fps"),
        ("1e-308", r"frame rate 1e\+308 fps is outside 1-1000 fps"),
        ("5", r"frame rate 0.2 fps is outside 1-1000 fps"),
    ],
)
def test_bvh_frame_time_gives_an_implausible_rate(shared_mocap, tmp_path, value, match):
    path = bvh_with(shared_mocap, tmp_path, "Frame Time: .0083333", f"Frame Time: {value}")
    refused(path, match)


@pytest.mark.parametrize("dt", [5e-324, 1e-9, 0.0, -0.03, 10.0])
def test_deepmimic_dt_gives_an_implausible_rate(shared_mocap, tmp_path, dt):
    def edit(text):
        doc = json.loads(text)
        doc["Frames"][0][0] = dt
        return json.dumps(doc)

    refused(edited(shared_mocap, WALK, tmp_path, edit), r"frame 0: dt .*(fps is outside|> 0 s)")


def test_amc_rate_outside_the_bounds(shared_mocap):
    lo, hi = FPS_RANGE
    for fps in (0.0, lo / 2, hi * 2, float("nan")):
        with pytest.raises(MocapError, match=r"frame rate .* fps is outside 1-1000 fps"):
            read_amc(shared_mocap / AMC, shared_mocap / ASF, fps=fps)


# --- rotation orders and axes never validated; ASF vectors of the wrong length


def test_bvh_repeated_rotation_axis(shared_mocap, tmp_path):
    path = bvh_with(
        shared_mocap, tmp_path, "Zrotation Yrotation Xrotation", "Xrotation Xrotation Xrotation"
    )
    refused(path, r"line 5: rotation channels 'xxx' must name each of X, Y, Z at most once")


def asf_with(shared: Path, tmp: Path, edit) -> Path:
    """A copy of the CMU pair with the ASF edited; returns the AMC's path."""
    (tmp / "clip.amc").write_bytes((shared / AMC).read_bytes())
    edited(shared, ASF, tmp, edit, "clip.asf")
    return tmp / "clip.amc"


@pytest.mark.parametrize(
    ("old", "new", "match"),
    [
        ("axis 0 0 20  XYZ", "axis 0 0 20  XQZ", r"line \d+: axis order 'XQZ' must name each"),
        ("axis XYZ", "axis XX", r"line 14: axis order 'XX' must name each of X, Y, Z at most"),
        ("dof rx ry rz", "dof rq", r"unknown dof 'rq'; valid: rx, ry, rz"),
        ("orientation 0 0 0", "orientation 0 0", r"line 16: root orientation has 2 values, exp"),
        ("position 0 0 0", "position 0 0", r"line 15: root position has 2 values, expected 3"),
        ("direction 0.34202 -0.939693 0", "direction 0.34202 -0.9", r"direction has 2 values"),
        ("order TX TY TZ RX RY RZ", "order TX TX TX RX RY RZ", r"line 13: dof .* repeats a d"),
        ("length 7.1578", "length nan", r"line \d+: non-finite value in 'nan'"),
    ],
)
def test_asf_malformed_fields(shared_mocap, tmp_path, old, new, match):
    amc = asf_with(shared_mocap, tmp_path, lambda t: t.replace(old, new, 1))
    with pytest.raises(MocapError, match=match) as info:
        load_motion(amc)
    assert "\n" not in str(info.value) and "clip.asf" in str(info.value)


@pytest.mark.parametrize(
    ("old", "new", "match"),
    [
        ("lfoot ltoes", "ltibia lfemur", r"bone 'lfemur' has two parents \(lhipjoint, ltibia\)"),
        ("lfoot ltoes", "lfoot lfoot", r"bone 'lfoot' has two parents \(ltibia, lfoot\)"),
        ("lhipjoint lfemur", "ltibia lfemur", r"the :hierarchy has a cycle through bone 'l"),
    ],
)
def test_asf_hierarchy_with_a_cycle_is_refused_not_followed(
    shared_mocap, tmp_path, old, new, match
):
    amc = asf_with(shared_mocap, tmp_path, lambda t: t.replace(old, new, 1))
    refused(amc, match)


@pytest.mark.parametrize("value", ["inf", "1e-300", "0", "-1", "nan"])
def test_asf_units_length_implausible(shared_mocap, tmp_path, value):
    amc = asf_with(shared_mocap, tmp_path, lambda t: t.replace("length 0.45", f"length {value}", 1))
    match = r"line 7: (non-finite value|:units length)|leg .* outside the human"
    with pytest.raises(MocapError, match=match):
        load_motion(amc)


# --- C3D: missing groups, truncated data, EVENT:TIMES, samples and units


def c3d_with(shared: Path, tmp: Path, edit) -> Path:
    data = bytearray((shared / C3D).read_bytes())
    edit(data)
    out = tmp / "trial.c3d"
    out.write_bytes(bytes(data))
    return out


def _at(data: bytearray, key: bytes) -> int:
    return bytes(data).find(key)


@pytest.mark.parametrize(
    ("key", "match"),
    [(b"\xfdPOINT", r"no POINT group"), (b"\x03LABELS", r"no POINT:LABELS parameter")],
)
def test_c3d_without_its_point_group_or_labels(shared_mocap, tmp_path, key, match):
    def rename(data):
        k = _at(data, key) + 1
        data[k] = ord("Q")

    refused(c3d_with(shared_mocap, tmp_path, rename), match)


def test_c3d_truncated_in_its_data_section(shared_mocap, tmp_path):
    def cut(data):
        del data[len(data) // 3 :]

    refused(c3d_with(shared_mocap, tmp_path, cut), r"data section ends after \d+ of 1206 frames")


def test_c3d_event_times_of_another_shape_or_not_finite(shared_mocap, tmp_path):
    def one_row(data):
        data[_at(data, b"TIMES") + 9] = 1  # dimensions (2, 43) -> (1, 43)

    with pytest.warns(MocapWarning, match=r"ignored the EVENT group: EVENT:TIMES of shape"):
        m = load_motion(c3d_with(shared_mocap, tmp_path, one_row))
    assert m.meta["events"] == [] and m.n_frames == 1206

    def nan_time(data):
        k = _at(data, b"TIMES") + 11 + 4  # the seconds of the first event
        data[k : k + 4] = np.float32(np.nan).tobytes()

    with pytest.warns(MocapWarning, match=r"dropped 1 event\(s\) whose EVENT:TIMES is not finite"):
        m = load_motion(c3d_with(shared_mocap, tmp_path, nan_time))
    assert len(m.meta["events"]) == 42


def test_c3d_wild_sample_is_an_invalid_sample(shared_mocap, tmp_path):
    ref = load_motion(shared_mocap / C3D)
    col = ref.channels.index("LTIO.x")
    frame = 500
    # the data start at block 62; a frame is 124 points x 4 float32 (x, y, z, residual), then
    # 24 analog channels x 10 samples x float32
    offset = 61 * 512 + frame * (124 * 16 + 240 * 4) + (col // 3) * 16

    def wild(data):
        data[offset : offset + 4] = np.float32(3e38).tobytes()

    with pytest.warns(MocapWarning, match=r"1 sample\(s\) not finite or beyond 1e\+06 m .*LTIO"):
        m = load_motion(c3d_with(shared_mocap, tmp_path, wild))
    assert np.isnan(m.data[frame, col]) and "LTIO: frames 500-500" in m.filled[0]
    err = np.abs(m.keypoints["l_ankle"][frame] - ref.keypoints["l_ankle"][frame]).max()
    assert err < 0.005  # interpolated over one frame


def test_c3d_point_units_m_on_mm_data(shared_mocap, tmp_path):
    def metres(data):
        k = _at(data, b"\x03UNITS") + 11
        assert bytes(data[k : k + 2]) == b"mm"
        data[k : k + 2] = b"m "

    msg = refused(c3d_with(shared_mocap, tmp_path, metres), r"leg .* outside the human 0.3-1.5 m")
    assert "check POINT:UNITS" in msg


# --- DeepMimic: nesting, types, huge numbers


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ('{"Loop": "wrap", "Frames": ' + "[" * 10**5 + "]" * 10**5 + "}", r"nested too deeply"),
        ('{"Loop": "wrap", "Frames": 5}', r"no 'Frames' list"),
        ('{"Frames": [[' + "1" + "0" * 400 + "]]}", r"'Frames' holds 1 frame"),
    ],
)
def test_deepmimic_malformed_documents(tmp_path, text, match):
    path = tmp_path / "m.txt"
    path.write_text(text)
    refused(path, match)


def test_deepmimic_integer_too_large_for_a_float(shared_mocap, tmp_path):
    def edit(text):
        doc = json.loads(text)
        doc["Frames"][3][1] = "__big__"
        return json.dumps(doc).replace('"__big__"', "1" + "0" * 400)

    refused(edited(shared_mocap, WALK, tmp_path, edit), r"too large for a float")


def test_deepmimic_huge_quaternion_is_a_rotation(shared_mocap, tmp_path):
    def edit(text):
        doc = json.loads(text)
        for frame in doc["Frames"]:
            frame[16:20] = [v * 1e155 for v in frame[16:20]]  # the right hip
        return json.dumps(doc)

    ref, m = (
        load_motion(shared_mocap / WALK),
        load_motion(edited(shared_mocap, WALK, tmp_path, edit)),
    )
    for key, v in ref.keypoints.items():
        np.testing.assert_allclose(m.keypoints[key], v, atol=1e-9, err_msg=key)


# --- implausible values; non-finite values in channels that move nothing


def test_nan_in_a_channel_that_moves_no_keypoint_is_dropped(shared_mocap, tmp_path):
    lines = (shared_mocap / BVH).read_text().splitlines()
    head = lines.index("MOTION")
    names = [c for c in load_motion(shared_mocap / BVH).channels]
    finger = names.index("LeftHandIndex1.Zrotation")
    tok = lines[head + 10].split()
    tok[finger] = "nan"
    lines[head + 10] = " ".join(tok)
    path = tmp_path / "finger.bvh"
    path.write_text("\n".join(lines))
    with pytest.warns(MocapWarning, match=r"dropped 1 channel\(s\) .*: LeftHandIndex1.Zrotation"):
        m = load_motion(path)
    assert "LeftHandIndex1.Zrotation" not in m.channels and np.isfinite(m.data).all()
    assert m.meta["dropped_channels"] == ("LeftHandIndex1.Zrotation",)
    tok[names.index("LeftUpLeg.Xrotation")] = "inf"
    lines[head + 10] = " ".join(tok)
    path.write_text("\n".join(lines))
    refused(path, rf"line {head + 11}: channel LeftUpLeg.Xrotation is inf, and it moves a keypoint")


def test_amc_nan_in_a_finger_is_dropped_in_a_femur_refused(shared_mocap, tmp_path):
    (tmp_path / "clip.asf").write_bytes((shared_mocap / ASF).read_bytes())
    text = (shared_mocap / AMC).read_text()
    (tmp_path / "clip.amc").write_text(re.sub(r"lfingers \S+", "lfingers nan", text, count=1))
    with pytest.warns(MocapWarning, match=r"lfingers.rx"):
        m = load_motion(tmp_path / "clip.amc")
    assert np.isfinite(m.data).all() and "lfingers.rx" not in m.channels
    (tmp_path / "clip.amc").write_text(re.sub(r"lfemur \S+", "lfemur inf", text, count=1))
    refused(tmp_path / "clip.amc", r"line \d+: lfemur.rx is inf, and it moves a keypoint")


def test_legs_outside_the_human_range(shared_mocap):
    lo, hi = LEG_RANGE_M
    with pytest.raises(MocapError, match=rf"outside the human {lo:g}-{hi:g} m; pass --units"):
        load_motion(shared_mocap / BVH, units="m")
    assert 0.7 < load_motion(shared_mocap / BVH).meta["leg_length_m"] < 1.0  # guessing cmu


# --- through the CLI: exit 2, one 'error:' line, no traceback, no output


@pytest.mark.parametrize("fmt", ["bvh", "amc", "c3d", "deepmimic"])
def test_cli_one_line_error(shared_mocap, tmp_path, capsys, fmt):
    if fmt == "bvh":
        bad = bvh_with(shared_mocap, tmp_path, "Frames: 450", "Frames: nan")
    elif fmt == "amc":
        bad = asf_with(shared_mocap, tmp_path, lambda t: t.replace("lfoot ltoes", "lfoot lfoot"))
    elif fmt == "c3d":
        bad = c3d_with(shared_mocap, tmp_path, lambda d: d.__delitem__(slice(len(d) // 2, None)))
    else:
        bad = tmp_path / "m.txt"
        bad.write_text('{"Frames": ' + "[" * 5000 + "]" * 5000 + "}")
    out = tmp_path / "o.npz"
    _fails_in_one_line(capsys, ["retarget", str(bad), "--out", str(out)], out, bad.stem)


def test_cli_warning_is_one_line(shared_mocap, tmp_path):
    """A dropped channel is one 'warning:' line on stderr (and the run goes on)."""
    (tmp_path / "clip.asf").write_bytes((shared_mocap / ASF).read_bytes())
    text = (shared_mocap / AMC).read_text()
    (tmp_path / "clip.amc").write_text(re.sub(r"lfingers \S+", "lfingers nan", text, count=1))
    out = tmp_path / "o.npz"
    cmd = [sys.executable, "-m", "imitwalk", "retarget", str(tmp_path / "clip.amc")]
    res = subprocess.run([*cmd, "--out", str(out)], capture_output=True, text=True, timeout=600)
    err = res.stderr.strip().splitlines()
    assert res.returncode == 2 and "Traceback" not in res.stderr and not out.exists()
    assert err[0].startswith("warning: ") and "lfingers.rx" in err[0]
    assert err[-1].startswith("error: ")  # the playground clip holds no walking cycle
