"""The built-in HOAP-2-class robot and the loading of user robots."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from imitwalk.cli.main import main
from imitwalk.errors import ImitwalkError, RobotError
from imitwalk.robots import BUILTIN, ROLES, load_robot

HOAP2 = BUILTIN["hoap2"].parent


def test_hoap2_has_25_named_hinges_and_sensors():
    r = load_robot("hoap2")
    assert r.dof == 25
    assert r.joint_names == ROLES
    assert r.gyro == "torso_gyro" and r.accelerometer == "torso_accel"
    assert all(len(v) == 4 for v in r.foot_force.values())
    assert r.limits.shape == (25, 2) and (r.limits[:, 0] < r.limits[:, 1]).all()
    assert np.all((r.stand >= r.limits[:, 0]) & (r.stand <= r.limits[:, 1]))


def test_hoap2_is_hoap2_sized():
    r = load_robot("hoap2")
    assert 6.5 < r.total_mass < 7.5
    assert 0.45 < r.height < 0.52
    legs = r.indices([n for n in r.joint_names if "hip" in n or "knee" in n or "ankle" in n])
    assert np.allclose(r.kp[legs], 40.0) and np.allclose(r.torque_limit[legs], 4.0)


def test_index_unknown_name_lists_valid():
    r = load_robot("hoap2")
    with pytest.raises(RobotError, match=r"unknown joint 'kneee'; valid: .*l_knee"):
        r.index("kneee")


def _user_robot(tmp_path: Path, edit_xml=None, edit_map=None) -> tuple[Path, Path]:
    xml = (HOAP2 / "hoap2.xml").read_text()
    jmap = json.loads((HOAP2 / "hoap2.json").read_text())
    jmap.pop("mjcf")
    if edit_xml:
        xml = edit_xml(xml)
    if edit_map:
        edit_map(jmap)
    (tmp_path / "bot.xml").write_text(xml)
    (tmp_path / "bot.json").write_text(json.dumps(jmap))
    return tmp_path / "bot.xml", tmp_path / "bot.json"


def test_user_mjcf_with_joint_map_loads(tmp_path):
    xml, jm = _user_robot(tmp_path)
    r = load_robot(xml, jm)
    assert r.dof == 25 and r.mjcf == xml


def test_user_robot_may_omit_arms(tmp_path):
    def drop(m):
        for k in [k for k in m["joints"] if "shoulder" in k or "elbow" in k]:
            del m["joints"][k]

    xml, jm = _user_robot(tmp_path, edit_map=drop)
    assert load_robot(xml, jm).dof == 19


@pytest.mark.parametrize(
    ("edit_xml", "edit_map", "message"),
    [
        (
            lambda s: s.replace('<gyro name="torso_gyro" site="imu"/>', ""),
            None,
            "has no gyro sensor",
        ),
        (
            None,
            lambda m: m["joints"].update(l_knee="left_knee"),
            "unknown joint 'left_knee'; valid:",
        ),
        (None, lambda m: m["joints"].update(l_tail="x"), "unknown joint role 'l_tail'; valid:"),
        (None, lambda m: m.update(gyro="imu"), "unknown gyro sensor 'imu'; valid: torso_gyro"),
        (lambda s: s.replace("</worldbody>", "<worldbody>"), None, "is not valid MJCF"),
        (None, lambda m: m["joints"].pop("r_knee"), "lacks leg roles: r_knee"),
    ],
)
def test_broken_robot_files_are_refused_in_one_line(tmp_path, edit_xml, edit_map, message):
    xml, jm = _user_robot(tmp_path, edit_xml, edit_map)
    with pytest.raises(ImitwalkError) as err:
        load_robot(xml, jm)
    assert message in str(err.value)
    assert "\n" not in str(err.value)


def test_cli_refuses_robot_without_gyro_without_traceback(tmp_path, capsys):
    xml, jm = _user_robot(tmp_path, lambda s: s.replace('<gyro name="torso_gyro" site="imu"/>', ""))
    assert main(["robot", "info", str(xml), "--joint-map", str(jm)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1 and "gyro" in err


def test_cli_robot_info_json(capsys):
    assert main(["robot", "info", "hoap2", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["dof"] == 25 and len(info["joints"]) == 25
    assert info["sensors"]["gyro"] == "torso_gyro"
    assert info["control_hz"] == 100.0 and info["physics_hz"] == 1000.0
    assert 6.5 < info["total_mass_kg"] < 7.5


def test_model_files_ship_with_the_package():
    assert shutil.which("imitwalk") is not None
    assert (HOAP2 / "README.md").is_file()
