"""Run a sweep's cells on Ray, resuming an interrupted sweep.

The sweep's folder holds ``sweep.json`` (the sweep as read: a folder holds one sweep, and
a different one is refused there), one folder per cell (its run and, once done, its
``row.json``), and the results (:mod:`imitwalk.sweep.table`), rewritten as each cell
ends. Running the same sweep into the same folder again runs only the cells without a
row: an interrupted sweep resumes without redoing finished cells.

Cells run as Ray tasks of one CPU each: on a local Ray of ``workers`` CPUs by default,
or on the cluster at ``address`` (``ray.init(address=...)``). A progress bar (``rich``)
counts the cells.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from imitwalk.errors import ConfigError
from imitwalk.fileio import atomic_write
from imitwalk.sweep.cell import ROW, CellJob, run_cell
from imitwalk.sweep.config import SweepConfig
from imitwalk.sweep.table import write_results

__all__ = ["SweepSummary", "run_sweep"]


@dataclass(frozen=True)
class SweepSummary:
    """What a sweep did: its folder, cells in all, cells run now, cells kept from before,
    cells refused (their rows hold the error), and the rows, in cell order."""

    out: str
    cells: int
    ran: int
    kept: int
    refused: int
    rows: tuple[dict[str, Any], ...]


def _start(cfg: SweepConfig, out: Path) -> None:
    """A new sweep's folder, or the same sweep's (refuse another's)."""
    mine = cfg.to_dict()
    saved = out / "sweep.json"
    if saved.is_file():
        try:
            theirs = json.loads(saved.read_text())
        except ValueError:
            theirs = None
        if theirs != mine:
            raise ConfigError(f"--out {out} holds another sweep; give a new folder to run this one")
    elif out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise ConfigError(f"--out {out} holds files that are not a sweep; give a new folder")
    text = json.dumps(mine, indent=1)
    atomic_write(saved, lambda tmp: tmp.write_text(text + "\n"))


def _read_row(path: Path) -> dict[str, Any] | None:
    try:
        row = json.loads(path.read_text())
    except (OSError, ValueError):
        return None  # a row written whole is read whole; anything else runs again
    return row if isinstance(row, dict) and "status" in row else None


def run_sweep(
    cfg: SweepConfig,
    out: str | Path,
    address: str | None = None,
    workers: int = 2,
    show_progress: bool = True,
) -> SweepSummary:
    """Learn and judge every cell of ``cfg`` not yet done in ``out``.

    Args:
        address: a Ray cluster's address (``None``: a local Ray of ``workers`` CPUs).
        show_progress: draw a progress bar on stderr.

    Raises:
        ConfigError: Ray is not installed, ``workers`` < 1, or ``out`` holds something else.
    """
    if workers < 1:
        raise ConfigError(f"--workers {workers}: expected >= 1")
    try:
        import ray
    except ImportError:
        raise ConfigError("imitwalk sweep runs on Ray: pip install 'imitwalk[ray]'") from None
    out = Path(out)
    _start(cfg, out)
    cells = cfg.cells()
    jobs = [
        CellJob(c, str(out / c.name), cfg.protocol, cfg.judge_robots, cfg.seconds) for c in cells
    ]
    rows: dict[int, dict[str, Any]] = {}
    for i, j in enumerate(jobs):
        row = _read_row(Path(j.folder) / ROW)
        if row is not None:
            rows[i] = row
    kept = len(rows)
    todo = [i for i in range(len(jobs)) if i not in rows]

    def flush() -> None:
        write_results([rows[i] for i in sorted(rows)], out, len(jobs))

    started = False
    if todo:
        if not ray.is_initialized():
            kw: dict[str, Any] = {"num_cpus": workers} if address is None else {}
            ray.init(
                address=address,
                include_dashboard=False,
                log_to_driver=False,
                configure_logging=False,
                **kw,
            )
            started = True
        task = ray.remote(num_cpus=1)(run_cell)
        refs = {task.remote(jobs[i]): i for i in todo}
        try:
            with _bar(show_progress, len(jobs), kept) as advance:
                pending = list(refs)
                while pending:
                    done, pending = ray.wait(pending, num_returns=1)
                    i = refs[done[0]]
                    rows[i] = ray.get(done[0])
                    flush()
                    advance()
        finally:
            if started:
                ray.shutdown()
    flush()
    ordered = tuple(rows[i] for i in sorted(rows))
    refused = sum(r["status"] != "ok" for r in ordered)
    return SweepSummary(str(out), len(jobs), len(todo), kept, refused, ordered)


class _bar:
    """A ``rich`` progress bar over the cells (nothing drawn when not shown)."""

    def __init__(self, show: bool, total: int, done: int):
        self.show, self.total, self.done = show, total, done
        self.progress: Any = None

    def __enter__(self) -> Callable[[], None]:
        if self.show:
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeElapsedColumn

            self.progress = Progress(
                "sweep", BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(), transient=False
            )
            self.progress.start()
            self.task = self.progress.add_task("cells", total=self.total, completed=self.done)
        return self.advance

    def advance(self) -> None:
        if self.progress is not None:
            self.progress.advance(self.task)

    def __exit__(self, *exc: object) -> None:
        if self.progress is not None:
            self.progress.stop()
