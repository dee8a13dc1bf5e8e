"""One cell of a sweep: its clip learned on its robot (the stepping gait), then judged.

:func:`run_cell` runs in a Ray worker (or in this process) on one core: learning and
judging each walk their robots one after the other (``IMITWALK_WORKERS=1``), so that the
sweep's parallelism is the cells'. A cell that ``learn`` or the judge refuses gives a row
with its one-line error, not a failed sweep. Its row is written to ``row.json`` in its
folder (atomically) as it ends: a cell with a row is done, and a resumed sweep skips it;
one without resumes its learning where it stopped (``learn --resume``).
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from imitwalk.errors import ImitwalkError
from imitwalk.fileio import atomic_write
from imitwalk.sweep.config import DEFAULT_CLIP, Cell

__all__ = ["COLUMNS", "ROW", "CellJob", "run_cell"]

#: A finished cell's row file, in its folder.
ROW = "row.json"
#: The results table's columns, in order.
COLUMNS = (
    "cell",
    "clip",
    "robot",
    "settings",
    "seed",
    "status",
    "scale_reached",
    "learn_sim_s",
    "learn_wall_s",
    "protocol",
    "judged_robots",
    "seconds",
    "falls",
    "survived",
    "progress_min",
    "distance_m",
    "abs_yaw_deg",
)


@dataclass(frozen=True)
class CellJob:
    """A cell to run: the cell, its folder, and how it is judged."""

    cell: Cell
    folder: str
    protocol: str
    judge_robots: int
    seconds: float


def _row(job: CellJob, status: str, **values: Any) -> dict[str, Any]:
    c = job.cell
    row: dict[str, Any] = dict.fromkeys(COLUMNS)
    row.update(
        cell=c.name,
        clip=c.clip,
        robot=c.robot,
        settings=" ".join(c.settings),
        seed=c.seed,
        status=status,
        protocol=job.protocol,
        judged_robots=job.judge_robots,
        seconds=job.seconds,
    )
    row.update(values)
    return row


def run_cell(job: CellJob) -> dict[str, Any]:
    """Learn and judge ``job``'s cell; its row (also written to ``row.json``)."""
    os.environ["IMITWALK_WORKERS"] = "1"  # the sweep runs cells side by side
    from imitwalk.config import apply_overrides
    from imitwalk.judge.verdict import judge_protocol
    from imitwalk.retarget.provenance import Provenance
    from imitwalk.robots import load_robot
    from imitwalk.sim.protocol import load_protocol
    from imitwalk.step.learn import StepLearnConfig
    from imitwalk.step.pipeline import learn

    folder = Path(job.folder)
    run_dir = folder / "run"
    c = job.cell
    try:
        robot = load_robot(c.robot)
        cfg = apply_overrides(StepLearnConfig(seed=c.seed), list(c.settings))
        resume = (run_dir / "config.json").is_file()
        clip = None if c.clip == DEFAULT_CLIP else c.clip
        where = Provenance(robot=c.robot)
        summary = learn(clip, robot, str(run_dir), cfg, resume, None, where)
        verdict = judge_protocol(
            str(run_dir),
            robot,
            load_protocol(job.protocol),
            job.judge_robots,
            job.seconds,
            controllers=("learned",),
            workers=1,
        )
        v = verdict.controllers["learned"]
        row = _row(
            job,
            "ok",
            scale_reached=summary.scale_reached,
            learn_sim_s=summary.sim_seconds_used_for_learning,
            learn_wall_s=summary.wall_seconds_for_learning,
            falls=v.falls,
            survived=v.survived,
            progress_min=v.progress_ratio_min,
            distance_m=v.distance_m,
            abs_yaw_deg=v.abs_yaw_deg,
        )
    except ImitwalkError as exc:
        row = _row(job, f"error: {exc}")
    text = json.dumps(row, indent=1)
    atomic_write(folder / ROW, lambda tmp: tmp.write_text(text + "\n"))
    return row
