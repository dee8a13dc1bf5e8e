"""``imitwalk sweep CONFIG``: clips × robots × settings × seeds, learned and judged on Ray."""

from __future__ import annotations

import argparse

from imitwalk.cli.progress import emit, progress

__all__ = ["add_parser", "sweep"]


def sweep(args: argparse.Namespace) -> int:
    from imitwalk.sweep.config import load_sweep
    from imitwalk.sweep.runner import run_sweep

    cfg = load_sweep(args.config)
    n = len(cfg.cells())
    where = f"a local Ray of {args.workers} CPUs"
    if args.address:
        where = f"the Ray cluster at {args.address}"
    progress(f"sweep: {n} cells into {args.out}, on {where}")
    res = run_sweep(cfg, args.out, args.address, args.workers, show_progress=not args.json)
    progress(f"sweep: {res.ran} run, {res.kept} kept from before, {res.refused} refused")
    emit(
        {
            "out": res.out,
            "cells": res.cells,
            "ran": res.ran,
            "kept": res.kept,
            "refused": res.refused,
            "table": f"{res.out}/results.csv",
            "summary": f"{res.out}/summary.md",
        },
        args.json,
    )
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """The ``sweep`` subcommand's arguments."""
    p = sub.add_parser(
        "sweep", help="learn and judge clips x robots x settings x seeds on Ray (resumable)"
    )
    p.add_argument(
        "config", help="the sweep's .toml or .json (clips, robots, settings, seeds, ...)"
    )
    p.add_argument("--out", required=True, help="the sweep's folder (run again to resume)")
    p.add_argument("--address", default=None, help="a Ray cluster (default: a local Ray)")
    p.add_argument("--workers", type=int, default=2, help="a local Ray's CPUs (2)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=sweep)
