"""Shared pytest fixtures."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

# MuJoCo reads MUJOCO_GL when it is first imported. imitwalk sets it (offscreen on the CPU)
# when it is imported, but a test module may import mujoco first (test_bullet.py, the first
# collected): without this the report's renderer would get GLFW and no display.
os.environ.setdefault("MUJOCO_GL", "egl")

#: Settings of a tiny faithful learning run (two scales, two short iterations each, one
#: process).
TINY = [
    "schedule.start=0.3",
    "schedule.stop=0.4",
    "schedule.iterations=2",
    "schedule.seconds=6",
    "workers=1",
]

#: Settings of a tiny per-tick learning run (:mod:`imitwalk.balance.ticklearn`): scales 0.8 and 1,
#: two training robots x 6 s, two candidates per trial-picked setting on two robots x 6 s.
TICK = [
    "start=0.8",
    "step=0.2",
    "robots=2",
    "seconds=6",
    "trials.robots=2",
    "trials.seconds=6",
    "trials.heading_robots=2",
    "trials.heading_seconds=6",
    "trials.feedforward=0,0.5",
    "trials.pitch=0,0.1",
    "trials.roll=0,0.1",
    "trials.heading=0,0.3",
    "trials.torso=0,-0.3",
    "trials.tilt=0,0.3",
    "workers=1",
]


#: Settings of a tiny stepping run (:mod:`imitwalk.step.learn`): two CMA-ES generations of
#: four candidates, each on one robot for 3 s.
TINY_STEP = ["generations=2", "population=4", "robots=1", "seconds=3", "final_robots=1"]


def sets(settings: list[str]) -> list[str]:
    """``--set`` arguments for ``settings``."""
    return [a for s in settings for a in ("--set", s)]


def strip_wall(summary) -> dict:
    """A learning summary (a :class:`~imitwalk.runs.LearnSummary` or its ``metrics.json``)
    without its wall time (the one thing a rerun may change)."""
    d = summary if isinstance(summary, dict) else summary.to_dict()
    return {k: v for k, v in d.items() if k != "wall_seconds_for_learning"}


def strip_log(log: list[dict]) -> list[dict]:
    """A learning log without its wall times."""
    return [{k: v for k, v in e.items() if k != "wall_seconds"} for e in log]


def _missing(why: str) -> None:
    """Skip a test whose input is absent, or fail it where it is required
    (``IMITWALK_REQUIRE_INPUTS=1``, as ``.ci/run`` sets: CI must not pass by skipping)."""
    if os.environ.get("IMITWALK_REQUIRE_INPUTS") == "1":
        pytest.fail(why + "; IMITWALK_REQUIRE_INPUTS=1 requires it")
    pytest.skip(why)


@pytest.fixture(scope="session")
def shared_mocap() -> Path:
    """Folder of the shared real mocap fixtures: ``$IMITWALK_SHARED_MOCAP``, else
    ``<repo root>/../shared/mocap``; skips the test if it is absent."""
    env = os.environ.get("IMITWALK_SHARED_MOCAP")
    path = Path(env) if env else Path(__file__).resolve().parents[1].parent / "shared" / "mocap"
    if not path.is_dir():
        _missing(f"shared mocap folder not found: {path} (set IMITWALK_SHARED_MOCAP)")
    return path


@pytest.fixture(scope="session")
def shared_robots() -> Path:
    """Folder of the third-party robots (ROBOTIS OP3, Unitree G1): ``$IMITWALK_SHARED_ROBOTS``,
    else ``<repo root>/../shared/robots``; skips the test if it is absent."""
    env = os.environ.get("IMITWALK_SHARED_ROBOTS")
    path = Path(env) if env else Path(__file__).resolve().parents[1].parent / "shared" / "robots"
    if not path.is_dir():
        _missing(f"shared robots folder not found: {path} (set IMITWALK_SHARED_ROBOTS)")
    return path


@pytest.fixture(scope="session")
def robot():
    """The built-in HOAP-2-class robot."""
    from imitwalk.robots import load_robot

    return load_robot("hoap2")


@pytest.fixture(scope="session")
def tiny_reference(robot, tmp_path_factory):
    """A walkable reference of the default clip at scales 0.3 and 0.4 (no search), and the
    path it is saved at."""
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.retarget import GaitParams, RetargetConfig, retarget

    cfg = RetargetConfig(search=False, scales=(0.3, 0.4), params=GaitParams(sway=0.9, ds=0.1))
    ref = retarget(load_motion(default_clip()), robot, cfg).reference
    path = tmp_path_factory.mktemp("ref") / "ref.npz"
    ref.save(path)
    return ref, path


@pytest.fixture(scope="session")
def tick_reference(tmp_path_factory) -> Path:
    """The default clip retargeted without the parameter search (every grid scale), as
    ``imitwalk retarget --no-search`` writes it: the reference of the per-tick tests."""
    from imitwalk.cli.main import main

    path = tmp_path_factory.mktemp("tickref") / "ref.npz"
    assert main(["retarget", "--no-search", "--out", str(path)]) == 0
    return path


@pytest.fixture(scope="session")
def tick_run(tick_reference, tmp_path_factory) -> Path:
    """A finished tiny per-tick run (:data:`TICK`) learned through the CLI. Shared: a test
    that writes into a run copies it first."""
    from imitwalk.cli.main import main

    out = tmp_path_factory.mktemp("tickrun") / "run"
    argv = ["learn", "--reference", str(tick_reference), "--out", str(out), *sets(TICK)]
    assert main(argv) == 0
    return out


@pytest.fixture(scope="session")
def step_run(tmp_path_factory) -> Path:
    """A finished tiny stepping run (:data:`TINY_STEP`, the default clip) learned through
    the CLI. Shared: a test that writes into a run copies it first."""
    from imitwalk.cli.main import main

    out = tmp_path_factory.mktemp("steprun") / "run"
    assert main(["learn", "--out", str(out), *sets(TINY_STEP)]) == 0
    return out
