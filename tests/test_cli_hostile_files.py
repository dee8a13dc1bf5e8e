"""Hostile input, round two (issue 60), through the command line: every file imitwalk
reads back (references, run folders), every path it writes, the robots it loads, C3D
and AMC oddities, and messages that name the flags. Each refusal exits with status 2
and one ``error:`` line naming the file, leaves no output behind, and runs no physics.
"""

from __future__ import annotations

import json
import pickle
import shutil
from pathlib import Path

import numpy as np
import pytest

from imitwalk import __version__
from imitwalk.cli.main import main
from tests.helpers.fuzz_files import SUMMARY

HOAP2 = Path(__file__).resolve().parents[1] / "src" / "imitwalk" / "robots" / "hoap2"
C3D, AMC, ASF = "c3d/treadmill_events.c3d", "cmu_asf_amc/test.amc", "cmu_asf_amc/test.asf"


def refused(capsys, argv: list[str], name: str, match: str = "", left: Path | None = None):
    """``argv`` exits with 2 and exactly one ``error:`` line that names ``name`` and holds
    ``match``; ``left`` (an output path) does not exist afterwards. The error line."""
    assert main([str(a) for a in argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    errors = [line for line in err if line.startswith("error: ")]
    assert len(errors) == 1 and err[-1] == errors[0], err
    assert "Traceback" not in "\n".join(err)
    assert name in errors[0] and match in errors[0], errors[0]
    if left is not None:
        assert not left.exists(), f"{left} left behind"
    return errors[0]


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> Path:
    """A real reference, retargeted without its search (one scale)."""
    out = tmp_path_factory.mktemp("ref") / "ref.npz"
    assert main(["retarget", "--out", str(out), "--no-search", "--set", "scales=[0.5]"]) == 0
    return out


def _rewritten(reference: Path, path: Path, meta=None, drop=(), **arrays) -> Path:
    """``reference`` written again to ``path``: ``meta`` (a function of its metadata) for
    its metadata, without the arrays in ``drop``, with ``arrays`` replaced."""
    with np.load(reference) as z:
        a = {k: z[k] for k in z.files if k not in drop}
    if meta is not None:
        a["meta_json"] = np.array(json.dumps(meta(json.loads(str(a["meta_json"])))))
    a.update(arrays)
    np.savez(path, **a)
    return path


def _without(key):
    return lambda m: {k: v for k, v in m.items() if k != key}


# --- references: playback and learn --reference


@pytest.mark.parametrize(
    ("case", "match"),
    [
        ("empty", "is empty"),
        ("truncated", "truncated or corrupt"),
        ("text", "is not an .npz archive (it begins 'hello world')"),
        ("a pickle", "is not an .npz archive (a Python pickle)"),
        ("folder", "is a folder"),
        ("missing", "not found"),
        ("no joint_names", "metadata lacks joint_names"),
        ("metadata a list", "metadata: expected an object"),
        ("joint_names a number", "joint_names is an integer, expected a list"),
        ("no dt", "metadata lacks dt"),
        ("settings a list", "settings is a list, expected an object"),
        ("no loops", "lacks loops, starts"),
        ("no metadata", "lacks meta_json"),
        ("metadata not JSON", "its metadata is not valid JSON"),
        ("wrong shapes", "do not fit"),
        ("pickled", "holds pickled objects"),
    ],
)
def test_playback_refuses_a_broken_reference(reference, tmp_path, capsys, case, match):
    path = tmp_path / "bad.npz"
    data = reference.read_bytes()
    if case == "empty":
        path.write_bytes(b"")
    elif case == "truncated":
        path.write_bytes(data[: len(data) // 2])
    elif case == "text":
        path.write_text("hello world")
    elif case == "a pickle":  # a GMR .pkl renamed: said, its bytes not echoed
        path.write_bytes(pickle.dumps({"fps": 100.0}))
    elif case == "folder":
        path.mkdir()
    elif case == "no joint_names":
        _rewritten(reference, path, _without("joint_names"))
    elif case == "metadata a list":
        _rewritten(reference, path, lambda m: [1, 2])
    elif case == "joint_names a number":
        _rewritten(reference, path, lambda m: {**m, "joint_names": 5})
    elif case == "no dt":
        _rewritten(reference, path, _without("dt"))
    elif case == "settings a list":
        _rewritten(reference, path, lambda m: {**m, "settings": []})
    elif case == "no loops":
        _rewritten(reference, path, drop=("loops", "starts"))
    elif case == "no metadata":
        _rewritten(reference, path, drop=("meta_json",))
    elif case == "metadata not JSON":
        _rewritten(reference, path, meta_json=np.array("{not json"))
    elif case == "wrong shapes":
        _rewritten(reference, path, loops=np.zeros((1, 10, 3)))
    elif case == "pickled":
        np.savez(path, meta_json=np.array([{"a": 1}], dtype=object))
    refused(capsys, ["playback", path, "--seconds", "1", "--models", "1"], "bad.npz", match)


def test_a_mocap_file_passed_as_a_reference(shared_mocap, tmp_path, capsys):
    bvh = tmp_path / "walk.bvh"
    shutil.copy(shared_mocap / "cmu_bvh" / "07_04.bvh", bvh)
    refused(capsys, ["playback", bvh], "walk.bvh", "is a mocap file, not a reference")
    out = tmp_path / "run"
    argv = ["learn", "--reference", bvh, "--out", out]
    refused(capsys, argv, "walk.bvh", "imitwalk retarget", left=out)


def test_learn_refuses_a_broken_reference_before_making_its_folder(tmp_path, capsys):
    bad, out = tmp_path / "ref.npz", tmp_path / "run"
    bad.write_bytes(b"PK\x03\x04 truncated")
    refused(capsys, ["learn", "--reference", bad, "--out", out], "ref.npz", left=out)


# --- run folders: evaluate, report, learn --resume


def _run(tmp_path: Path, **files) -> Path:
    run = tmp_path / "run"
    run.mkdir()
    files = {"config.json": {"learner": "step", "learn": {}}, "metrics.json": SUMMARY, **files}
    for name, content in files.items():
        path = run / name
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content if isinstance(content, str) else json.dumps(content))
    return run


@pytest.mark.parametrize(
    ("metrics", "match"),
    [
        ("", "is empty"),
        ("{", "is not valid JSON"),
        ("[3]", "holds a list, not an object"),
        (b"\xff\xfe{}", "is not text (not UTF-8)"),
        ({"learner": "step"}, "lacks scale_reached, scales_passed"),
        ({**SUMMARY, "scale_reached": "x"}, "scale_reached is a string, expected a number"),
        ({**SUMMARY, "config": []}, "config is a list, expected an object"),
    ],
)
def test_report_refuses_a_broken_metrics_json(tmp_path, capsys, metrics, match):
    run = _run(tmp_path, **{"metrics.json": metrics})
    refused(capsys, ["report", run], "metrics.json", match, left=run / "report.html")


@pytest.mark.parametrize(
    ("config", "match"), [("[1]", "holds a list"), ("", "is empty"), ("{x", "not valid JSON")]
)
def test_evaluate_refuses_a_broken_config_json(tmp_path, capsys, config, match):
    run = _run(tmp_path, **{"config.json": config})
    refused(capsys, ["evaluate", run], "config.json", match)
    assert not list(run.glob("protocol_*.json"))


def test_evaluate_refuses_a_broken_reference_in_its_run(tmp_path, capsys):
    run = _run(tmp_path, **{"reference.npz": b""})
    refused(capsys, ["evaluate", run], "reference.npz", "is empty")


def test_learn_resume_refuses_a_broken_reference_in_its_run(tmp_path, capsys):
    run = _run(tmp_path, **{"config.json": {"learner": "tick"}, "reference.npz": b"x" * 10})
    argv = ["learn", "--resume", "--out", run]
    refused(capsys, argv, "reference.npz", "not an .npz archive", left=run / "checkpoint.json")


def test_a_broken_learning_log_is_one_line(tmp_path):
    from imitwalk.errors import RunError
    from imitwalk.runs import RunDir

    run = _run(tmp_path, **{"log.jsonl": '{"a": 1}\n[2]\n'})
    with pytest.raises(RunError, match=r"log\.jsonl is not a learning log"):
        RunDir(run).read_log()
    (run / "log.jsonl").write_text('{"a": 1}\n{"b"\n')
    with pytest.raises(RunError, match=r"log\.jsonl is not a learning log"):
        RunDir(run).read_log()


# --- output paths: checked before any work


@pytest.mark.parametrize("where", ["folder", "no parent", "parent a file", "read-only"])
def test_retarget_refuses_an_output_it_cannot_write(tmp_path, capsys, where):
    (tmp_path / "afile").write_text("x")
    out = {
        "folder": tmp_path,
        "no parent": tmp_path / "nope" / "ref.npz",
        "parent a file": tmp_path / "afile" / "ref.npz",
        "read-only": Path("/proc/ref.npz"),
    }[where]
    match = {
        "folder": "is a folder",
        "no parent": "does not exist",
        "parent a file": "is a file, not a folder",
        "read-only": "cannot write in /proc",
    }[where]
    line = refused(capsys, ["retarget", "--out", out], str(out), match)
    assert line.startswith(f"error: --out {out}")
    assert not (tmp_path / "nope").exists() and list(tmp_path.iterdir()) == [tmp_path / "afile"]


@pytest.mark.parametrize(
    "argv",
    [
        ["learn", "--out", "{tmp}/nope/run"],
        ["learn", "--variant", "extended", "--out", "{tmp}/nope/run"],
        ["demo", "--out", "{tmp}/nope/run"],
        ["robot", "import", str(HOAP2 / "hoap2.xml"), "--out", "{tmp}/nope/map.json"],
    ],
)
def test_commands_that_write_refuse_a_missing_parent(tmp_path, capsys, argv):
    argv = [a.format(tmp=tmp_path) for a in argv]
    refused(capsys, argv, str(tmp_path / "nope"), "does not exist; create it first")
    assert not (tmp_path / "nope").exists()


def test_robot_import_refuses_a_folder_as_its_joint_map(tmp_path, capsys):
    argv = ["robot", "import", HOAP2 / "hoap2.xml", "--out", tmp_path]
    refused(capsys, argv, str(tmp_path), "is a folder")
    assert list(tmp_path.iterdir()) == []


def test_learn_refuses_a_file_as_its_run_folder(tmp_path, capsys):
    out = tmp_path / "run"
    out.write_text("not a folder")
    refused(capsys, ["learn", "--out", out], str(out), "is a file, not a run folder")
    assert out.read_text() == "not a folder"


# --- messages that name the flags; --version


def test_version(capsys):
    with pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0
    assert capsys.readouterr().out.strip() == f"imitwalk {__version__}"


def test_out_of_range_command_names_its_flag(tmp_path, capsys):
    out = tmp_path / "ref.npz"
    line = refused(capsys, ["retarget", "--turn", "45", "--out", out], "--turn", left=out)
    assert "expected -30 <= --turn <= 30" in line and "turn_deg=" not in line


def test_amc_without_its_asf_names_the_skeleton_flag(shared_mocap, tmp_path, capsys):
    amc, out = tmp_path / "walk.amc", tmp_path / "ref.npz"
    shutil.copy(shared_mocap / AMC, amc)
    for name in ("a.asf", "b.asf"):
        shutil.copy(shared_mocap / ASF, tmp_path / name)
    line = refused(capsys, ["retarget", amc, "--out", out], "walk.amc", "--skeleton", left=out)
    assert "skeleton=" not in line.split("(")[0]


def test_a_folder_named_like_a_mocap_file(tmp_path, capsys):
    folder, out = tmp_path / "x.bvh", tmp_path / "ref.npz"
    folder.mkdir()
    refused(capsys, ["retarget", folder, "--out", out], "x.bvh", "is a folder", left=out)


def test_skeleton_given_for_a_file_that_is_not_amc(shared_mocap, tmp_path, capsys):
    out = tmp_path / "ref.npz"
    argv = ["retarget", shared_mocap / "cmu_bvh" / "07_04.bvh", "--skeleton", "x.asf"]
    refused(capsys, [*argv, "--out", out], "07_04.bvh", "--skeleton applies to AMC", left=out)


def test_an_upper_case_xml_suffix_loads(tmp_path, capsys):
    shutil.copy(HOAP2 / "hoap2.xml", tmp_path / "HOAP2.XML")
    argv = ["robot", "info", tmp_path / "HOAP2.XML", "--joint-map", HOAP2 / "hoap2.json"]
    assert main([str(a) for a in [*argv, "--json"]]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["total_mass_kg"] == pytest.approx(7.158)
    out = tmp_path / "map.json"
    assert main(["robot", "import", str(tmp_path / "HOAP2.XML"), "--out", str(out)]) == 0
    assert json.loads(out.read_text())["mjcf"].endswith("HOAP2.XML")


# --- robots held to physical plausibility bounds


@pytest.mark.parametrize(
    ("old", "new", "match"),
    [
        ('mass="1.70"', 'mass="1e308"', "total mass 1e+308 kg is outside 0.1-500 kg"),
        ('mass="1.70"', 'mass="300"', "body 'torso' has a mass of 300.7 kg; expected at most"),
        ('timestep="0.001"', 'timestep="5"', "timestep 5 s is outside 1e-06-0.1 s"),
        ('range="-0.01745 2.2689"', 'range="-0.01745 20"', "joint 'l_knee' has the range"),
        ('kp="40"', 'kp="1e7"', "has a stiffness of 1e+07 Nm/rad; expected above 0"),
        (
            '<body name="head" pos="0.008 0 0.081">',
            '<body name="head" pos="0.008 0 5">',
            "standing height 5.404 m is outside 0.1-3 m",
        ),
    ],
)
def test_an_implausible_robot_is_refused(tmp_path, capsys, old, new, match):
    text = (HOAP2 / "hoap2.xml").read_text()
    assert old in text
    bot = tmp_path / "bot.xml"
    bot.write_text(text.replace(old, new, 1))
    argv = ["robot", "info", bot, "--joint-map", HOAP2 / "hoap2.json"]
    refused(capsys, argv, "bot.xml", match)


def test_a_joint_map_error_names_the_joint_map(tmp_path, capsys):
    jmap = json.loads((HOAP2 / "hoap2.json").read_text())
    jmap["joints"]["l_knee"] = "no_such_joint"
    path = tmp_path / "bot.json"
    path.write_text(json.dumps({**jmap, "mjcf": str(HOAP2 / "hoap2.xml")}))
    refused(capsys, ["robot", "info", path], "joint map", "bot.json: unknown joint 'no_such_joint'")


# --- C3D and AMC


@pytest.mark.parametrize(
    ("cut", "match"),
    [
        (lambda d: d[:100], "truncated header: the file is 100 bytes, a C3D header is 512"),
        (lambda d: b"\0" * 600, "not a C3D file: byte 2 of its header is 0"),
        (lambda d: d[:1500], "truncated parameter section: its 60 blocks end at byte 31232"),
        (lambda d: d[:515] + b"\x63" + d[516:], "corrupt parameter section: processor type 99"),
        (lambda d: d[: len(d) // 2], "the data section ends after"),
    ],
)
def test_c3d_errors_say_what_is_wrong_with_the_file(shared_mocap, tmp_path, capsys, cut, match):
    path, out = tmp_path / "trial.c3d", tmp_path / "ref.npz"
    path.write_bytes(cut((shared_mocap / C3D).read_bytes()))
    line = refused(capsys, ["retarget", path, "--out", out], "trial.c3d", match, left=out)
    assert "unpack" not in line and "buffer" not in line


def _amc_lines(shared: Path) -> list[str]:
    return (shared / AMC).read_text().splitlines()


def test_amc_with_an_unknown_header(shared_mocap, tmp_path, capsys):
    lines = _amc_lines(shared_mocap)
    amc, out = tmp_path / "walk.amc", tmp_path / "ref.npz"
    amc.write_text("\n".join([*lines[:2], ":FOO", *lines[2:]]) + "\n")
    argv = ["retarget", amc, "--skeleton", shared_mocap / ASF, "--out", out]
    refused(capsys, argv, "walk.amc", "line 3: unknown AMC header ':FOO'; valid: ", left=out)


def test_amc_with_a_frame_block_repeated(shared_mocap, tmp_path, capsys):
    lines = _amc_lines(shared_mocap)
    starts = [i for i, line in enumerate(lines) if line.strip().isdigit()]
    block = lines[starts[2] : starts[3]]  # frame 3
    amc, out = tmp_path / "walk.amc", tmp_path / "ref.npz"
    amc.write_text("\n".join([*lines[: starts[3]], *block, *lines[starts[3] :]]) + "\n")
    argv = ["retarget", amc, "--skeleton", shared_mocap / ASF, "--out", out]
    refused(capsys, argv, "walk.amc", "frame 3 comes after frame 3", left=out)
