"""Process-parallel map for independent simulations (one worker per core by default)."""

from __future__ import annotations

import os
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor

__all__ = ["run_parallel"]


def run_parallel(fn: Callable, jobs: list, workers: int | None = None) -> list:
    """``[fn(j) for j in jobs]``, in worker processes when there is more than one.

    Results come back in job order and do not depend on the number of workers.
    ``IMITWALK_WORKERS`` overrides the default worker count.
    """
    default = int(os.environ.get("IMITWALK_WORKERS", 0)) or os.cpu_count() or 1
    workers = min(len(jobs), workers or default)
    if workers <= 1:
        return [fn(j) for j in jobs]
    with ProcessPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(fn, jobs))
