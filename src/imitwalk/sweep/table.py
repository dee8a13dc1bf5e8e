"""A sweep's results: one table (``results.csv``, ``results.parquet``) and a summary page
(``summary.md``), written atomically from the rows of the cells done so far."""

from __future__ import annotations

import csv
import io
from pathlib import Path
from typing import Any

from imitwalk.fileio import atomic_write
from imitwalk.sweep.cell import COLUMNS

__all__ = ["write_results"]


def _csv(rows: list[dict[str, Any]]) -> str:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=COLUMNS, lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: "" if r.get(k) is None else r[k] for k in COLUMNS})
    return buf.getvalue()


def _parquet(rows: list[dict[str, Any]], path: Path) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.Table.from_pylist([{k: r.get(k) for k in COLUMNS} for r in rows])
    pq.write_table(table, str(path))


def _fmt(v: Any, spec: str = "") -> str:
    return "–" if v is None else format(v, spec)


def _summary(rows: list[dict[str, Any]], cells: int) -> str:
    ok = [r for r in rows if r["status"] == "ok"]
    lines = [
        "# Sweep summary",
        "",
        f"{len(rows)} of {cells} cells done, {len(ok)} learned and judged, "
        f"{len(rows) - len(ok)} refused.",
        "",
        "| Cell | Clip | Robot | Settings | Seed | Scale | Falls | Survived | Progress min "
        "| Distance [m] | Learning: sim s, wall s | Status |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        judged = f"{r['falls']} of {r['judged_robots']}" if r["falls"] is not None else "–"
        lines.append(
            f"| {r['cell']} | {Path(r['clip']).name} | {Path(r['robot']).name} "
            f"| {r['settings'] or '–'} | {r['seed']} | {_fmt(r['scale_reached'], 'g')} "
            f"| {judged} | {_fmt(r['survived'])} | {_fmt(r['progress_min'], '.2f')} "
            f"| {_fmt(r['distance_m'], '.2f')} "
            f"| {_fmt(r['learn_sim_s'], '.0f')}, {_fmt(r['learn_wall_s'], '.0f')} "
            f"| {r['status']} |"
        )
    lines += [
        "",
        f"Robots judged on protocol {rows[0]['protocol']!r} for {rows[0]['seconds']:g} s each."
        if rows
        else "",
    ]
    return "\n".join(lines) + "\n"


def write_results(rows: list[dict[str, Any]], out: Path, cells: int) -> None:
    """Write the table and the page of ``rows`` (in cell order) into ``out``."""
    text = _csv(rows)
    atomic_write(out / "results.csv", lambda tmp: tmp.write_text(text))
    atomic_write(out / "results.parquet", lambda tmp: _parquet(rows, tmp))
    page = _summary(rows, cells)
    atomic_write(out / "summary.md", lambda tmp: tmp.write_text(page))
