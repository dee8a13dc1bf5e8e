"""Shared pytest fixtures."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

#: Settings of a tiny learning run (two scales, two short iterations each, one process).
TINY = [
    "schedule.start=0.3",
    "schedule.stop=0.4",
    "schedule.iterations=2",
    "schedule.seconds=6",
    "gain_robots=2",
    "gain_seconds=4",
    "workers=1",
]


def strip_wall(summary: dict) -> dict:
    """A learning summary without its wall times (the one thing a rerun may change)."""
    out = {k: v for k, v in summary.items() if k != "wall_seconds_for_learning"}
    for key in ("gain_trials", "cadence_trials"):
        if out.get(key):
            out[key] = {k: v for k, v in out[key].items() if k != "wall_seconds"}
    return out


@pytest.fixture(scope="session")
def shared_mocap() -> Path:
    """Folder of the shared real mocap fixtures: ``$IMITWALK_SHARED_MOCAP``, else
    ``<repo root>/../shared/mocap``; skips the test if it is absent."""
    env = os.environ.get("IMITWALK_SHARED_MOCAP")
    path = Path(env) if env else Path(__file__).resolve().parents[1].parent / "shared" / "mocap"
    if not path.is_dir():
        pytest.skip(f"shared mocap folder not found: {path} (set IMITWALK_SHARED_MOCAP)")
    return path


@pytest.fixture(scope="session")
def shared_robots() -> Path:
    """Folder of the third-party robots (ROBOTIS OP3, Unitree G1): ``$IMITWALK_SHARED_ROBOTS``,
    else ``<repo root>/../shared/robots``; skips the test if it is absent."""
    env = os.environ.get("IMITWALK_SHARED_ROBOTS")
    path = Path(env) if env else Path(__file__).resolve().parents[1].parent / "shared" / "robots"
    if not path.is_dir():
        pytest.skip(f"shared robots folder not found: {path} (set IMITWALK_SHARED_ROBOTS)")
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
