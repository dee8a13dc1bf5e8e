"""The command line's numbers and names, checked before any work starts: a walk's length,
the robots and processes to use, a stride scale and an output folder's name. Each refusal
is one line that names the flag and the valid range (:class:`~imitwalk.errors.ConfigError`,
exit status 2)."""

from __future__ import annotations

import argparse
import math

from imitwalk.errors import ConfigError

__all__ = [
    "MAX_SCALE",
    "MIN_SECONDS",
    "check_count",
    "check_folder_name",
    "check_joint_map_alone",
    "check_scale",
    "check_seconds",
    "check_workers",
]

#: The shortest walk a command simulates [s]: ten control ticks of 10 ms, so that a walk
#: has a state to report.
MIN_SECONDS = 0.1
#: The largest stride scale a run is judged or exported at (a reference's grid ends at
#: 1.0 or, with ``--forward``, at 1.5).
MAX_SCALE = 1.5


def check_seconds(seconds: float, flag: str = "--seconds") -> None:
    """Refuse a walk's length [s] that is not finite or is under :data:`MIN_SECONDS`."""
    if not (math.isfinite(seconds) and seconds >= MIN_SECONDS):
        raise ConfigError(
            f"{flag} {seconds:g}: expected a finite number of seconds >= {MIN_SECONDS:g}"
        )


def check_count(count: int, flag: str) -> None:
    """Refuse a count of robots (or of anything a command needs one of) under 1."""
    if count < 1:
        raise ConfigError(f"{flag} {count}: expected >= 1")


def check_folder_name(name: str, flag: str) -> None:
    """Refuse an empty folder name (it would be the working directory)."""
    if not name:
        raise ConfigError(f"{flag} '': give the name of a folder (an empty or new one)")


def check_workers(workers: int | None) -> None:
    """Refuse ``--workers`` under 1 (``None``: one per core)."""
    if workers is not None and workers < 1:
        raise ConfigError(f"--workers {workers}: expected >= 1 processes (default: one per core)")


def check_scale(scale: float | None) -> None:
    """Refuse a stride scale outside (0, :data:`MAX_SCALE`] (``None``: the run's own)."""
    if scale is not None and not (math.isfinite(scale) and 0.0 < scale <= MAX_SCALE):
        raise ConfigError(f"--scale {scale:g}: expected a stride scale in (0, {MAX_SCALE:g}]")


def check_joint_map_alone(args: argparse.Namespace) -> None:
    """Refuse ``--joint-map`` without ``--robot`` where a command otherwise takes the
    robot its run or reference records (and would ignore the joint map)."""
    if getattr(args, "joint_map", None) and getattr(args, "robot", None) is None:
        raise ConfigError(
            f"--joint-map {args.joint_map} needs --robot (the MJCF it maps); without both, "
            "the robot the run records is used"
        )
