"""The reference choice of ``imitwalk learn CLIP`` (:mod:`imitwalk.learning.refchoice`):
the rule that keeps a pass, the walker the second search plays its candidates with, and
the run folder the whole choice writes and resumes."""

from __future__ import annotations

import json
import shutil
from dataclasses import replace
from types import SimpleNamespace

import pytest
from hypothesis import given
from hypothesis import strategies as st

from imitwalk.balance.tickconfig import TickLearnConfig
from imitwalk.cli.main import main
from imitwalk.config import apply_overrides
from imitwalk.errors import ConfigError
from imitwalk.learning.refchoice import (
    PASSES,
    Choice,
    PassVerdict,
    law_walker,
    learn_clip,
    pick,
    same_gait,
)
from imitwalk.retarget import Reference
from imitwalk.retarget.search import SearchConfig, search_params
from imitwalk.retarget.template import extract_template
from imitwalk.runs import RunDir
from tests.conftest import sets


def _verdict(name: str, scale=1.0, falls=0, progress=0.9) -> PassVerdict:
    return PassVerdict(name, scale, falls, 40, progress, 5.0, 1200.0, 1300.0, 20.0, 640.0)


verdicts = st.tuples(
    st.sampled_from([0.8, 0.9, 1.0]),
    st.integers(0, 40),
    st.floats(0.0, 1.2, allow_nan=False),
)


@given(verdicts, verdicts)
def test_pick_keeps_the_larger_scale_then_fewer_falls_then_faster(a, b):
    first, second = _verdict(PASSES[0], *a), _verdict(PASSES[1], *b)
    kept = pick([first, second])
    if a == b:
        assert kept == PASSES[0]  # a tie keeps the open-loop search's reference
    elif a[0] != b[0]:
        assert kept == (PASSES[0] if a[0] > b[0] else PASSES[1])
    elif a[1] != b[1]:
        assert kept == (PASSES[0] if a[1] < b[1] else PASSES[1])
    else:
        assert kept == (PASSES[0] if a[2] >= b[2] else PASSES[1])


def test_where_every_robot_fell_the_longer_walk_is_kept():
    first = replace(_verdict(PASSES[0], falls=40, progress=0.5), walked_s=80.0)
    second = replace(_verdict(PASSES[1], falls=40, progress=-3.0), walked_s=90.0)
    assert pick([first, second]) == PASSES[1]


def test_the_choice_round_trips_and_counts_its_own_cost():
    c = Choice(PASSES[1], (_verdict(PASSES[0]), _verdict(PASSES[1])))
    assert Choice.from_dict(json.loads(json.dumps(c.to_dict()))) == c
    # the kept pass's learning, and the rest: the other learning, both judgements, one search
    assert c.cost() == {"learning_sim_seconds": 1300.0, "choice_sim_seconds": 1300 + 2400 + 640}


def test_a_pass_sharing_its_twins_gait_costs_only_its_search():
    first = _verdict(PASSES[0])
    twin = replace(
        first, name=PASSES[1], learn_sim_seconds=0.0, learn_wall_seconds=0.0, same_as=PASSES[0]
    )
    c = Choice(pick([first, twin]), (first, twin))
    assert c.kept == PASSES[0] and Choice.from_dict(json.loads(json.dumps(c.to_dict()))) == c
    assert c.cost() == {"learning_sim_seconds": 1300.0, "choice_sim_seconds": 1200 + 640}


def test_same_gait_looks_at_the_gait_not_the_search_report(tick_reference):
    ref = Reference.load(tick_reference)
    assert same_gait(ref, replace(ref, search={"method": "another search"}))
    loops = ref.loops.copy()
    loops[-1, 0, 0] += 1e-6
    assert not same_gait(ref, replace(ref, loops=loops))
    assert not same_gait(ref, replace(ref, params=replace(ref.params, sway=-1.0)))


def test_a_second_search_that_keeps_the_first_gait_is_not_learned_again(
    robot, tick_reference, tmp_path
):
    ref = Reference.load(tick_reference)
    cfg = apply_overrides(TickLearnConfig(), QUICK_LEARN)
    out = tmp_path / "run"
    summary, choice = learn_clip(lambda walker: ref, robot, cfg, out)
    assert summary.scale_reached == choice.passes[0].scale
    assert choice.kept == PASSES[0] and choice.passes[1].same_as == PASSES[0]
    assert choice.passes[1].learn_sim_seconds == 0.0
    assert sorted(p.name for p in (out / PASSES[1]).iterdir()) == ["reference.npz"]
    assert (out / "metrics.json").read_bytes() == (out / PASSES[0] / "metrics.json").read_bytes()
    again = learn_clip(lambda walker: ref, robot, cfg, out, resume=True)
    assert again[1] == choice


@pytest.mark.parametrize(
    "setting", ["choice.robots=-1", "choice.first=5", "choice.first=299990", "choice.seconds=0"]
)
def test_choice_settings_out_of_range_are_one_line_errors(setting):
    with pytest.raises(ConfigError, match="choice"):
        apply_overrides(TickLearnConfig(), [setting])


def test_no_choice_to_make_is_refused(robot, tmp_path):
    cfg = apply_overrides(TickLearnConfig(), ["choice.robots=0"])
    with pytest.raises(ConfigError, match=r"choice\.robots is 0"):
        learn_clip(lambda walker: None, robot, cfg, tmp_path / "run")


def _stub_walker(ref, robot, scale, seed, options, seconds):
    """A walker that checks it is given the candidate, and walks half the time forward."""
    assert isinstance(ref, Reference) and not ref.search  # a candidate, not yet reported
    return SimpleNamespace(fell=True, seconds=seconds / 2, progress_ratio=0.4, yaw_drift_deg=9.0)


def test_the_search_scores_the_walkers_walks(robot):
    from imitwalk.mocap import default_clip, load_motion

    template = extract_template(load_motion(default_clip()), allow_turn=False)
    cfg = SearchConfig(
        generations=1, population=1, elites=1, scales=(0.5,), models=2, seconds=2.0, workers=1
    )
    _, rep = search_params(template, robot, cfg, walker=_stub_walker)
    assert rep.best_score == pytest.approx(0.5 + 0.5 * 0.4 - 0.5 * 9 / 45)
    assert [r["fell"] for r in rep.best["runs"]] == [True, True]
    assert "learned law" in rep.method


QUICK_SEARCH = [
    "retarget.search_config.generations=1",
    "retarget.search_config.elites=1",
    "retarget.search_config.population=2",
    "retarget.search_config.models=1",
    "retarget.search_config.seconds=4",
    "retarget.scales=0.9,1.0",
]
QUICK_LEARN = [
    "start=0.9",
    "step=0.1",
    "iterations=1",
    "robots=2",
    "seconds=4",
    "trials.robots=2",
    "trials.seconds=4",
    "trials.heading_robots=1",
    "trials.heading_seconds=4",
    "choice.robots=2",
    "choice.seconds=5",
    "workers=1",
]


def test_learn_a_clip_learns_both_references_and_keeps_the_better(tmp_path, capsys):
    out = tmp_path / "run"
    argv = [
        "learn",
        "--variant",
        "extended",
        "--out",
        str(out),
        "--json",
        *sets([*QUICK_SEARCH, *QUICK_LEARN]),
    ]
    assert main(argv) == 0
    printed = json.loads(capsys.readouterr().out)
    choice = RunDir(out).read_json("choice.json")
    kept = choice["kept"]
    assert printed["reference_choice"]["kept"] == kept and kept in PASSES
    assert [p["name"] for p in choice["passes"]] == list(PASSES)
    assert all(p["robots"] == 2 for p in choice["passes"])
    for name in ("metrics.json", "checkpoint.json", "reference.npz", "learned.npz"):
        if (out / kept / name).exists():
            assert (out / name).read_bytes() == (out / kept / name).read_bytes(), name
            assert (out / name).samefile(out / kept / name), name  # linked, not stored twice
    assert "learned law" in Reference.load(out / "closed" / "reference.npz").search.method
    config = json.loads((out / "config.json").read_text())
    assert config["learn"]["choice"] == {"robots": 2, "seconds": 5.0, "first": 1001}
    walker = law_walker(out / PASSES[0])
    assert walker.engine == "mujoco" and walker.law.channels
    # a finished choice resumes to the same summary; a fresh start there is refused
    assert main([*argv, "--resume"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert again["reference_choice"] == printed["reference_choice"]
    assert main(argv) == 2
    assert "already holds a run" in capsys.readouterr().err


def _no_wall(choice: dict) -> dict:
    walls = ("learn_wall_seconds", "wall_seconds_for_learning")
    return {
        **choice,
        "passes": [{k: v for k, v in p.items() if k not in walls} for p in choice["passes"]],
    }


def test_an_interrupted_choice_resumes_to_the_same_choice(tmp_path, capsys):
    out = tmp_path / "run"
    argv = [
        "learn",
        "--variant",
        "extended",
        "--out",
        str(out),
        "--json",
        *sets([*QUICK_SEARCH, *QUICK_LEARN]),
    ]
    assert main(argv) == 0
    whole = json.loads(capsys.readouterr().out)["reference_choice"]
    # stopped in pass 2's search, before the choice: pass 1 kept, the rest gone
    for name in ("choice.json", "metrics.json", "checkpoint.json", "reference.npz"):
        (out / name).unlink()
    shutil.rmtree(out / PASSES[1])
    assert main([*argv, "--resume"]) == 0
    again = json.loads(capsys.readouterr().out)["reference_choice"]
    assert _no_wall(again) == _no_wall(whole)
    assert (out / "reference.npz").read_bytes() == (
        out / again["kept"] / "reference.npz"
    ).read_bytes()


def test_a_choice_stopped_in_pass_2s_learning_resumes_to_the_same_choice(
    robot, tick_reference, tmp_path
):
    first = Reference.load(tick_reference)
    second = replace(first, loops=first.loops + 1e-3)  # another gait, learned again

    def make(walker):
        return first if walker is None else second

    cfg = apply_overrides(TickLearnConfig(), QUICK_LEARN)
    out = tmp_path / "run"
    _summary, whole = learn_clip(make, robot, cfg, out)
    assert not any(p.same_as for p in whole.passes)
    assert (out / PASSES[1] / "checkpoint.json").is_file()
    for name in ("choice.json", "metrics.json", "checkpoint.json", "reference.npz"):
        (out / name).unlink()
    (out / PASSES[1] / "metrics.json").unlink()
    _summary, again = learn_clip(make, robot, cfg, out, resume=True)
    assert _no_wall(again.to_dict()) == _no_wall(whole.to_dict())
    assert (out / "reference.npz").read_bytes() == (out / again.kept / "reference.npz").read_bytes()


def test_a_reference_not_searched_is_learned_once(tmp_path, capsys):
    out = tmp_path / "run"
    argv = [
        "learn",
        "--variant",
        "extended",
        "--out",
        str(out),
        "--json",
        *sets(["retarget.search=false", "retarget.scales=0.9,1.0"]),
    ]
    assert main([*argv, *sets(QUICK_LEARN)]) == 0
    assert "reference_choice" not in json.loads(capsys.readouterr().out)
    assert not (out / PASSES[0]).exists() and not (out / "choice.json").exists()
    assert (out / "metrics.json").is_file()
