"""Parallel map for independent simulations: local processes, or a Ray cluster.

Every evaluation, search and training iteration runs independent simulations through
:func:`run_parallel`. By default they go to a local process pool (one worker per core);
with ``IMITWALK_EXECUTOR=ray`` (and ``pip install 'imitwalk[ray]'``) they become Ray
tasks, so a sweep scales out to whatever cluster ``ray.init`` connects to
(``RAY_ADDRESS``, or a local one). Results come back in job order and do not depend on
the executor or the number of workers.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor

from imitwalk.errors import ConfigError, unknown_name

__all__ = ["EXECUTORS", "run_parallel"]

EXECUTORS = ("process", "ray")


def run_parallel(fn: Callable, jobs: list, workers: int | None = None) -> list:
    """``[fn(j) for j in jobs]`` on the configured executor.

    ``IMITWALK_WORKERS`` overrides the default worker count (one per core) of the process
    pool; ``workers=1`` (or a single job) runs in this process.
    """
    executor = os.environ.get("IMITWALK_EXECUTOR", "process")
    if executor not in EXECUTORS:
        raise unknown_name("IMITWALK_EXECUTOR", executor, EXECUTORS, ConfigError)
    if executor == "ray" and len(jobs) > 1 and workers != 1:
        return _ray_map(fn, jobs)
    default = int(os.environ.get("IMITWALK_WORKERS", 0)) or os.cpu_count() or 1
    workers = min(len(jobs), workers or default)
    if workers <= 1:
        return [fn(j) for j in jobs]
    with ProcessPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(fn, jobs))


def _ray_map(fn: Callable, jobs: list) -> list:
    try:
        import ray
    except ImportError:
        raise ConfigError("IMITWALK_EXECUTOR=ray needs Ray: pip install 'imitwalk[ray]'") from None
    if not ray.is_initialized():
        ray.init(
            address=os.environ.get("RAY_ADDRESS"),
            include_dashboard=False,
            log_to_driver=False,
            configure_logging=False,
        )
    task = ray.remote(fn)
    return ray.get([task.remote(j) for j in jobs])
