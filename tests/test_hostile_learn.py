"""Hostile input to learning and judging (round 3, findings A1, A3, A4, A5, A10, A11):
``learn --resume`` continues exactly, ``learn --out`` never overwrites a user's files,
a resumed run keeps its robot and clip, a run's gains are read whole, and a verdict
names its robot. Each refusal is one line (the CLI: ``error: ...``, exit status 2),
made before any learning or walking.
"""

from __future__ import annotations

import json
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from imitwalk.cli.main import main
from imitwalk.errors import ConfigError, RunError

# -- A1: the optimiser resumes exactly ------------------------------------------------


def _cost(x: np.ndarray) -> float:
    """A cheap synthetic cost of a candidate ``x`` (the unit box of the gains' ranges)."""
    return float(np.sum((x - 0.3) ** 2) + 0.1 * np.sin(7.0 * x).sum())


def _generations(opt, cfg, rd, log: list[dict], gens: range) -> list[list[np.ndarray]]:
    """Generations ``gens`` of the learn module's optimiser on :func:`_cost`, checkpointed
    after each as ``learn`` does; each generation's candidates."""
    from imitwalk.step.learn import _ask, _save

    seen = []
    for gen in gens:
        xs = _ask(opt, cfg, gen)
        opt.tell([(x, _cost(x)) for x in xs])
        log.append({"generation": gen + 1})
        _save(rd, cfg, opt, log, float(gen), 0.0)
        seen.append([x.copy() for x in xs])
    return seen


def _same(a: list[list[np.ndarray]], b: list[list[np.ndarray]]) -> bool:
    """Equal candidates, generation by generation, to the bit."""
    return len(a) == len(b) and all(
        len(ga) == len(gb) and all(np.array_equal(x, y) for x, y in zip(ga, gb, strict=True))
        for ga, gb in zip(a, b, strict=True)
    )


def _plain_cma(cfg, start, generations: int) -> list[list[np.ndarray]]:
    """The candidates of ``generations`` of cmaes alone (never pickled) on :func:`_cost`."""
    from cmaes import CMA

    bounds = np.tile([0.0, 1.0], (len(cfg.names), 1))
    opt = CMA(
        mean=start.vector(cfg.names),
        sigma=cfg.sigma,
        bounds=bounds,
        population_size=cfg.population,
        seed=cfg.seed,
    )
    seen = []
    for gen in range(generations):
        opt.reseed_rng(cfg.seed * 100_003 + gen)
        xs = [opt.ask() for _ in range(opt.population_size)]
        opt.tell([(x, _cost(x)) for x in xs])
        seen.append(xs)
    return seen


def test_a_resumed_optimiser_draws_what_an_uninterrupted_one_draws(tmp_path):
    """Resumed from the checkpoint of generation 2 (when the covariance matrix is no
    longer exactly symmetric), generations 3 and 4 draw the uninterrupted run's
    candidates to the bit and the optimisers end in the same state; an uninterrupted run
    draws what cmaes alone draws (its checkpoints change nothing)."""
    from imitwalk.runs import RunDir
    from imitwalk.step.gains import StepGains
    from imitwalk.step.learn import StepLearnConfig, _optimiser

    cfg = StepLearnConfig(generations=4, population=6, final_robots=0)
    start, say = StepGains(), lambda _line: None
    whole = RunDir(tmp_path / "whole")
    opt, log, _, _ = _optimiser(whole, cfg, start, False, say)
    first = _generations(opt, cfg, whole, log, range(2))
    snapshot = whole.file("cma.pkl").read_bytes()
    assert not np.array_equal(opt._C, opt._C.T)  # the case that diverged
    rest = _generations(opt, cfg, whole, log, range(2, 4))
    assert _same(first + rest, _plain_cma(cfg, start, 4))

    resumed = RunDir(tmp_path / "resumed")
    resumed.path.mkdir()
    resumed.file("cma.pkl").write_bytes(snapshot)
    again, log2, spent, _ = _optimiser(resumed, cfg, start, True, say)
    assert len(log2) == 2 and spent == 1.0
    assert _same(_generations(again, cfg, resumed, log2, range(2, 4)), rest)
    assert vars(opt).keys() == vars(again).keys()
    for name, mine in vars(opt).items():
        theirs = vars(again)[name]
        if name == "_rng":  # not pickled: reseeded every generation
            continue
        if isinstance(mine, np.ndarray):
            assert mine.tobytes() == theirs.tobytes() and mine.shape == theirs.shape, name
        else:
            assert mine == theirs, name


def test_a_checkpoint_with_a_foreign_covariance_is_refused(tmp_path):
    import pickle

    from imitwalk.runs import RunDir
    from imitwalk.step.gains import StepGains
    from imitwalk.step.learn import StepLearnConfig, _optimiser

    cfg = StepLearnConfig(generations=2, population=4, final_robots=0)
    rd = RunDir(tmp_path / "run")
    opt, log, _, _ = _optimiser(rd, cfg, StepGains(), False, lambda _line: None)
    _generations(opt, cfg, rd, log, range(1))
    saved = pickle.loads(rd.file("cma.pkl").read_bytes())
    for exact in ({"_C": np.eye(3)}, {"_mean": opt._mean}, [1, 2]):
        rd.file("cma.pkl").write_bytes(pickle.dumps({**saved, "cma_exact": exact}))
        with pytest.raises(RunError, match="is not a stepping-gait checkpoint") as err:
            _optimiser(rd, cfg, StepGains(), True, lambda _line: None)
        assert "\n" not in str(err.value)


# -- a stepping run's files, written directly (no learning) ----------------------------


@pytest.fixture(scope="module")
def step_files(tmp_path_factory) -> Path:
    """A finished stepping run of the default clip on hoap2, as ``learn`` writes it (the
    shipped gains learned), its ``learn`` settings not any ``learn`` command's: a resume
    that passes the robot and clip checks stops at once on "other settings". Copy it
    (:func:`_copy`) to change it."""
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.retarget.provenance import Provenance
    from imitwalk.robots import load_robot
    from imitwalk.runs import LearnSummary, RunDir, StepOutcome
    from imitwalk.step.gains import shipped_gains
    from imitwalk.step.pipeline import gait_from_motion

    gait = gait_from_motion(
        load_motion(default_clip()), load_robot("hoap2"), Provenance(robot="hoap2")
    )
    rd = RunDir(tmp_path_factory.mktemp("hostile_learn") / "run")
    rd.path.mkdir()
    gains = shipped_gains(gait.style.backward).to_dict()
    config = {"learner": "step", "learn": {}, "robot": "hoap2", "source": gait.source}
    rd.write_json("config.json", config)
    gait.save(rd.file("style.json"))
    rd.write_json("gains.json", {"learned": gains, "default": gains})
    summary = LearnSummary("step", 1.0, [1.0], 1, 1.0, 1.0, {}, StepOutcome(gains, {}))
    rd.write_json("metrics.json", summary.to_dict())
    return rd.path


def _copy(run: Path, tmp_path: Path) -> Path:
    out = tmp_path / "run"
    shutil.copytree(run, out)
    return out


def _cli(argv: list, capsys) -> tuple[int, str]:
    """The exit status and the last line on stderr of ``imitwalk ARGV``."""
    code = main([str(a) for a in argv])
    err = capsys.readouterr().err.strip().splitlines()
    return code, err[-1] if err else ""


def _refused(argv: list, capsys, *words: str) -> str:
    """``imitwalk ARGV`` refused in one line (exit 2) holding ``words``; the line."""
    code, line = _cli(argv, capsys)
    assert code == 2 and line.startswith("error: "), (argv, line)
    assert all(w in line for w in words), (words, line)
    return line


@pytest.fixture(scope="module")
def hoap2_copy(tmp_path_factory) -> Path:
    """hoap2's joint map copied to another folder (its MJCF by absolute path): hoap2 by
    another file."""
    from imitwalk.robots import BUILTIN

    doc = json.loads(BUILTIN["hoap2"].read_text())
    doc["mjcf"] = str(BUILTIN["hoap2"].parent / doc["mjcf"])
    path = tmp_path_factory.mktemp("h2k") / "hoap2.json"
    path.write_text(json.dumps(doc))
    return path


@pytest.fixture(scope="module")
def op3(shared_robots, tmp_path_factory) -> Path:
    """OP3's joint map (imported from the shared MJCF)."""
    path = tmp_path_factory.mktemp("op3") / "op3.json"
    xml = shared_robots / "robotis_op3" / "op3.xml"
    assert main(["robot", "import", str(xml), "--out", str(path)]) == 0
    return path


# -- A3: learn --out never overwrites a user's files ------------------------------------


def test_learn_refuses_a_folder_of_user_files_and_leaves_them(tmp_path, capsys):
    mine = tmp_path / "mine"
    mine.mkdir()
    files = {"metrics.json": "my metrics", "gains.json": "my gains", "log.jsonl": "my log"}
    files["notes.txt"] = "keep"
    for name, text in files.items():
        (mine / name).write_text(text)
    for extra in ([], ["--resume"]):
        line = _refused(
            ["learn", "--out", mine, *extra],
            capsys,
            f"--out {mine} holds files that are not an imitwalk run (gains.json, log.jsonl, ",
            "give an empty or new folder, or --resume for an imitwalk run",
        )
        assert "and 1 more" in line
    assert {p.name: p.read_text() for p in mine.iterdir()} == files


def test_the_python_learn_refuses_a_folder_of_user_files_too(tmp_path):
    """``iw.learn`` (what the command runs) keeps a user's files as the command does."""
    import imitwalk as iw

    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "metrics.json").write_text("my metrics")
    with pytest.raises(RunError, match="not an imitwalk run"):
        iw.learn(None, "hoap2", mine)
    assert [p.name for p in mine.iterdir()] == ["metrics.json"]
    assert (mine / "metrics.json").read_text() == "my metrics"


def test_learn_refuses_an_empty_out_and_a_run_without_resume(step_files, tmp_path, capsys):
    _refused(["learn", "--out", ""], capsys, "--out '': give the name of a folder")
    _refused(["learn", "--out", step_files], capsys, "already holds a run; pass --resume")


def test_an_empty_or_new_folder_is_learned_into(tmp_path, capsys):
    """An empty folder passes the folder check: the next check (a setting) refuses."""
    from imitwalk.runs import RunDir

    empty = tmp_path / "empty"
    empty.mkdir()
    for out in (empty, tmp_path / "new"):
        RunDir(out).check_new(resume=False)
        line = _refused(["learn", "--out", out, "--set", "generations=0"], capsys, "generations")
        assert str(out) not in line
    assert not any(empty.iterdir()) and not (tmp_path / "new").exists()


def test_a_run_is_told_from_user_files(step_files, tmp_path):
    from imitwalk.runs import RunDir

    assert RunDir(step_files).holds_run()
    pass_only = tmp_path / "choice"  # an unfinished reference choice: its first pass
    (pass_only / "searched").mkdir(parents=True)
    (pass_only / "searched" / "checkpoint.json").write_text("{}")
    assert RunDir(pass_only).holds_run()
    user = tmp_path / "user"
    user.mkdir()
    (user / "config.json").write_text('{"name": "my-webapp"}')
    assert not RunDir(user).holds_run()
    with pytest.raises(RunError, match=r"holds files that are not an imitwalk run \(config"):
        RunDir(user).check_new(resume=True)


# -- A4: a resumed run keeps its robot and clip ------------------------------------------


def test_resume_refuses_another_robot(step_files, op3, hoap2_copy, tmp_path, capsys):
    run = _copy(step_files, tmp_path)
    before = {p.name: p.read_bytes() for p in run.iterdir()}
    _refused(
        ["learn", "--resume", "--out", run, "--robot", op3],
        capsys,
        f"--robot {op3}: {run} was started on hoap2, not {op3} ('op3')",
    )
    _refused(
        ["learn", "--resume", "--out", run, "--robot", hoap2_copy],
        capsys,
        f"was started on hoap2, not {hoap2_copy} ('hoap2')",
    )
    assert {p.name: p.read_bytes() for p in run.iterdir()} == before


def test_the_python_learn_resumes_only_on_the_runs_robot(step_files, op3, tmp_path):
    """``imitwalk.learn(..., resume=True)`` refuses another robot's name, as the command
    does (its settings the run's, so that check passes first)."""
    import imitwalk as iw
    from imitwalk.robots import load_robot
    from imitwalk.step.learn import StepLearnConfig

    run, cfg = _copy(step_files, tmp_path), StepLearnConfig()
    config = json.loads((run / "config.json").read_text())
    (run / "config.json").write_text(json.dumps({**config, "learn": cfg.to_dict()}))
    with pytest.raises(RunError, match="started on robot 'hoap2', not 'op3'"):
        iw.learn(None, load_robot(str(op3)), run, cfg, resume=True)


def test_resume_refuses_another_clip(step_files, tmp_path, capsys):
    run = _copy(step_files, tmp_path)
    source = json.loads((run / "config.json").read_text())["source"]
    for clip in ("/nonexistent/clip.bvh", tmp_path / "walk.bvh"):
        _refused(
            ["learn", clip, "--units", "mm", "--resume", "--out", run],
            capsys,
            f"{clip}: {run} was started on the clip {source}; resume it without a clip",
        )


def test_the_python_learn_resumes_only_with_the_runs_clip(step_files, tmp_path):
    """``imitwalk.learn(clip, ..., resume=True)`` refuses another clip, a path's or a
    motion's, as the command does; the run's own (or none) goes on to the next check."""
    import imitwalk as iw
    from imitwalk.mocap import default_clip, load_motion

    run = _copy(step_files, tmp_path)
    source = json.loads((run / "config.json").read_text())["source"]
    for clip in ("/nonexistent/clip.bvh", tmp_path / "walk.bvh"):
        with pytest.raises(ConfigError, match=f"was started on the clip {source}"):
            iw.learn(clip, "hoap2", run, resume=True)
    motion = load_motion(default_clip())
    for clip in (None, default_clip(), motion):
        with pytest.raises(RunError, match="was started with other settings"):
            iw.learn(clip, "hoap2", run, resume=True)


def test_resume_with_the_same_robot_and_clip_goes_on(step_files, tmp_path, capsys):
    """The same robot and clip (given again, or by a copy of the clip's bytes) pass: the
    resume goes on to the next check, the settings (the fixture's are no command's)."""
    from imitwalk.mocap import default_clip

    run = _copy(step_files, tmp_path)
    copy = tmp_path / "clip.txt"
    copy.write_bytes(Path(default_clip()).read_bytes())
    for extra in ([], ["--robot", "hoap2"], [default_clip()], [copy, "--units", "mm"]):
        code = main(["learn", *map(str, extra), "--resume", "--out", str(run)])
        assert code == 2
        err = capsys.readouterr().err
        assert "was started with other settings" in err.strip().splitlines()[-1], err
    assert "--units: not used" in err


def test_resume_records_name_the_robot_file(step_files, hoap2_copy, tmp_path, capsys):
    """A run started on a robot file resumes on that file only (not the built-in robot of
    its name)."""
    from imitwalk.retarget.provenance import Provenance
    from imitwalk.step.gait import StepGait

    run = _copy(step_files, tmp_path)
    gait = StepGait.load(run / "style.json")
    named = Provenance(robot=str(hoap2_copy.resolve()))
    replace(gait, provenance=named).save(run / "style.json")
    _refused(
        ["learn", "--resume", "--out", run],
        capsys,
        f"--robot hoap2: {run} was started on {hoap2_copy.resolve()}, not hoap2",
    )
    code = main(["learn", "--resume", "--out", str(run), "--robot", str(hoap2_copy)])
    assert code == 2 and "other settings" in capsys.readouterr().err


# -- A10: a run's gains are read whole ----------------------------------------------------


def test_gains_missing_from_a_run_are_refused_not_defaulted(step_files, tmp_path, capsys):
    from imitwalk.judge.replay import load_run
    from imitwalk.step.gains import BOUNDS

    run = _copy(step_files, tmp_path)
    gains = json.loads((run / "gains.json").read_text())
    (run / "gains.json").write_text(json.dumps({"learned": {}, "default": {}}))
    with pytest.raises(RunError) as err:
        load_run(run)
    msg = str(err.value)
    assert "\n" not in msg and f"'learned' lacks the gains {', '.join(BOUNDS)}" in msg
    partial = dict(gains["learned"])
    del partial["dcm"], partial["heading"]
    (run / "gains.json").write_text(json.dumps({**gains, "default": partial}))
    with pytest.raises(RunError, match=r"'default' lacks the gains dcm, heading \(a run"):
        load_run(run)
    _refused(["evaluate", run, "--seeds", "1", "--seconds", "1"], capsys, "lacks the gains")
    (run / "gains.json").write_text(json.dumps(gains))
    assert load_run(run).step_gains is not None


# -- A11: the judge's API refuses no robots ----------------------------------------------


@pytest.mark.parametrize("seeds", [0, -1, True, 2.0])
def test_evaluate_run_refuses_a_count_of_robots_under_one(step_files, seeds):
    import imitwalk as iw
    from imitwalk.judge.verdict import judge_controllers
    from imitwalk.robots import load_robot

    robot, protocol = load_robot("hoap2"), iw.load_protocol("eval")
    with pytest.raises(ConfigError, match=r"seeds .*: expected a whole number of robots >= 1"):
        iw.evaluate_run(step_files, robot, protocol, seeds=seeds, seconds=1.0)
    with pytest.raises(ConfigError, match=r"^seeds "):
        judge_controllers({}, robot, protocol, seeds=seeds)


# -- A5: a verdict names its robot; another robot is refused ------------------------------


def test_evaluate_and_report_refuse_another_robot(step_files, op3, tmp_path, capsys):
    run = _copy(step_files, tmp_path)
    for cmd in (["evaluate", run, "--seeds", "1"], ["report", run]):
        _refused(
            [*cmd, "--robot", op3],
            capsys,
            f"--robot {op3}: {run} learned on 'hoap2', not 'op3'; judge it on hoap2",
        )
    assert not (run / "protocol_eval.json").exists() and not (run / "report.html").exists()


def test_a_verdict_records_the_robot_it_was_judged_on(step_files, hoap2_copy, tmp_path, capsys):
    """The run's own robot by default; another joint map of hoap2 is allowed, and recorded."""
    from imitwalk.judge.records import ProtocolVerdict

    run = _copy(step_files, tmp_path)
    argv = ["evaluate", str(run), "--seeds", "1", "--seconds", "0.2", "--workers", "1"]
    for extra, robot in (([], "hoap2"), (["--robot", str(hoap2_copy)], str(hoap2_copy))):
        assert main([*argv, *extra, "--json"]) == 0
        printed = json.loads(capsys.readouterr().out)
        saved = json.loads((run / "protocol_eval.json").read_text())
        recorded = {"name": "hoap2", "robot": robot, "joint_map": None}
        assert saved["robot"] == printed["robot"] == recorded
        assert ProtocolVerdict.from_dict(saved).settings.seeds == 1  # still read back
