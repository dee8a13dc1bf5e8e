"""Every benchmark runs: each script of ``bench/`` and each fuzz helper's command line
(``python -m tests.helpers.fuzz_<x>``), on a tiny budget (one or two robots, a second or
three of simulated time, one repetition), in a fresh interpreter from the repository root.
Each must exit with status 0 and print the JSON its docstring documents, with its
top-level keys. The figures themselves (and any wall time) are not checked: the scripts
measure, BENCHMARKS.md reports.

The learned run is the tiny stepping run of ``conftest.step_run``; the reference is
``conftest.tick_reference`` (every grid scale, no search; ``trial_rules`` walks scale 1).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from imitwalk.cli.main import main

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[1]

#: Per benchmark: its command (``{run}``, ``{export}``, ``{reference}``, ``{out}``: the
#: fixtures' paths) and the top-level keys of its JSON (of each item, for a list).
BENCHES = {
    "controller_loop": (
        ["bench/controller_loop.py", "{run}", "--seconds", "1", "--repeat", "1"],
        {"run", "learner", "seconds", "machine", "bare_mj_step_per_s", "controllers"},
    ),
    "engine_speed": (
        ["bench/engine_speed.py", "--seconds", "1", "--repeat", "1"],
        {
            "sim_seconds",
            "scale",
            "wall_s_per_sim_s",
            "bullet_over_mujoco",
            "fell",
            "forward_m",
            "joint_rms_diff_rad",
            "sole_force_mean_N",
        },
    ),
    "env_speed": (
        ["bench/env_speed.py", "--seconds", "0.5", "--repeat", "1"],
        {
            "unit",
            "one_core",
            "one_core_over_bare",
            "two_cores",
            "two_cores_over_bare",
            "env_steps_per_second",
            "seconds",
            "repeat",
            "machine",
        },
    ),
    "imitation": (
        ["bench/imitation.py", "{run}", "--seconds", "2"],
        {"clip", "fell", "human", "style", "robot", "ratios"},
    ),
    "judge_training": (
        ["bench/judge_training.py", "{run}", "--robots", "1", "--seconds", "2"],
        {"first", "falls", "robots", "fell", "progress_min", "distance_m"},
    ),
    "learn_gains": (
        [
            *("bench/learn_gains.py", "{out}", "--generations", "1", "--population", "4"),
            *("--robots", "1", "--seconds", "1", "--final", "1"),
        ],
        {"gains", "shipped", "final", "sim_seconds", "wall_seconds"},
    ),
    "mpc_latency": (
        ["bench/mpc_latency.py", "--ticks", "10"],
        {"mode", "candidates", "median_ms", "p90_ms", "runs", "numpy", "sklearn", "cpu"},
    ),
    "paired": (
        [
            *("bench/paired.py", "{run}:learned", "{run}:default"),
            *("--seeds", "1", "--seconds", "2"),
        ],
        {"protocol", "seeds", "first", "seconds", "runs"},
    ),
    "parallel_speedup": (
        ["bench/parallel_speedup.py", "--models", "2", "--seconds", "1", "--repeat", "1"],
        {
            "models",
            "sim_seconds_each",
            "rollout_1_threads_s",
            "rollout_2_threads_s",
            "rollout_speedup",
            "pool_1_workers_s",
            "pool_2_workers_s",
            "pool_speedup",
        },
    ),
    "retarget_speed": (
        ["bench/retarget_speed.py", "--repeat", "1"],
        {"clip", "walkable_frames_per_s", "walkable_frames", "paper_mapping_frames_per_s"},
    ),
    "runtime_latency": (
        ["bench/runtime_latency.py", "{export}", "--seconds", "1", "--repeat", "1"],
        {
            "export",
            "controller",
            "rate_hz",
            "ticks",
            "step_ms_median",
            "step_ms_p90",
            "step_ms_p99",
            "budget_share_median",
        },
    ),
    "sim_speed": (
        ["bench/sim_speed.py", "--seconds", "1", "--repeat", "1"],
        {"robot", "dof", "mj_step_per_s", "plant_steps_per_s", "plant_over_bare"},
    ),
    # 3 s: the first planned swing starts after 2 s (the script needs one).
    "stride_realised": (
        ["bench/stride_realised.py", "{reference}", "--seconds", "3"],
        {"fell", "fall_time_s", "distance_m", "expected_m", "stride_m", "feet"},
    ),
    "trial_rules": (
        ["bench/trial_rules.py", "{reference}", "--robots", "1", "--seconds", "1"],
        {"reference", "first", "robots", "seconds", "protocol", "laws"},
    ),
    "turning": (
        ["bench/turning.py", "{run}", "--seeds", "1", "--seconds", "2"],
        {
            "run",
            "protocol",
            "robots",
            "falls",
            "clip_deg_per_cycle",
            "style_deg_per_cycle",
            "walked_deg_per_cycle",
            "within_20pct_of_clip",
            "robots_detail",
        },
    ),
}

#: The fuzz helpers' command lines: arguments, and the keys of each input's counts.
FUZZ = {
    "fuzz_files": (
        ["--cases", "3"],
        {"reference", "run", "out"},
        {"cases", "counts", "failures", "wall_seconds"},
    ),
    "fuzz_mocap": (
        ["--cases", "3", "--limit", "10"],
        {"bvh", "amc", "c3d", "deepmimic"},
        {
            "cases",
            "project_errors",
            "other_exceptions",
            "accepted",
            "accepted_implausible",
            "hangs",
            "wall_seconds",
            "failures",
        },
    ),
    "fuzz_robot": (
        ["--cases", "4", "--seed", "1", "--timeout", "20"],
        {"map", "mjcf"},
        {"project_error", "accepted", "other_exception", "hang"},
    ),
}


def _run(args: list[str], **env: str) -> str:
    """Stdout of ``python ARGS`` run from the repository root; fails on a non-zero exit."""
    proc = subprocess.run(
        [sys.executable, *args],
        cwd=ROOT,
        env={**os.environ, "MUJOCO_GL": "egl", **env},
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert proc.returncode == 0, f"{args} exited with {proc.returncode}:\n{proc.stderr[-4000:]}"
    return proc.stdout


def _json(stdout: str):
    """The JSON a benchmark prints last (``learn_gains`` prints its progress lines first)."""
    lines = stdout.splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith(("{", "[")))
    return json.loads("\n".join(lines[start:]))


@pytest.fixture(scope="module")
def export(step_run, tmp_path_factory) -> Path:
    """The tiny stepping run's learned controller, exported through the CLI."""
    out = tmp_path_factory.mktemp("bench-export") / "walk"
    assert main(["export", str(step_run), "--out", str(out)]) == 0
    return out


def test_every_bench_script_is_covered():
    assert {p.stem for p in (ROOT / "bench").glob("*.py")} == set(BENCHES)


@pytest.mark.parametrize("name", BENCHES)
def test_bench(name, request, tmp_path):
    argv, keys = BENCHES[name]
    paths = {"out": tmp_path / "out"}
    for fixture, key in (
        ("step_run", "run"),
        ("export", "export"),
        ("tick_reference", "reference"),
    ):
        if any("{" + key + "}" in a for a in argv):
            paths[key] = request.getfixturevalue(fixture)
    out = _json(_run([a.format(**paths) for a in argv]))
    for item in out if isinstance(out, list) else [out]:
        assert keys <= set(item), (name, sorted(keys - set(item)))
    if name == "paired":
        assert "vs_first" in out["runs"][argv[2].format(**paths)]


@pytest.mark.parametrize("name", FUZZ)
def test_fuzz_command_line(name, request):
    argv, inputs, keys = FUZZ[name]
    env = {}
    if name == "fuzz_mocap":
        env["IMITWALK_SHARED_MOCAP"] = str(request.getfixturevalue("shared_mocap"))
    out = json.loads(_run(["-m", f"tests.helpers.{name}", *argv], **env))
    if name == "fuzz_robot":
        assert {"cases", "seed", "timeout_s", "counts", "failures", "wall_seconds"} <= set(out)
    per_input = out["counts"] if name == "fuzz_robot" else out
    assert set(per_input) == inputs
    for counts in per_input.values():
        assert keys <= set(counts), (name, sorted(keys - set(counts)))
