"""The reference refinement at full stride (``search_config.refine_rounds``)."""

from __future__ import annotations

from dataclasses import dataclass, replace
from types import SimpleNamespace

import pytest

from imitwalk.errors import ConfigError
from imitwalk.parallel import run_parallel
from imitwalk.retarget import GaitParams, RetargetConfig, retarget
from imitwalk.retarget import refine as refine_mod
from imitwalk.retarget.refine import STEPS, refine_params, refine_per_scale
from imitwalk.retarget.search import BOUNDS, SearchConfig
from imitwalk.sim.perturb import TRAIN_SEED_BASE


@dataclass
class _Metrics:
    fell: bool
    seconds: float
    progress_ratio: float
    yaw_drift_deg: float


def _falls(p: dict) -> int:
    """A made-up landscape: fewest falls at lean 3 mm and ds 0.14."""
    return round(abs(p["lean"] - 0.003) / 0.0015) + round(abs(p["ds"] - 0.14) / 0.02)


def _stops(play):
    """``play`` with the real playback's ``stop``: its runs go through
    :func:`imitwalk.parallel.run_parallel` (in this process) as the robots' jobs would."""

    def with_stop(*args, stop=None, **kw):
        return run_parallel(lambda run: run, play(*args, **kw), workers=1, stop=stop)

    return with_stop


played: list[tuple] = []  # (scale, seconds, seeds, disturbance) of each stubbed playback


def _play(ref, robot, scale, seconds, seeds, base, workers, engine, disturbance):
    """A stubbed playback: the first ``_falls(ref)`` robots fall, halfway through."""
    played.append((scale, seconds, tuple(seeds), disturbance))
    n = _falls(ref)
    return [
        SimpleNamespace(metrics=_Metrics(i < n, seconds / 2 if i < n else seconds, 1.0, 0.0))
        for i in range(len(seeds))
    ]


@pytest.fixture
def stubbed(monkeypatch):
    """No IK, no physics: a 'reference' is its parameters, and its falls are _falls."""
    played.clear()

    def build(template, robot, params, scales, dt, ik=None, command=None):
        return SimpleNamespace(reference=params.to_dict())

    monkeypatch.setattr(refine_mod, "WalkIK", lambda robot: None)
    monkeypatch.setattr(refine_mod, "build_walkable", build)
    monkeypatch.setattr("imitwalk.sim.playback.play_reference", _stops(_play))
    return played


def test_refinement_keeps_the_first_nudge_that_falls_less_and_stops_once_nothing_falls(stubbed):
    cfg = SearchConfig(
        scales=(0.5, 1.0),
        refine_rounds=5,
        refine_models=10,
        refine_seconds=4.0,
        refine_early_stop=False,  # every robot of every trial played (the next test: not)
    )
    start = GaitParams(lean=0.0, ds=0.1, lift=BOUNDS["lift"][0])
    seen = []
    params, rep = refine_params(None, None, start, cfg, progress=lambda *a: seen.append(a))
    assert params.lean == pytest.approx(0.003) and params.ds == pytest.approx(0.14)
    # falls are counted at each refinement scale, on the same training robots, with the push
    assert rep["start_falls"] == 3 * _falls(start.to_dict()) == 12 and rep["falls"] == 0
    assert rep["scales"] == [0.8, 0.9, 1.0] == sorted({s for s, *_ in stubbed})
    assert len({x[2] for x in stubbed}) == 1 and rep["trials"][0]["robots"] == 30
    seeds = rep["seeds"]
    assert len(seeds) == 10 and seeds[0] == 0 and min(seeds[1:]) > TRAIN_SEED_BASE
    assert all(d for *_, d in stubbed)
    changed = [t["changed"] for t in rep["trials"]]
    assert changed[0] == "" and "lift-" not in changed  # lift starts at its lower bound
    kept = [t["changed"] for t in rep["trials"] if t["kept"]]
    assert kept == ["", "ds+", "lean+", "ds+", "lean+"]
    # once nothing falls, nothing can beat it: the search ends before its five rounds
    assert rep["trials"][-1]["changed"] == "lean+" and rep["trials"][-1]["kept"]
    assert [a[0] for a in seen] == list(range(1, len(rep["trials"]) + 1))
    fresh = sum(not t["repeat"] for t in rep["trials"])
    assert len(stubbed) == 3 * fresh and rep["sim_seconds"] == fresh * 3 * 10 * 4.0
    assert [a[2].kept for a in seen] == [t["kept"] for t in rep["trials"]]


def _with_sway(play, sway: float):
    """``play`` on a landscape where any nudge of the sway away from ``sway`` falls more."""

    def worse(ref, robot, scale, seconds, seeds, base, workers, engine, disturbance):
        runs = play(ref, robot, scale, seconds, seeds, base, workers, engine, disturbance)
        n = _falls(ref) + 3 * round(abs(ref["sway"] - sway) / STEPS["sway"])
        return [
            SimpleNamespace(metrics=replace(r.metrics, fell=i < n, seconds=seconds / (1 + (i < n))))
            for i, r in enumerate(runs)
        ]

    return worse


def test_early_stop_keeps_the_same_sets_and_plays_fewer_robots(stubbed, monkeypatch):
    start = GaitParams(lean=0.0, ds=0.1, lift=BOUNDS["lift"][0])
    monkeypatch.setattr(
        "imitwalk.sim.playback.play_reference", _stops(_with_sway(_play, start.sway))
    )
    cfg = SearchConfig(refine_rounds=5, refine_models=10, refine_seconds=4.0)
    full_params, full = refine_params(None, None, start, replace(cfg, refine_early_stop=False))
    stubbed.clear()
    params, rep = refine_params(None, None, start, cfg)
    assert cfg.refine_early_stop and rep["early_stop"]  # on by default
    # the same nudges, kept or not, in the same order: the same parameters
    assert params == full_params and rep["falls"] == full["falls"]
    assert [(t["changed"], t["kept"]) for t in rep["trials"]] == [
        (t["changed"], t["kept"]) for t in full["trials"]
    ]
    stopped = 0
    best = rep["trials"][0]
    for t, f in zip(rep["trials"], full["trials"], strict=True):
        if t["complete"]:
            assert t == f  # a trial played to the end counts as before, to the bit
        else:  # stopped once it fell more often than the set to beat: a lower bound
            assert not t["kept"] and best["falls"] < t["falls"] <= f["falls"]
            assert t["robots"] < f["robots"]
            stopped += not t["repeat"]
        if t["kept"]:
            best = t
    assert stopped == rep["stopped_early"] > 0
    played = sum(t["robots"] for t in rep["trials"] if not t["repeat"])
    assert rep["sim_seconds"] == played * 4.0 < full["sim_seconds"]
    assert stubbed[0][0] == 1.0  # the longest stride, where most robots fall, is played first


def test_early_stop_in_the_per_scale_refinement(stubbed, monkeypatch):
    start = GaitParams(lean=0.0, ds=0.1)
    monkeypatch.setattr(
        "imitwalk.sim.playback.play_reference", _stops(_with_sway(_play, start.sway))
    )
    cfg = SearchConfig(refine_rounds=3, refine_scales=(1.0, 0.8), refine_models=5)
    full_own, full = refine_per_scale(None, None, start, replace(cfg, refine_early_stop=False))
    own, rep = refine_per_scale(None, None, start, cfg)
    assert own == full_own and rep["falls"] == full["falls"]
    assert rep["stopped_early"] > 0 and rep["sim_seconds"] < full["sim_seconds"]
    assert all(t["robots"] <= 5 and (t["complete"] or not t["kept"]) for t in rep["trials"])


def test_a_nudge_that_costs_progress_is_not_kept(stubbed, monkeypatch):
    def play(ref, robot, scale, seconds, seeds, base, workers, engine, disturbance):
        prog = 0.5 if ref["lean"] > 0.001 else 1.0  # more lean: fewer falls, but shuffles
        n = _falls(ref)
        return [
            SimpleNamespace(metrics=_Metrics(i < n, seconds, prog, 0.0)) for i in range(len(seeds))
        ]

    monkeypatch.setattr("imitwalk.sim.playback.play_reference", _stops(play))
    cfg = SearchConfig(refine_rounds=2, refine_models=6, refine_seconds=4.0)
    params, rep = refine_params(None, None, GaitParams(lean=0.0, ds=0.14), cfg)
    assert params.lean == 0.0 and rep["falls"] == rep["start_falls"] == 2 * 3
    # a round that keeps nothing ends it (width 0 is its lower bound: no "width-")
    assert len(rep["trials"]) == 2 * len(STEPS)


def test_the_heading_is_not_guarded(stubbed, monkeypatch):
    def play(ref, robot, scale, seconds, seeds, base, workers, engine, disturbance):
        yaw = 4.0 + 1500.0 * max(ref["lean"], 0.0)  # more lean: fewer falls, but it turns
        n = _falls(ref)
        return [
            SimpleNamespace(metrics=_Metrics(i < n, seconds, 1.0, yaw)) for i in range(len(seeds))
        ]

    monkeypatch.setattr("imitwalk.sim.playback.play_reference", _stops(play))
    cfg = SearchConfig(refine_rounds=3, refine_models=6, refine_seconds=4.0)
    params, rep = refine_params(None, None, GaitParams(lean=0.0, ds=0.14), cfg)
    assert params.lean == pytest.approx(0.003) and rep["falls"] == 0  # heading not guarded


def test_per_scale_refinement_finds_each_scale_its_own_set(stubbed, monkeypatch):
    def play(ref, robot, scale, seconds, seeds, base, workers, engine, disturbance):
        stubbed.append((scale, seconds, tuple(seeds), disturbance))
        best_lean = 0.003 if scale > 0.95 else 0.0  # full stride wants lean, 0.8 does not
        n = round(abs(ref["lean"] - best_lean) / 0.0015) + round(abs(ref["ds"] - 0.14) / 0.02)
        return [
            SimpleNamespace(metrics=_Metrics(i < n, seconds, 1.0, 0.0)) for i in range(len(seeds))
        ]

    monkeypatch.setattr("imitwalk.sim.playback.play_reference", _stops(play))
    cfg = SearchConfig(
        refine_rounds=4, refine_scales=(1.0, 0.8), refine_models=5, refine_early_stop=False
    )
    start = GaitParams(lean=0.0, ds=0.12)
    seen = []
    own, rep = refine_per_scale(None, None, start, cfg, progress=lambda *a: seen.append(a))
    assert sorted(own) == [0.8, 1.0]
    assert own[0.8].lean == 0.0 and own[0.8].ds == pytest.approx(0.14)
    assert own[1.0].lean == pytest.approx(0.003) and own[1.0].ds == pytest.approx(0.14)
    # each trial is played at its own scale only, and both start from the searched set
    per = rep["per_scale"]
    assert set(per) == {"0.8", "1"} and rep["scales"] == [0.8, 1.0]
    for key, at in (("0.8", 0.8), ("1", 1.0)):
        assert per[key]["scales"] == [at] and per[key]["trials"][0]["params"] == start.to_dict()
        assert all(t["at"] == at and t["robots"] == 5 for t in per[key]["trials"])
    assert rep["start_falls"] == 1 + 3 and rep["falls"] == 0
    assert rep["trials"] == per["0.8"]["trials"] + per["1"]["trials"]
    assert rep["sim_seconds"] == per["0.8"]["sim_seconds"] + per["1"]["sim_seconds"]
    # one progress line per trial, counted over both scales
    assert [a[0] for a in seen] == list(range(1, len(rep["trials"]) + 1))
    assert [a[2].at for a in seen] == [t["at"] for t in rep["trials"]]
    assert len({a[1] for a in seen}) == 1


def test_refinement_settings_are_checked():
    with pytest.raises(ConfigError, match="refine_rounds"):
        SearchConfig(refine_rounds=-1)
    with pytest.raises(ConfigError, match="refine_models"):
        SearchConfig(refine_rounds=1, refine_models=0)
    with pytest.raises(ConfigError, match="refine_scales"):
        SearchConfig(refine_rounds=1, refine_scales=(0.9, 1.2))
    assert SearchConfig().refine_rounds == 0  # off by default
    from imitwalk.config import apply_overrides

    cfg = apply_overrides(
        RetargetConfig(),
        ["search_config.refine_rounds=2", "search_config.refine_models=3"],
    )
    assert cfg.search_config.refine_rounds == 2 and cfg.search_config.refine_models == 3


def test_retarget_refines_the_searched_parameters_and_records_it(robot):
    from imitwalk.mocap import default_clip, load_motion

    sc = SearchConfig(
        generations=1,
        population=2,
        elites=1,
        scales=(0.3, 0.4),
        models=1,
        seconds=1.0,
        workers=1,
        refine_rounds=1,
        refine_scales=(0.4,),
        refine_models=2,
        refine_seconds=1.0,
    )
    cfg = RetargetConfig(scales=(0.3, 0.4), search_config=sc)
    res = retarget(load_motion(default_clip()), robot, cfg)
    ref, rep = res.reference, res.reference.search["refine"]
    stats = res.stats()["refine"]
    assert stats["runs_per_trial"] == 2 and stats["trials"] == len(rep["trials"])
    assert stats["falls"] == rep["falls"] and stats["scales"] == [0.4]
    assert rep["scales"] == [0.4] and rep["trials"][0]["params"] == ref.search["best"]["params"]
    assert ref.params == rep["params"]
    # one second on two robots: nothing falls, so nothing can beat the searched parameters
    assert rep["falls"] == 0 and len(rep["trials"]) == 1 and rep["trials"][0]["kept"]
    again = retarget(load_motion(default_clip()), robot, replace(cfg, search=False))
    assert "refine" not in again.reference.search
    assert again.reference.scale_params == {}  # one set for every scale
    # per scale: the 0.4 loop is solved with its own set (here the searched one: nothing
    # fell), the rest of the grid with the searched set; it survives a save and a load
    per = replace(cfg, search_config=replace(sc, refine_per_scale=True))
    res = retarget(load_motion(default_clip()), robot, per)
    ref, rep = res.reference, res.reference.search["refine"]
    assert set(rep["per_scale"]) == {"0.4"} and rep["trials"][0]["at"] == 0.4
    assert ref.scale_params == {"0.4": rep["per_scale"]["0.4"]["params"]}
    assert res.stats()["scale_params"] == ref.scale_params
    assert ref.params_at(0.4) == ref.scale_params["0.4"] and ref.params_at(0.3) == ref.params
    with pytest.raises(ConfigError, match=r"refine_scales \[0.35\]: not grid scales \(0.3, 0.4\)"):
        retarget(
            None,
            robot,
            replace(cfg, search_config=replace(sc, refine_per_scale=True, refine_scales=(0.35,))),
        )


def test_a_reference_can_be_solved_with_its_own_parameters_at_some_scales(robot, tmp_path):
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.retarget import Reference, extract_template
    from imitwalk.retarget.walkable import build_walkable

    template = extract_template(load_motion(default_clip()))
    base, high = GaitParams(), GaitParams(lift=0.03)
    one = build_walkable(template, robot, base, [0.3, 0.4], 0.01).reference
    two = build_walkable(template, robot, base, [0.3, 0.4], 0.01, scale_params={0.4: high})
    two = Reference.load(two.reference.save(tmp_path / "two.npz"))
    assert two.scale_params == {"0.4": high.to_dict()} and two.params == base.to_dict()
    assert two.params_at(0.4)["lift"] == 0.03 and two.params_at(0.31) == base.to_dict()
    # the 0.3 loop is the same; the 0.4 one lifts its swing foot higher
    assert (two.loops[0] == one.loops[0]).all() and not (two.loops[1] == one.loops[1]).all()
    lift = lambda r: (r.plan["l_sole"][1][:, 2].max(), r.plan["l_sole"][0][:, 2].max())  # noqa: E731
    assert lift(two)[0] > lift(one)[0] + 0.005 and lift(two)[1] == lift(one)[1]
    with pytest.raises(ConfigError, match="not a grid scale"):
        build_walkable(template, robot, base, [0.3, 0.4], 0.01, scale_params={0.5: high})


def test_the_command_line_shows_each_refinement_trial(capsys):
    from imitwalk.cli.commands import refine_report
    from imitwalk.retarget.refine import RefineTrial

    trial = RefineTrial({}, "lean+", 3, 72, 29.0, 0.9, 4.0, kept=True)
    refine_report(2, 25, trial)
    refine_report(1, 25, RefineTrial({}, "", 9, 72, 28.0, 0.9, 4.0, kept=True))
    refine_report(3, 75, RefineTrial({}, "ds-", 2, 24, 29.0, 0.9, 4.0, kept=True, at=1.0))
    err = capsys.readouterr().err.splitlines()
    # retarget and learn announce the refinement before the search starts
    from imitwalk.cli.commands import _announce_search

    _announce_search(RetargetConfig(search_config=SearchConfig(refine_rounds=2)))
    per = SearchConfig(refine_rounds=1, refine_per_scale=True, refine_scales=(0.9, 1.0))
    _announce_search(RetargetConfig(search_config=per))
    _announce_search(RetargetConfig(search=False, search_config=per))
    assert capsys.readouterr().err.splitlines() == [
        "  then up to 2 refinement rounds: 24 robots x 30 s at 0.8/0.9/1",
        "  then up to 1 refinement rounds: 24 robots x 30 s at 0.9/1, each scale on its own",
    ]
    assert err == [
        "  refine 2/25: lean+: 3/72 fell (kept)",
        "  refine 1/25: searched: 9/72 fell",
        "  refine 3/75: ds- at 1: 2/24 fell (kept)",
    ]


@pytest.mark.parametrize(
    ("setting", "message"),
    [
        ("generations=0", "generations: 0 is below 1"),
        ("population=0", "population: 0 is below 1"),
        ("models=0", "models: 0 is below 1"),
        ("elites=9", r"elites: 9 is not in 1\.\.8 \(population\)"),
        ("seconds=0", "seconds: 0.0 is not above 0 s"),
        ("scales=0.5,1.5", r"scales: \(0\.5, 1\.5\) must be scales in \(0, 1\]"),
    ],
)
def test_search_settings_out_of_range_are_refused(setting, message):
    from imitwalk.config import apply_overrides

    with pytest.raises(ConfigError, match=f"search_config.{message}"):
        apply_overrides(RetargetConfig(), [f"search_config.{setting}"])
