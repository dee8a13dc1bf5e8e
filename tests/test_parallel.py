"""The parallel map gives the same results on every executor."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest

from imitwalk.errors import ConfigError
from imitwalk.parallel import abandoned, run_parallel


def _square(x: int) -> int:
    return x * x


def test_process_pool_keeps_job_order():
    assert run_parallel(_square, list(range(7)), workers=2) == [x * x for x in range(7)]
    assert run_parallel(_square, list(range(3)), workers=1) == [0, 1, 4]


def _mark(job: tuple) -> int:
    """Square ``x`` after a short wait, and leave a file saying that job ``x`` ran."""
    folder, x = job
    time.sleep(0.05)
    (folder / f"{x}.ran").touch()
    return x * x


def test_a_map_with_stop_returns_the_shortest_prefix_it_accepts_and_skips_the_rest(tmp_path):
    def stop(squares):
        return sum(squares) > 10  # 0 + 1 + 4 + 9

    for workers in (1, 2):
        folder = tmp_path / str(workers)
        folder.mkdir()
        jobs = [(folder, x) for x in range(40)]
        assert run_parallel(_mark, jobs, workers=workers, stop=stop) == [0, 1, 4, 9]
        ran = len(list(folder.iterdir()))
        assert 4 <= ran <= 4 + workers - 1  # at most one job per other worker ran beyond it
    assert run_parallel(_square, [0, 1, 2], workers=2, stop=stop) == [0, 1, 4]  # never held


def test_a_stopped_map_hands_back_every_job_that_ran_beyond_its_prefix(tmp_path):
    """What ran and was not returned is paid for: ``spent`` gets exactly those jobs."""
    for workers in (1, 2):
        folder = tmp_path / str(workers)
        folder.mkdir()
        spent: list = []
        out = run_parallel(
            _mark, [(folder, x) for x in range(40)], workers, lambda s: len(s) == 4, spent
        )
        ran = sorted(int(p.stem) for p in folder.iterdir())
        assert out == [0, 1, 4, 9]
        assert [x * x for x in ran[4:]] == spent  # in job order


def _long_unless_abandoned(x: int) -> tuple[int, int]:
    """``(x, ticks)``: jobs from 4 on tick 100 times unless abandoned first (job 3 waits
    long enough for job 4 to have started)."""
    time.sleep(0.3 if x == 3 else 0.0)
    ticks = 0
    while x >= 4 and ticks < 100 and not abandoned():
        time.sleep(0.01)
        ticks += 1
    return x, ticks


def test_the_jobs_running_beyond_a_stopped_maps_prefix_see_that_they_are_abandoned():
    """What runs beyond the prefix may end early: it is paid for, not used."""
    assert not abandoned()  # outside a worker
    spent: list = []
    out = run_parallel(_long_unless_abandoned, list(range(40)), 2, lambda s: len(s) == 4, spent)
    assert out == [(x, 0) for x in range(4)]
    assert [x for x, _ in spent] == [4]  # the one job started beyond the prefix ...
    assert spent[0][1] < 100  # ... ended early
    full = run_parallel(_long_unless_abandoned, [4, 5], 2)  # no stop: every job runs out
    assert full == [(4, 100), (5, 100)]


_INTERRUPTED = """
import pathlib, signal, sys, time
from imitwalk.parallel import run_parallel

# as a terminal's Ctrl-C finds it: a shell that ran the tests in the background left
# SIGINT ignored, and Python then installs no KeyboardInterrupt
signal.signal(signal.SIGINT, signal.default_int_handler)

def job(x):
    time.sleep(0.1)
    (pathlib.Path(sys.argv[1]) / str(x)).touch()
    return x

if __name__ == "__main__":
    try:
        print("start", flush=True)
        run_parallel(job, list(range(200)), workers=2,
                     stop=(lambda out: False) if sys.argv[2] == "stop" else None)
    except KeyboardInterrupt:
        sys.exit(130)
"""


@pytest.mark.parametrize("mode", ["map", "stop"])
def test_ctrl_c_cancels_the_jobs_not_started_and_leaves_no_worker(tmp_path, mode):
    """Ctrl-C reaches the whole process group, at any moment of a map: the parent raises
    KeyboardInterrupt, the jobs not yet started never run, and no worker is left behind
    (an idle worker interrupted while it waited for a job used to hang the pool)."""
    script = tmp_path / "run.py"
    script.write_text(_INTERRUPTED)
    for delay in (0.0, 0.002, 0.01, 0.05, 0.3):
        folder = tmp_path / f"{delay}"
        folder.mkdir()
        p = subprocess.Popen(
            [sys.executable, str(script), str(folder), mode],
            stdout=subprocess.PIPE,
            text=True,
            start_new_session=True,
        )
        assert p.stdout is not None and p.stdout.readline().strip() == "start"
        time.sleep(delay)
        os.killpg(p.pid, signal.SIGINT)
        try:
            assert p.wait(timeout=120) == 130
        finally:
            ran = len(list(folder.iterdir()))
            try:
                os.killpg(p.pid, signal.SIGKILL)
                left = True
            except ProcessLookupError:
                left = False
        assert ran < 200 and not left, (delay, ran, left)


def test_unknown_executor_lists_the_valid_ones(monkeypatch):
    monkeypatch.setenv("IMITWALK_EXECUTOR", "dask")
    with pytest.raises(ConfigError, match="valid: process, ray"):
        run_parallel(_square, [1, 2])


@pytest.mark.slow
def test_ray_executor_runs_a_playback_sweep(monkeypatch, tiny_reference, robot):
    pytest.importorskip("ray")
    import ray

    from imitwalk.retarget.playback import play_reference

    ref, _ = tiny_reference
    local = play_reference(ref, robot, 0.3, 2.0, [0, 1], workers=1)
    monkeypatch.setenv("IMITWALK_EXECUTOR", "ray")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        remote = play_reference(ref, robot, 0.3, 2.0, [0, 1])
        first = play_reference(ref, robot, 0.3, 2.0, [0, 1], stop=lambda runs: True)
    finally:
        ray.shutdown()
    assert [r.metrics for r in remote] == [r.metrics for r in local]
    assert [r.metrics for r in first] == [local[0].metrics]
