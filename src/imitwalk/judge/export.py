"""A finished run written as a controller for :mod:`imitwalk.runtime` (``imitwalk
export``)."""

from __future__ import annotations

from pathlib import Path

from imitwalk.errors import ConfigError
from imitwalk.judge.replay import LoadedRun, load_run
from imitwalk.robots import Robot
from imitwalk.runtime.bundle import check_out, write_bundle

__all__ = ["export_run", "learned_scales"]


def learned_scales(lr: LoadedRun) -> list[float]:
    """The stride scales run ``lr`` learned and was judged at (its ``scales_passed`` and
    the scale it reached), in increasing order."""
    return sorted({float(s) for s in lr.metrics.scales_passed} | {float(lr.scale)})


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
        out: a new or empty folder, or an earlier export (replaced; see
        :func:`~imitwalk.runtime.bundle.check_out`); controller: which of its controllers
        (default: ``rl`` for a PPO run, ``learned`` for a stepping run); scale: the
        stride scale, one of :func:`learned_scales` (default: the scale it reached).

    Returns:
        ``out``.

    Raises:
        RunError: not a finished run; ConfigError: a run of another learner, a
            controller it cannot build, a scale it did not learn (listing those it did),
            or an ``out`` that is a file, a symbolic link, or a folder that holds
            anything but an earlier export (nothing is written or deleted then).
    """
    check_out(out)  # before anything is built
    lr = load_run(run_dir)
    if controller is None:
        controller = "rl" if lr.learner == "rl" else "learned"
    if scale is not None:
        valid = learned_scales(lr)
        if not any(abs(scale - s) <= 1e-9 for s in valid):
            scales = ", ".join(f"{s:g}" for s in valid)
            raise ConfigError(
                f"--scale {scale:g} was not learned or judged in {lr.path}; valid: {scales}"
            )
    bundle = lr.bundle(controller, robot, scale)
    return write_bundle(bundle, out)
