"""A finished run written as a controller for :mod:`imitwalk.runtime` (``imitwalk
export``)."""

from __future__ import annotations

from pathlib import Path

from imitwalk.judge.replay import load_run
from imitwalk.robots import Robot
from imitwalk.runtime.bundle import write_bundle

__all__ = ["export_run"]


def export_run(
    run_dir: str | Path,
    robot: Robot,
    out: str | Path,
    controller: str | None = None,
    scale: float | None = None,
) -> Path:
    """Write run ``run_dir``'s controller to the folder ``out`` (atomically).

    Args:
        run_dir: a stepping or PPO run; robot: the robot it learned on (nominal);
        controller: which of its controllers (default: ``rl`` for a PPO run, ``learned``
        for a stepping run); scale: the stride scale (default: the scale it reached).

    Returns:
        ``out``.

    Raises:
        RunError: not a finished run; ConfigError: a run of another learner, a
            controller it cannot build, or an ``out`` that holds something else.
    """
    lr = load_run(run_dir)
    if controller is None:
        controller = "rl" if lr.learner == "rl" else "learned"
    bundle = lr.bundle(controller, robot, scale)
    return write_bundle(bundle, out)
