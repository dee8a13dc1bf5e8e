"""Judging a run on a protocol: every controller on the same robots, compared in pairs."""

from __future__ import annotations

import json

import pytest

from imitwalk.errors import ConfigError
from imitwalk.judge.records import ProtocolVerdict
from imitwalk.judge.verdict import judge_protocol
from imitwalk.paper.evaluate import compare_falls
from imitwalk.sim.protocol import load_protocol

#: Robots and seconds of the judgement (the hard protocol, where robots fall).
SEEDS, SECONDS = 3, 6.0


@pytest.fixture(scope="module")
def judged(tick_run, robot):
    return judge_protocol(tick_run, robot, load_protocol("hard"), SEEDS, SECONDS, workers=1)


def test_every_controller_walks_the_same_robots(judged, robot):
    sides = judged.controllers
    assert list(sides) == ["learned", "feedback", "fixed", "open_loop"]
    protocol = load_protocol("hard")
    furthest = [protocol.draw(s, robot, seconds=SECONDS).furthest for s in range(SEEDS)]
    for side in sides.values():
        assert side.robots == SEEDS and side.survived + side.falls == SEEDS
        assert [r.seed for r in side.per_seed] == list(range(SEEDS))
        assert [r.furthest for r in side.per_seed] == furthest
        lo, hi = side.survival_ci95
        assert lo <= side.survival == side.survived / SEEDS <= hi
        assert side.falls == sum(r.fell for r in side.per_seed)
    st = judged.settings
    assert (st.seeds, st.seconds, st.engine) == (SEEDS, SECONDS, "mujoco")
    assert st.controllers == tuple(sides) and judged.protocol.name == "hard"


def test_the_verdict_round_trips_through_its_json(judged):
    back = ProtocolVerdict.from_dict(json.loads(json.dumps(judged.to_dict())))
    assert back == judged


def test_falls_are_broken_down_by_the_factor_drawn_furthest(judged):
    factors = set(load_protocol("hard").factors)
    for side in judged.controllers.values():
        by = side.falls_by_furthest_factor
        assert set(by) >= factors
        # every robot of the hard protocol is perturbed: each fall is under one factor
        assert sum(by.values()) == side.falls
        for factor, count in by.items():
            fell = [r for r in side.per_seed if r.fell and r.furthest == factor]
            assert count == len(fell)


def test_each_controller_is_compared_with_open_loop_on_the_same_robots(judged):
    sides, comp = judged.controllers, judged.comparison
    assert set(comp) == {"learned", "feedback", "fixed"}
    base = [r.fell for r in sides["open_loop"].per_seed]
    for name, c in comp.items():
        fell = [r.fell for r in sides[name].per_seed]
        assert c == compare_falls(fell, base)
        assert c["robots"] == SEEDS and 0.0 < c["mcnemar_p"] <= 1.0
        assert c["learned_fall_rate"] == sides[name].falls / SEEDS


def test_a_subset_of_controllers_at_another_scale(tick_run, robot):
    out = judge_protocol(tick_run, robot, load_protocol("eval"), 1, 2.0, ("fixed",), 0.8, 1)
    assert list(out.controllers) == ["fixed"] and out.comparison == {}
    assert out.settings.scale == 0.8
    with pytest.raises(ConfigError, match=r"unknown controller 'x'; valid: feedback, fixed, l"):
        judge_protocol(tick_run, robot, load_protocol("eval"), 1, 2.0, ("learned", "x"))


def test_robots_from_a_first_seed_are_judged(tick_run, robot):
    protocol = load_protocol("eval")
    out = judge_protocol(tick_run, robot, protocol, 1, 2.0, ("fixed",), 1.0, 1, first=300_000)
    assert [r.seed for r in out.controllers["fixed"].per_seed] == [300_000]
    assert out.settings.first == 300_000
    assert protocol.draw(300_000, robot).options != protocol.draw(0, robot).options
    with pytest.raises(ConfigError, match=r"first robot -1: valid robots are 0 and up"):
        judge_protocol(tick_run, robot, protocol, 1, 2.0, ("fixed",), first=-1)


def test_judging_stops_once_more_robots_fell_than_allowed(tick_run, robot):
    hard = load_protocol("hard")
    whole = judge_protocol(tick_run, robot, hard, 4, 4.0, ("fixed",), 1.0, 1)
    fell = [r.fell for r in whole.controllers["fixed"].per_seed]
    assert any(fell)  # hard's kicked robots fall within 4 s without the learned law
    cut = judge_protocol(tick_run, robot, hard, 4, 4.0, ("fixed",), 1.0, 1, most_falls=0)
    rows = cut.controllers["fixed"].per_seed
    assert rows == whole.controllers["fixed"].per_seed[: fell.index(True) + 1]
    assert cut.controllers["fixed"].falls == 1 and cut.settings.seeds == 4
    with pytest.raises(ConfigError, match="most_falls needs one controller, not 2"):
        judge_protocol(tick_run, robot, hard, 1, 2.0, ("fixed", "learned"), most_falls=0)


def test_the_breakdown_counts_each_perturbed_robots_fall_once():
    from imitwalk.judge.verdict import RobotWalk, _side
    from imitwalk.sim.metrics import WalkMetrics

    def row(seed, fell, furthest):
        m = WalkMetrics(
            fell=fell,
            fall_time_s=1.0 if fell else None,
            seconds=10.0,
            forward_distance_m=1.0,
            forward_speed_mps=0.1,
            progress_ratio=0.9,
            lateral_drift_m=0.0,
            yaw_drift_deg=-2.0,
            gyro_rms=0.1,
            max_tilt_deg=1.0,
            joint_rms_error_rad=0.01,
        )
        return RobotWalk(seed, furthest, m)

    runs = [
        row(0, True, None),
        row(1, True, "mass"),
        row(2, False, "mass"),
        row(3, True, "slope"),
        row(4, True, "mass"),
    ]
    side = _side(runs, ("mass", "slope", "friction"))
    assert side.falls == 4 and side.survived == 1
    assert side.falls_by_furthest_factor == {"mass": 2, "slope": 1, "friction": 0}
    # the nominal robot (seed 0 of a nominal-first protocol) has no factor to fall under
    perturbed = sum(r.metrics.fell for r in runs if r.furthest is not None)
    assert sum(side.falls_by_furthest_factor.values()) == perturbed
    assert side.abs_yaw_deg == 2.0 and side.progress_ratio_min == 0.9


def test_a_verdict_file_of_another_layout_is_a_one_line_error():
    from imitwalk.errors import RunError
    from imitwalk.judge.records import PushVerdict

    old = {
        "settings": {
            "seeds": 40,
            "seconds": 30.0,
            "engine": "mujoco",
            "scale": 1.0,
            "channel_gain": 0.5,
        },
        "controllers": {},
    }
    with pytest.raises(RunError, match=r"^old\.json: not a protocol verdict of this imitwalk"):
        ProtocolVerdict.from_dict(old, "old.json")
    with pytest.raises(RunError, match=r"^p\.json: not a push-recovery table"):
        PushVerdict.from_dict({"controllers": {}}, "p.json")


def test_falls_explained_name_the_factors_whose_removal_alone_saves_them(tick_run, robot):
    from imitwalk.judge.verdict import RunController

    protocol = load_protocol("hard")
    out = judge_protocol(
        tick_run, robot, protocol, SEEDS, SECONDS, ("fixed",), workers=1, explain=True
    )
    side = out.controllers["fixed"]
    assert side.falls > 0  # hard's robots fall in 6 s on this tiny run
    for r in side.per_seed:
        assert (r.saved_by is None) == (not r.fell)
    saved = {r.seed: r.saved_by for r in side.per_seed if r.fell}
    assert side.falls_no_single_factor == sum(not s for s in saved.values())
    assert side.falls_saved_by_factor == {
        f: sum(f in s for s in saved.values()) for f in protocol.factors
    }
    # each named factor, taken away, does let that robot walk; each other one does not
    seed = next(iter(saved))
    for factor in protocol.factors:
        rest = protocol.only([f for f in protocol.factors if f != factor])
        d = rest.draw(seed, robot, seconds=SECONDS)
        walk = RunController(str(tick_run), "fixed").walk(robot, d.options, SECONDS, "mujoco")
        assert walk.fell == (factor not in saved[seed]), factor
    back = ProtocolVerdict.from_dict(json.loads(json.dumps(out.to_dict())))
    assert back == out
    # verdicts written before falls could be explained still load
    old = out.to_dict()
    for c in old["controllers"].values():
        del c["falls_saved_by_factor"], c["falls_no_single_factor"]
        for r in c["per_seed"]:
            del r["saved_by"]
    plain = ProtocolVerdict.from_dict(old).controllers["fixed"]
    assert plain.falls_saved_by_factor is None and plain.per_seed[0].saved_by is None


def test_the_reports_table_lists_the_explained_falls(judged):
    from dataclasses import replace

    from imitwalk.judge.tables import protocol_table

    assert "one factor alone" not in protocol_table(judged)
    sides = {
        name: replace(s, falls_saved_by_factor={"pushes": s.falls}, falls_no_single_factor=0)
        for name, s in judged.controllers.items()
    }
    html = protocol_table(replace(judged, controllers=sides))
    falling = [n for n, s in sides.items() if s.falls]
    assert falling and "one factor alone back to nominal" in html
    for name in falling:
        assert f"<li>{name}: pushes {sides[name].falls}; by no single factor: 0</li>" in html


def test_any_controller_is_judged_on_a_protocols_robots(tick_run, robot):
    """judge_controllers takes controllers, not a run folder: a run's controller judged
    through it is the same verdict as through judge_protocol, beside one of the caller's
    own (a RunController at another scale), on the same robots."""
    from imitwalk.judge.verdict import RunController, judge_controllers

    protocol = load_protocol("eval")
    by_run = judge_protocol(tick_run, robot, protocol, 3, 4.0, ("fixed",), workers=1)
    mine = {
        "fixed": RunController(str(tick_run), "fixed", by_run.settings.scale),
        "slower": RunController(str(tick_run), "fixed", 0.8),
    }
    out = judge_controllers(mine, robot, protocol, 3, 4.0, by_run.settings.scale, workers=1)
    assert out.controllers["fixed"] == by_run.controllers["fixed"]
    assert out.settings.controllers == ("fixed", "slower")
    assert [r.seed for r in out.controllers["slower"].per_seed] == [0, 1, 2]
