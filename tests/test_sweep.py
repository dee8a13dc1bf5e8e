"""Sweeps on Ray (``imitwalk sweep``): the cells learned and judged, the table and its
page, resuming an interrupted sweep without redoing finished cells, and bad sweep files."""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("ray")

#: Learning settings of a tiny cell: one generation of four candidates, one robot, 2 s.
TINY = '["generations=1", "population=4", "robots=1", "seconds=2", "final_robots=0"]'


def _sweep(folder: Path, clips: str, robots: str, seeds: str = "[0]") -> Path:
    path = folder / "sweep.toml"
    path.write_text(
        f"clips = {clips}\nrobots = {robots}\nsettings = [{TINY}]\nseeds = {seeds}\n"
        "judge_robots = 2\nseconds = 3.0\n"
    )
    return path


def _longshank(folder: Path) -> Path:
    """A second robot: hoap2 with 2 cm longer shanks, as an MJCF and its joint map."""
    from imitwalk.robots import BUILTIN

    home = BUILTIN["hoap2"].parent
    xml = (home / "hoap2.xml").read_text()
    for s in "lr":
        xml = xml.replace(
            f'<body name="{s}_ankle" pos="0 0 -0.1">', f'<body name="{s}_ankle" pos="0 0 -0.12">'
        )
    (folder / "longshank.xml").write_text(xml)
    jmap = json.loads((home / "hoap2.json").read_text())
    jmap.update(name="longshank", mjcf="longshank.xml")
    (folder / "longshank.json").write_text(json.dumps(jmap))
    return folder / "longshank.json"


def _cli(argv, capsys):
    from imitwalk.cli import main

    code = main(argv)
    out = capsys.readouterr()
    return code, out.out, out.err


def test_a_sweep_learns_judges_and_keeps_its_cells_on_a_rerun(tmp_path, capsys):
    cfg = _sweep(tmp_path, '["default"]', '["hoap2"]')
    out = tmp_path / "out"
    code, stdout, _ = _cli(
        ["sweep", str(cfg), "--out", str(out), "--workers", "1", "--json"], capsys
    )
    assert code == 0
    res = json.loads(stdout)
    assert (res["cells"], res["ran"], res["kept"], res["refused"]) == (1, 1, 0, 0)
    rows = list(csv.DictReader((out / "results.csv").open()))
    assert len(rows) == 1 and rows[0]["status"] == "ok" and rows[0]["judged_robots"] == "2"
    assert int(rows[0]["falls"]) + int(rows[0]["survived"]) == 2
    assert "1 of 1 cells done" in (out / "summary.md").read_text()
    code, stdout, _ = _cli(["sweep", str(cfg), "--out", str(out), "--json"], capsys)
    assert code == 0 and json.loads(stdout)["ran"] == 0 and json.loads(stdout)["kept"] == 1


@pytest.mark.slow
def test_an_interrupted_two_by_two_sweep_resumes_without_redoing_cells(shared_mocap, tmp_path):
    """2 clips × 2 robots on a local Ray of 2 workers, interrupted (Ctrl-C) once the
    first cell is done, then run again: the finished cells are kept as they were, the
    others run, and the table holds all four."""
    import pyarrow.parquet as pq

    clip = shared_mocap / "cmu_bvh" / "07_04.bvh"
    robot = _longshank(tmp_path)
    cfg = _sweep(tmp_path, f'["default", "{clip}"]', f'["hoap2", "{robot.name}"]')
    out = tmp_path / "out"
    argv = [sys.executable, "-m", "imitwalk", "sweep", str(cfg), "--out", str(out), "--json"]
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    while not list(out.glob("*/row.json")) and proc.poll() is None:
        time.sleep(0.2)
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=600)
    first = {p.parent.name: os.stat(p).st_mtime_ns for p in out.glob("*/row.json")}
    assert 1 <= len(first)
    done = subprocess.run(argv, capture_output=True, text=True, check=True, timeout=1200)
    res = json.loads(done.stdout)
    assert res["cells"] == 4 and res["kept"] == len(first) and res["ran"] == 4 - len(first)
    assert {
        p.parent.name: os.stat(p).st_mtime_ns
        for p in out.glob("*/row.json")
        if p.parent.name in first
    } == first
    rows = list(csv.DictReader((out / "results.csv").open()))
    assert len(rows) == 4 and all(r["status"] == "ok" for r in rows)
    assert {(Path(r["clip"]).name, Path(r["robot"]).name) for r in rows} == {
        ("default", "hoap2"),
        ("default", "longshank.json"),
        ("07_04.bvh", "hoap2"),
        ("07_04.bvh", "longshank.json"),
    }
    table = pq.read_table(out / "results.parquet").to_pylist()
    assert [r["cell"] for r in table] == [r["cell"] for r in rows]


@pytest.mark.parametrize(
    ("text", "word"),
    [
        ('clips = ["default"]\nrobotz = ["hoap2"]\n', "unknown sweep key 'robotz'; valid:"),
        ('clips = ["nowhere.bvh"]\n', "clip nowhere.bvh not found"),
        ('settings = [["generations=x"]]\n', "generations"),
        ('settings = ["generations=2"]\n', "list of lists"),
        ('robots = ["nobot"]\n', "unknown robot 'nobot'"),
        ('protocol = "nope"\n', "unknown protocol 'nope'"),
        ("seeds = [-1]\n", "seeds"),
        ("seconds = 0\n", "seconds"),
        ("clips = [\n", "not a sweep's JSON or TOML"),
    ],
)
def test_a_bad_sweep_file_is_refused_in_one_line_before_any_cell(tmp_path, capsys, text, word):
    cfg = tmp_path / "sweep.toml"
    cfg.write_text(text)
    code, _, err = _cli(["sweep", str(cfg), "--out", str(tmp_path / "out")], capsys)
    lines = err.strip().splitlines()
    assert code == 2 and lines[-1].startswith("error: ") and word in lines[-1], err
    assert not (tmp_path / "out").exists()


def test_a_folder_of_another_sweep_or_of_other_files_is_refused(tmp_path, capsys):
    cfg = _sweep(tmp_path, '["default"]', '["hoap2"]')
    out = tmp_path / "out"
    out.mkdir()
    (out / "sweep.json").write_text('{"clips": ["other"]}')
    code, _, err = _cli(["sweep", str(cfg), "--out", str(out)], capsys)
    assert code == 2 and "another sweep" in err
    (out / "sweep.json").unlink()
    (out / "notes.txt").write_text("mine")
    code, _, err = _cli(["sweep", str(cfg), "--out", str(out)], capsys)
    assert code == 2 and "not a sweep" in err
