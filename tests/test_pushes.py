"""Push recovery by bisection: the largest kick survived per controller, direction, phase."""

from __future__ import annotations

import json

import numpy as np
import pytest

from imitwalk.errors import ConfigError
from imitwalk.judge import pushes
from imitwalk.judge.pushes import (
    DIRECTIONS,
    PHASES,
    STEPS,
    PushJob,
    kick_time,
    push_recovery,
    top_speed,
)
from imitwalk.judge.records import PushVerdict
from imitwalk.judge.replay import load_run


def _threshold(job: PushJob) -> float:
    """The kick [m/s] each (controller, direction, phase) survives up to, made up: some
    cells survive everything, ``open_loop`` survives nothing, not even no kick."""
    if job.controller == "open_loop":
        return -1.0
    base = {"forward": 0.05, "left": 0.2, "back": 0.33, "right": 9.0}[job.direction]
    return base + 0.01 * job.phase


@pytest.fixture(scope="module")
def recovery(tick_run, robot):
    calls: list[PushJob] = []

    def survives(job):
        calls.append(job)
        return job.speed < _threshold(job)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(pushes, "survives", survives)
        out = push_recovery(tick_run, robot, ("learned", "open_loop"), workers=1)
    return out, calls


def test_bisection_finds_each_threshold_within_the_resolution(recovery, robot):
    out, _ = recovery
    top = top_speed(robot.height)
    st = out.settings
    assert st.top_mps == top and st.resolution_mps == pytest.approx(top / 2**STEPS)
    assert st.phases == PHASES and st.directions == tuple(DIRECTIONS)
    table = out.controllers["learned"].table
    assert list(table) == list(DIRECTIONS) and all(len(v) == PHASES for v in table.values())
    for d, speeds in table.items():
        for p, found in enumerate(speeds):
            thr = _threshold(PushJob("", robot, "learned", 1.0, d, p, 0.0))
            if thr >= top:
                assert found == top  # survived the largest kick tried
            else:
                assert found < thr <= found + st.resolution_mps + 1e-12, (d, p)
    side = out.controllers["learned"]
    assert side.min_by_direction == {d: min(v) for d, v in table.items()}
    assert side.mean == pytest.approx(np.mean([v for row in table.values() for v in row]))
    assert PushVerdict.from_dict(json.loads(json.dumps(out.to_dict()))) == out


def test_a_controller_that_falls_without_a_kick_gets_zero(recovery):
    out, calls = recovery
    side = out.controllers["open_loop"]
    assert all(v == 0.0 for row in side.table.values() for v in row)
    assert side.mean == 0.0
    # it was asked only the two ends: no kick (fell), then no bisection
    asked = [j.speed for j in calls if j.controller == "open_loop"]
    assert len(asked) == 2 * len(DIRECTIONS) * PHASES and set(asked) == {
        0.0,
        out.settings.top_mps,
    }


def test_the_kicks_come_two_cycles_after_the_start_up_at_each_phase(recovery, tick_run):
    out, calls = recovery
    ref = load_run(tick_run).ref
    times = out.settings.kick_times_s
    n, m = ref.loops.shape[1], ref.starts.shape[1]
    assert times[0] == pytest.approx((m + 2 * n) * ref.dt)
    assert np.all(np.diff(times) > 0) and times[-1] < times[0] + n * ref.dt
    assert times == tuple(kick_time(ref, p) for p in range(PHASES))
    assert {j.scale for j in calls} == {load_run(tick_run).scale}  # the scale reached


def test_a_real_kick_is_simulated(tick_run, robot):
    lr = load_run(tick_run)
    job = PushJob(str(tick_run), robot, "learned", lr.scale, "left", 0, 0.0)
    assert pushes.survives(job)  # the learned walk on the nominal robot stays up unkicked
    kicked = PushJob(str(tick_run), robot, "learned", lr.scale, "left", 0, 5.0)
    assert not pushes.survives(kicked)  # and a kick of 5 m/s knocks it over


def test_an_unknown_controller_is_refused_listing_the_runs_own(tick_run, robot):
    with pytest.raises(ConfigError, match=r"unknown controller 'x'; valid: feedback, fixed, learn"):
        push_recovery(tick_run, robot, ("x",), workers=1)
