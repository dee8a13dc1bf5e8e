"""An honest stand check (issues 59 and 60): one rule for ``robot import``, ``robot stand``
and ``learn``, a stated tilt limit, and a message that names the joint-map keys to change.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from imitwalk.cli.main import main
from imitwalk.robots import BUILTIN, load_robot
from imitwalk.sim.standing import CHECK_SECONDS, TILT_LIMIT_DEG, stand_test
from tests.test_cli_hostile_files import refused


def _hoap2_with_legs(tmp_path: Path, kp: float, name: str = "weak.json") -> Path:
    """hoap2's own joint map, with leg servos of stiffness ``kp`` [Nm/rad] (hoap2's: 40)."""
    jm = json.loads(BUILTIN["hoap2"].read_text())
    jm["mjcf"] = str(BUILTIN["hoap2"].parent / jm["mjcf"])
    jm["servos"] = {"legs": {"kp": kp}}
    path = tmp_path / name
    path.write_text(json.dumps(jm))
    return path


def test_a_robot_tilting_past_the_limit_has_not_stood_though_it_has_not_fallen(tmp_path):
    """The defect: 28 deg of tilt after 2 s was reported as ``fell: false`` and accepted."""
    res = stand_test(load_robot(_hoap2_with_legs(tmp_path, 14.2)), seconds=CHECK_SECONDS)
    assert not res.fell and res.max_tilt_deg > TILT_LIMIT_DEG
    assert not res.stands
    line = res.refusal("x.json")
    assert "\n" not in line and f"(limit {TILT_LIMIT_DEG:g})" in line
    assert '"servos"' in line and '"kp"' in line and "now 14.2 Nm/rad" in line
    assert '"stand_keyframe"' in line and '"soles"' in line


def test_hoap2_stands_by_the_same_rule():
    res = stand_test(load_robot("hoap2"), seconds=CHECK_SECONDS)
    assert res.stands and res.max_tilt_deg < 5.0 and res.tipping_deg_per_s < 1.0
    assert res.height_lost_m < res.height_lost_limit_m


def test_robot_stand_refuses_in_one_line_with_what_to_change(tmp_path, capsys):
    weak = _hoap2_with_legs(tmp_path, 14.2)
    line = refused(capsys, ["robot", "stand", weak, "--seconds", "2"], str(weak), "cannot stand")
    assert "tilted" in line and '"servos"' in line and '{"legs": {"kp": ...}}' in line
    collapsed = _hoap2_with_legs(tmp_path, 0.01, "collapsed.json")
    line = refused(capsys, ["robot", "stand", collapsed], str(collapsed), "now 0.01 Nm/rad")
    assert "sank" in line


@pytest.mark.parametrize("variant", [None, "step", "extended", "faithful"])
def test_learn_refuses_a_robot_that_cannot_stand_at_once(tmp_path, capsys, variant):
    weak = _hoap2_with_legs(tmp_path, 0.01)
    run = tmp_path / "run"
    argv = ["learn", "--robot", weak, "--out", run] + (["--variant", variant] if variant else [])
    line = refused(capsys, argv, str(weak), "cannot stand", left=run)
    assert '"servos"' in line


def test_learn_refuses_a_robot_given_by_mjcf_and_joint_map(tmp_path, capsys):
    weak = _hoap2_with_legs(tmp_path, 0.01)
    xml = BUILTIN["hoap2"].parent / "hoap2.xml"
    run = tmp_path / "run"
    argv = ["learn", "--robot", xml, "--joint-map", weak, "--out", run]
    refused(capsys, argv, f"joint map {weak}", "cannot stand", left=run)


def test_import_writes_a_robot_that_cannot_stand_and_says_so(shared_robots, tmp_path, capsys):
    """The drafted map is written (it is what the user edits), reported ``stands: false``
    with a warning naming the keys; ``robot stand`` and ``learn`` then refuse it."""
    src = shared_robots / "robotis_op3"
    xml = (src / "op3.xml").read_text().replace('meshdir="assets"', f'meshdir="{src / "assets"}"')
    (tmp_path / "op3.xml").write_text(xml.replace('kp="21.1"', 'kp="0.05"'))
    out = tmp_path / "op3.json"
    assert main(["robot", "import", str(tmp_path / "op3.xml"), "--out", str(out), "--json"]) == 0
    captured = capsys.readouterr()
    summary = json.loads(captured.out)
    assert summary["stands"] is False and summary["stand"]["stands"] is False
    warnings = [x for x in captured.err.splitlines() if x.startswith("warning: ")]
    assert len(warnings) == 1 and str(out) in warnings[0] and '"servos"' in warnings[0]
    assert "does NOT stand" in captured.err and out.is_file()
    refused(capsys, ["robot", "stand", out], str(out), "cannot stand")
    refused(
        capsys,
        ["learn", "--robot", out, "--out", tmp_path / "run"],
        str(out),
        "cannot stand",
        left=tmp_path / "run",
    )
    jm = json.loads(out.read_text())
    jm["servos"] = {"legs": {"kp": 21.1}}  # what the message says to change
    fixed = tmp_path / "fixed.json"  # a new path: robots are cached per process by path
    fixed.write_text(json.dumps(jm))
    assert main(["robot", "stand", str(fixed), "--seconds", "2", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["stands"] is True
