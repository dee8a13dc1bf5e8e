"""Bad joint maps and bad MJCF: each defect class of issue 34 is a one-line RobotError."""

from __future__ import annotations

import json

import numpy as np
import pytest

from imitwalk.cli.main import main
from imitwalk.errors import RobotError
from imitwalk.robots import BUILTIN, load_robot
from imitwalk.robots.jointmap import parse_joint_map

HOAP2 = BUILTIN["hoap2"].parent


def _files(tmp_path, edit_map=None, xml: bytes | None = None, text: bytes | None = None):
    jm = json.loads((HOAP2 / "hoap2.json").read_text())
    jm.pop("mjcf")
    if edit_map:
        edit_map(jm)
    (tmp_path / "bot.xml").write_bytes(
        xml if xml is not None else (HOAP2 / "hoap2.xml").read_bytes()
    )
    (tmp_path / "bot.json").write_bytes(text if text is not None else json.dumps(jm).encode())
    return tmp_path / "bot.xml", tmp_path / "bot.json"


def _refused(tmp_path, message, **kw):
    xml, jm = _files(tmp_path, **kw)
    with pytest.raises(RobotError) as err:
        load_robot(xml, jm)
    text = str(err.value)
    assert message in text and "\n" not in text, text
    return text


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda m: m.update(stand=5), "'stand' must be an object of role -> angle"),
        (lambda m: m.update(stand={"nosuch": 0.1}), "unknown joint role in 'stand' 'nosuch'"),
        (lambda m: m.update(stand={"l_knee": None}), "'stand.l_knee' must be a number, got null"),
        (lambda m: m["joints"].update(l_knee=5), "'joints.l_knee' must be an object"),
        (lambda m: m["joints"].update(l_knee={"joint": 5}), "'joints.l_knee.joint' must be a"),
        (lambda m: m["joints"].update(l_knee={"joint": "l_knee", "sign": True}), "1 or -1"),
        (lambda m: m.update(foot_force=["l_fsr_fl"]), "'foot_force' must be an object"),
        (lambda m: m.update(foot_force={"l": 5}), "'foot_force.l' must be a list of names"),
        (lambda m: m.update(foot_force={"x": []}), "unknown side in 'foot_force' 'x'"),
        (lambda m: m.update(soles="l_sole"), "'soles' must be an object"),
        (lambda m: m.update(soles={"l": "l_sole"}), "'soles' has no 'r' sole"),
        (lambda m: m.update(mjcf=5), "'mjcf' must be a non-empty string, got the number 5"),
        (lambda m: m.update(gyro=["torso_gyro"]), "'gyro' must be a non-empty string"),
        (lambda m: m.update(servos={"legs": {"kp": -1}}), "'servos.legs.kp' must be a finite"),
        (lambda m: m.update(servos={"arms": {}}), "unknown role or group in 'servos' 'arms'"),
        (lambda m: m["soles"].update(l={"body": "l_foot", "pos": [0, 0], "size": [1, 1]}), "3"),
    ],
)
def test_a_joint_map_of_the_wrong_shape_is_one_line(tmp_path, edit, message):
    _refused(tmp_path, message, edit_map=edit)


def test_nan_in_stand_is_refused_in_the_file_and_in_memory(tmp_path):
    text = (
        (HOAP2 / "hoap2.json")
        .read_text()
        .replace('"stand_keyframe"', '"stand": {"l_knee": NaN}, "x"')
    )
    text = text.replace('"x": "stand"', '"stand_keyframe": "stand"')
    _refused(tmp_path, "NaN is not a number JSON allows", text=text.encode())
    jm = json.loads((HOAP2 / "hoap2.json").read_text())
    jm["stand"] = {"l_knee": float("nan")}
    with pytest.raises(RobotError, match=r"'stand.l_knee' must be a finite number, got nan"):
        parse_joint_map(jm, "bot.json")


def test_a_joint_map_that_is_not_utf8_or_nests_deeply(tmp_path):
    raw = (HOAP2 / "hoap2.json").read_bytes()
    _refused(tmp_path, "is not UTF-8 text (byte", text=raw.replace(b"torso", b"tor\xffso", 1))
    deep = raw.replace(b'"torso":', b'"x": ' + b"[" * 5000 + b"]" * 5000 + b', "torso":', 1)
    _refused(tmp_path, "is not valid JSON", text=deep)


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (b'name="l_foot"', b'name="l_fo\xffot"', "is not UTF-8 text (byte"),
        (b'range="-0.4363 0.4363"', b'range="nan 1"', "range='nan 1' is not finite"),
        (b'mass="0.157"', b'mass="inf"', "mass='inf' is not finite"),
        (b'mass="0.157"', b'mass="1e400"', "mass='1e400' is not finite"),
    ],
)
def test_bad_mjcf_is_one_line(tmp_path, old, new, message):
    xml = (HOAP2 / "hoap2.xml").read_bytes()
    assert old in xml
    _refused(tmp_path, message, xml=xml.replace(old, new, 1))


def test_an_mjcf_without_a_floating_base_is_refused(tmp_path):
    xml = (HOAP2 / "hoap2.xml").read_text()
    xml = xml.replace('<freejoint name="root"/>', "")
    xml = xml[: xml.index("<keyframe>")] + xml[xml.index("</keyframe>") + 11 :]
    jm = lambda m: m.pop("stand_keyframe")  # noqa: E731
    _refused(tmp_path, "has no floating base", edit_map=jm, xml=xml.encode())


def test_robot_info_json_never_prints_nan(tmp_path, capsys):
    """A servo without a torque limit is ``null`` in ``robot info --json``, not Infinity."""
    xml = (HOAP2 / "hoap2.xml").read_bytes().replace(b' forcerange="-4 4"', b"")
    xml, jm = _files(tmp_path, xml=xml)
    assert np.isinf(load_robot(xml, jm).torque_limit).any()
    assert main(["robot", "info", str(xml), "--joint-map", str(jm), "--json"]) == 0
    out = capsys.readouterr().out
    assert "NaN" not in out and "Infinity" not in out
    info = json.loads(out)
    assert info["joints"]["l_knee"]["torque_limit_nm"] is None
