"""Parallel map for independent simulations: local processes, or a Ray cluster.

Every evaluation, search and training iteration runs independent simulations through
:func:`run_parallel`. By default they go to a local process pool (one worker per core);
with ``IMITWALK_EXECUTOR=ray`` (and ``pip install 'imitwalk[ray]'``) they become Ray
tasks, so a sweep scales out to whatever cluster ``ray.init`` connects to
(``RAY_ADDRESS``, or a local one). Results come back in job order and do not depend on
the executor or the number of workers.

With ``stop``, a map can end early: results are taken in job order, and once ``stop``
holds for those taken so far, the jobs not yet started are cancelled and that prefix is
returned. Which prefix that is does not depend on the executor either. The process pool
then runs at most one job per worker ahead of the first result not yet taken, so that
at most ``workers - 1`` jobs beyond the prefix are paid for, and a job that asks
:func:`abandoned` as it goes can end those early.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import threading
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import Future, ProcessPoolExecutor
from contextlib import contextmanager
from typing import TYPE_CHECKING

from imitwalk.errors import ConfigError, unknown_name

if TYPE_CHECKING:
    import ctypes

__all__ = ["EXECUTORS", "abandoned", "run_parallel"]

EXECUTORS = ("process", "ray")

#: In a pool's worker: its map's shared flag, set to 1 once ``stop`` has held (``None``
#: elsewhere). A lock-free byte, since a job may read it every tick.
_ABANDONED: ctypes.c_byte | None = None


def abandoned() -> bool:
    """Whether the map running this job no longer needs its result: ``stop`` held on the
    results before it. A long job may ask this as it goes and end early, with whatever
    partial result it has (it goes to ``spent``). Always ``False`` outside a pool's
    worker, where every job runs to its end."""
    return _ABANDONED is not None and bool(_ABANDONED.value)


def run_parallel(
    fn: Callable,
    jobs: list,
    workers: int | None = None,
    stop: Callable | None = None,
    spent: list | None = None,
) -> list:
    """``[fn(j) for j in jobs]`` on the configured executor.

    ``IMITWALK_WORKERS`` overrides the default worker count (one per core) of the process
    pool; ``workers=1`` (or a single job) runs in this process. ``stop(results) -> bool``,
    if given, is asked after each result in job order; once it says True, the rest of
    the jobs are cancelled (those already running finish, unused) and the results so far
    are returned: the shortest prefix of ``[fn(j) for j in jobs]`` that ``stop`` accepts.
    With ``stop`` the process pool starts job ``k + workers`` only once job ``k``'s
    result is taken (a worker may wait on a slower job before it), so that no more than
    ``workers - 1`` jobs run beyond that prefix.
    ``spent``, if given, receives the results of the jobs beyond that prefix that ran all
    the same (unused, but paid for), in job order: to their end, or to where they saw
    :func:`abandoned`. Ctrl-C (sent to the
    whole process group, as a terminal does) raises ``KeyboardInterrupt`` here: the jobs
    not yet started are cancelled, the running ones end, and no worker is left behind.
    """
    executor = os.environ.get("IMITWALK_EXECUTOR", "process")
    if executor not in EXECUTORS:
        raise unknown_name("IMITWALK_EXECUTOR", executor, EXECUTORS, ConfigError)
    if executor == "ray" and len(jobs) > 1 and workers != 1:
        return _ray_map(fn, jobs, stop, spent)
    default = int(os.environ.get("IMITWALK_WORKERS", 0)) or os.cpu_count() or 1
    workers = min(len(jobs), workers or default)
    if workers <= 1:
        return _until(jobs, fn, stop)
    ahead = workers if stop is not None else len(jobs)  # jobs started beyond the first untaken
    futures: list = []
    pool: ProcessPoolExecutor | None = None

    # each next job is started only once the result before is taken
    def in_order() -> Iterator[Future]:
        assert pool is not None
        for k in range(len(jobs)):
            yield futures[k]
            if len(futures) < len(jobs):
                futures.append(pool.submit(fn, jobs[len(futures)]))

    try:
        # Ctrl-C is held while the pool starts: an interrupt then would orphan its workers,
        # and one raised in the imports a process's first map makes (ctypes, the locks,
        # the fork) would be lost, since Python ignores it in an import lock's clean-up
        with _ctrl_c_held():
            ctx = multiprocessing.get_context()
            done = ctx.RawValue("b", 0)
            pool = ProcessPoolExecutor(
                max_workers=workers, mp_context=ctx, initializer=_worker_init, initargs=(done,)
            )
            futures = [pool.submit(fn, j) for j in jobs[:ahead]]
        out = _until(in_order(), lambda f: f.result(), stop)
        done.value = 1  # the jobs still running may end early
        ran = [f for f in futures[len(out) :] if not f.cancel()]
        if spent is not None:
            spent.extend(f.result() for f in ran)
    except BaseException:  # Ctrl-C or a failed job: drop the jobs not yet started
        if pool is not None:
            done.value = 1
            for f in futures:
                f.cancel()
            pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown()
    return out


@contextmanager
def _ctrl_c_held() -> Iterator[None]:
    """Hold Ctrl-C (SIGINT) back in this thread until the block ends, where it is raised."""
    block = getattr(signal, "pthread_sigmask", None)
    if block is None or threading.current_thread() is not threading.main_thread():
        yield
        return
    old = block(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        block(signal.SIG_SETMASK, old)


def _worker_init(done: ctypes.c_byte) -> None:
    """A worker keeps its map's ``done`` flag (:func:`abandoned`) and ignores Ctrl-C: the
    parent cancels the jobs not yet started and the running ones end. (An idle worker
    interrupted while it waits for a job dies holding the pool's queue, and the pool then
    waits for it forever.)"""
    global _ABANDONED
    _ABANDONED = done
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _until(pending: Iterable, get: Callable, stop: Callable | None) -> list:
    """``[get(p) for p in pending]``, ended after the first prefix ``stop`` accepts."""
    out: list = []
    for p in pending:
        out.append(get(p))
        if stop is not None and stop(out):
            break
    return out


def _ray_map(fn: Callable, jobs: list, stop: Callable | None, spent: list | None) -> list:
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
    refs = [task.remote(j) for j in jobs]
    if stop is None:
        return ray.get(refs)
    out = _until(refs, ray.get, stop)
    for r in refs[len(out) :]:
        ray.cancel(r)
    if spent is not None:
        for r in refs[len(out) :]:
            try:
                spent.append(ray.get(r))
            except ray.exceptions.TaskCancelledError:
                pass  # cancelled before it ended: nothing was paid for it
    return out
