"""File versions (issue 60): a reference's metadata and a run's ``config.json`` and
``metrics.json`` carry a ``format``; a file without one (written before versions) is read
as format 1, and a newer format is refused in one line naming the file and the formats
this imitwalk reads."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from imitwalk.readback import check_format
from imitwalk.retarget import Reference
from imitwalk.retarget.reffile import REFERENCE_FORMAT
from imitwalk.runs import RUN_FORMAT, RunDir
from tests.test_cli_hostile_files import _rewritten, refused


def _meta(path) -> dict:
    with np.load(path) as z:
        return json.loads(str(z["meta_json"]))


def test_a_reference_is_written_with_its_format_and_an_old_one_still_loads(
    tick_reference, tmp_path
):
    assert _meta(tick_reference)["format"] == REFERENCE_FORMAT == 1
    unversioned = lambda m: {k: v for k, v in m.items() if k != "format"}  # noqa: E731
    old = _rewritten(tick_reference, tmp_path / "old.npz", unversioned)
    assert "format" not in _meta(old)
    assert Reference.load(old).joint_names == Reference.load(tick_reference).joint_names


@pytest.mark.parametrize("version", [2, 99])
def test_a_newer_reference_is_refused_in_one_line(tick_reference, tmp_path, capsys, version):
    new = _rewritten(tick_reference, tmp_path / "new.npz", lambda m: {**m, "format": version})
    line = refused(capsys, ["playback", new, "--models", "1"], str(new), f"format {version}")
    assert "this one reads format 1" in line


@pytest.mark.parametrize("bad", ["1", 0, -1, 1.5, True, None])
def test_a_format_that_is_not_a_version_is_refused(bad):
    from imitwalk.errors import RunError

    with pytest.raises(RunError, match=r"^f\.json: format is .*; this imitwalk reads format 1$"):
        check_format({"format": bad}, 1, "f.json")
    assert check_format({}, 1, "f.json") == 1 and check_format({"format": 2}, 3, "f") == 2


def test_a_run_is_written_with_its_format_and_an_old_one_still_loads(tick_run, tmp_path):
    for name in ("config.json", "metrics.json"):
        assert json.loads((tick_run / name).read_text())["format"] == RUN_FORMAT == 1
    run = tmp_path / "run"
    shutil.copytree(tick_run, run)
    for name in ("config.json", "metrics.json"):
        doc = json.loads((run / name).read_text())
        del doc["format"]
        (run / name).write_text(json.dumps(doc))
    rd = RunDir(run)
    assert rd.read_summary() == RunDir(tick_run).read_summary()
    assert "format" not in rd.read_json("config.json")


@pytest.mark.parametrize("name", ["config.json", "metrics.json"])
def test_a_newer_run_is_refused_in_one_line(tick_run, tmp_path, capsys, name):
    run = tmp_path / "run"
    shutil.copytree(tick_run, run)
    doc = json.loads((run / name).read_text())
    (run / name).write_text(json.dumps({**doc, "format": RUN_FORMAT + 1}))
    where = str(run / name)
    argv = ["evaluate", run, "--seeds", "1", "--seconds", "1"]
    line = refused(capsys, argv, where, "written by a newer imitwalk", run / "protocol_eval.json")
    assert "this one reads format 1" in line
    refused(capsys, ["report", run], where, "format 2", run / "report.html")
