"""Choosing the straight, steady cycles of a clip that turns and wanders, and saying why."""

from __future__ import annotations

from dataclasses import replace
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from imitwalk.errors import MocapError
from imitwalk.mocap import find_cycles, load_motion, smooth
from imitwalk.mocap.selection import MAX_TURN_DEG, choose_cycles
from imitwalk.retarget.template import extract_template

WALK = "cmu_bvh/07_06.bvh"  # two whole left cycles: frames 24-164 and 164-301


@cache
def _walk(folder: str):
    return load_motion(Path(folder) / WALK)


def turned(m, start: int, stop: int, degrees: float):
    """``m`` with its heading turned by ``degrees`` (+ left), ramping up over frames
    ``[start, stop)`` and held after, about the pelvis's position at ``start``."""
    ramp = np.clip((np.arange(m.n_frames) - start) / (stop - start), 0.0, 1.0)
    theta = np.radians(degrees) * ramp
    c, s = np.cos(theta), np.sin(theta)
    rot = np.zeros((m.n_frames, 3, 3))
    rot[:, 0, 0], rot[:, 0, 1], rot[:, 1, 0], rot[:, 1, 1], rot[:, 2, 2] = c, -s, s, c, 1.0
    o = m.keypoints["pelvis"][start] * [1.0, 1.0, 0.0]
    k = {n: np.einsum("tij,tj->ti", rot, p - o) + o for n, p in m.keypoints.items()}
    return replace(m, keypoints=k)


@pytest.mark.parametrize("clip", ["cmu_bvh/07_04.bvh", WALK, "c3d/treadmill_events.c3d"])
def test_straight_clips_keep_every_cycle(shared_mocap, clip):
    m = smooth(load_motion(shared_mocap / clip))
    cycles = find_cycles(m, "l")
    choice = choose_cycles(m, cycles)
    assert list(choice.cycles) == cycles and all(c.used for c in choice.checks)
    assert all(abs(c.turn_deg) < 3 for c in choice.checks)
    assert choice.summary().startswith("frames " + ", ".join(f"{a}-{b}" for a, b in cycles))
    assert "left out" not in choice.summary()


def test_a_turning_cycle_is_left_out_and_said_why(shared_mocap):
    m = turned(_walk(str(shared_mocap)), 24, 164, 40.0)
    t = extract_template(m)
    assert t.cycles == ((164, 301),)
    report = t.meta["cycles_report"]
    assert (
        report.startswith("frames 164-301 (straight: turn") and "left out 24-164: turns" in report
    )
    turn = t.meta["cycle_choice"].checks[0].turn_deg
    assert 30 < turn < 50  # the ramp turned the first cycle by 40 deg


def test_no_straight_cycle_is_one_line_unless_a_turn_is_commanded(shared_mocap):
    m = turned(_walk(str(shared_mocap)), 0, 417, 90.0)  # ~30 deg per cycle, all along
    with pytest.raises(MocapError, match=r"no straight walking cycle in .*07_06.bvh: 2 cycle") as e:
        extract_template(m)
    msg = str(e.value)
    assert "\n" not in msg and f"at most {MAX_TURN_DEG:g} deg" in msg and "--turn" in msg
    t = extract_template(m, allow_turn=True)
    assert t.cycles == ((24, 164), (164, 301))
    turns = [abs(c.turn_deg) for c in t.meta["cycle_choice"].checks]
    assert min(turns) > MAX_TURN_DEG  # so no kept cycle is called straight
    report = t.meta["cycles_report"]
    assert "(turning, allowed by --turn: turn <=" in report and "straight" not in report


def test_an_unsteady_cycle_is_left_out(shared_mocap):
    m = smooth(_walk(str(shared_mocap)))
    choice = choose_cycles(m, [(24, 164), (164, 301), (30, 300)])
    assert choice.cycles == ((24, 164), (164, 301))
    assert "lasts 2.25 s, the median is 1.17 s" in choice.checks[2].reason


def test_a_loop_is_used_whole_and_its_turn_reported(shared_mocap):
    m = load_motion(shared_mocap / "deepmimic" / "walker_turn_left0.txt")
    t = extract_template(m)
    assert len(t.cycles) == 1
    assert t.meta["cycles_report"].endswith("(a loop, used whole; its hips turn 29.8 deg per loop)")
