"""Judging controllers on a robustness protocol: every controller on the same robots.

:func:`judge_controllers` draws ``seeds`` robots from a
:class:`~imitwalk.sim.protocol.Protocol` (the robot population) and walks each
controller (anything :class:`Judged`: it walks a robot and measures the walk) on every
one of them, for ``seconds`` from standing; :func:`judge_protocol` does so for the
controllers a run folder can build (:class:`RunController`). Per controller it reports
survival with its 95 % Wilson interval, distance, speed and mean |yaw| drift, and the
falls broken down by the factor each robot drew furthest from nominal (and, if asked, by
the factors whose removal alone saves it: :mod:`imitwalk.judge.explain`); every
controller is compared with open loop on the same robots by the paired McNemar test.
Robot ``s`` is the same robot whatever the controller, so the comparison is paired.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol as Interface

import numpy as np

from imitwalk.errors import ConfigError, unknown_name
from imitwalk.judge.explain import explain_falls
from imitwalk.judge.records import (
    ControllerVerdict,
    JudgeSettings,
    ProtocolId,
    ProtocolVerdict,
    SeedRow,
)
from imitwalk.judge.replay import OPEN_LOOP, LoadedRun, load_run
from imitwalk.paper.evaluate import compare_falls, wilson
from imitwalk.parallel import run_parallel
from imitwalk.robots import Robot
from imitwalk.runs import RunDir
from imitwalk.sim.metrics import WalkMetrics, walk_metrics
from imitwalk.sim.protocol import Protocol, RobotDraw
from imitwalk.sim.types import SimOptions

__all__ = [
    "JudgeJob",
    "Judged",
    "JudgedRobot",
    "RobotWalk",
    "RunController",
    "judge_controllers",
    "judge_protocol",
    "run_controller",
]


class Judged(Interface):
    """A controller the judge walks: picklable (it crosses to worker processes), it walks
    ``robot`` simulated with ``options`` on ``engine`` for ``seconds`` [s] from standing
    and measures the walk."""

    def walk(
        self, robot: Robot, options: SimOptions, seconds: float, engine: str
    ) -> WalkMetrics: ...


@dataclass(frozen=True)
class JudgedRobot:
    """The robot a verdict was judged on, as ``imitwalk evaluate`` records it beside the
    verdict (``"robot"`` in ``protocol_NAME.json`` and ``push_recovery.json``).

    Attributes:
        name: the robot's name (:attr:`~imitwalk.robots.Robot.name`); robot: as the
        command named it, a built-in name or its file's absolute path; joint_map: the
        joint map given beside an MJCF, as an absolute path (``None``: none).
    """

    name: str
    robot: str
    joint_map: str | None = None


@dataclass(frozen=True)
class JudgeJob:
    """One controller on one robot of a protocol (runs in a worker process).

    Attributes:
        controller: its name in the verdict (``open_loop``, ``learned``); walker: what
        walks (:class:`Judged`); robot: the robot; seed: the protocol's robot; options:
        that robot's simulation; furthest: the factor it drew furthest from nominal;
        seconds: simulated time [s]; engine: the physics engine.
    """

    controller: str
    walker: Judged
    robot: Robot
    seed: int
    options: SimOptions
    furthest: str | None
    seconds: float
    engine: str


@dataclass(frozen=True)
class RobotWalk:
    """What :func:`run_controller` measured: the robot's seed, the factor it drew furthest
    from nominal, and its walk."""

    seed: int
    furthest: str | None
    metrics: WalkMetrics

    def row(self, saved_by: tuple[str, ...] | None = None) -> SeedRow:
        """Its row in a verdict (``saved_by``: its fall explained, see
        :func:`~imitwalk.judge.explain.explain_falls`)."""
        m = self.metrics
        return SeedRow(
            self.seed,
            m.fell,
            m.fall_time_s,
            m.forward_distance_m,
            self.furthest,
            m.yaw_drift_deg,
            saved_by,
        )


_CACHE: dict[tuple[str, int], LoadedRun] = {}


def _loaded(run_dir: str) -> LoadedRun:
    metrics = RunDir(run_dir).file("metrics.json")  # load_run refuses a folder without one
    key = (run_dir, metrics.stat().st_mtime_ns if metrics.is_file() else -1)
    if key not in _CACHE:
        _CACHE.clear()
        _CACHE[key] = load_run(run_dir)
    return _CACHE[key]


@dataclass(frozen=True)
class RunController:
    """Controller ``name`` of the run folder ``run_dir`` (:class:`Judged`), at the stride
    ``scale`` (``None``: the scale the run reached)."""

    run_dir: str
    name: str
    scale: float | None = None

    def walk(self, robot: Robot, options: SimOptions, seconds: float, engine: str) -> WalkMetrics:
        """Walk it on ``robot``; its progress is judged against its reference or style."""
        from imitwalk.sim.mujoco import make_plant, run

        lr = _loaded(self.run_dir)
        scale = lr.scale if self.scale is None else self.scale
        ref = lr.ref
        policy = lr.policy(self.name, robot, scale, seconds)
        plant = make_plant(robot, ref.sim_options(options), engine)
        ro = run(plant, policy, round(seconds / ref.dt))
        # progress over the whole judged walk, so that an early fall scores the share of it
        # made (about 0), not its fall over the few millimetres commanded before it
        return walk_metrics(
            ro,
            ref.expected_distance(scale, seconds),
            ref.trajectory(scale, seconds),
            ref.track(scale, seconds),
        )


def run_controller(job: JudgeJob) -> RobotWalk:
    """Walk ``job``'s controller on its robot; its walk metrics, seed and furthest factor."""
    m = job.walker.walk(job.robot, job.options, job.seconds, job.engine)
    return RobotWalk(job.seed, job.furthest, m)


def _side(
    runs: list[RobotWalk], factors: Collection[str], saved: dict[int, tuple] | None = None
) -> ControllerVerdict:
    """One controller's verdict (``saved``: seed → the factors saving its fall, if
    the falls were explained)."""
    n = len(runs)
    ms = [r.metrics for r in runs]
    falls = int(sum(m.fell for m in ms))
    by = {f: 0 for f in factors}
    for r in runs:
        if r.metrics.fell and r.furthest is not None:
            by[r.furthest] = by.get(r.furthest, 0) + 1

    def mean(xs: list[float]) -> float | None:
        return float(np.mean(xs)) if runs else None

    lo, hi = wilson(n - falls, n)
    return ControllerVerdict(
        robots=n,
        survived=n - falls,
        falls=falls,
        survival=(n - falls) / n if n else 0.0,
        survival_ci95=(float(lo), float(hi)),
        distance_m=mean([m.forward_distance_m for m in ms]),
        speed_mps=mean([m.forward_speed_mps for m in ms]),
        abs_yaw_deg=mean([abs(m.yaw_drift_deg) for m in ms]),
        progress_ratio_min=float(min(m.progress_ratio for m in ms)) if runs else None,
        falls_by_furthest_factor=by,
        per_seed=tuple(r.row(None if saved is None else saved.get(r.seed)) for r in runs),
        falls_saved_by_factor=None
        if saved is None
        else {f: sum(f in s for s in saved.values()) for f in factors},
        falls_no_single_factor=None if saved is None else sum(not s for s in saved.values()),
    )


def judge_protocol(
    run_dir: str | Path,
    robot: Robot,
    protocol: Protocol,
    seeds: int = 40,
    seconds: float = 30.0,
    controllers: tuple[str, ...] | None = None,
    scale: float | None = None,
    workers: int | None = None,
    explain: bool = False,
    first: int = 0,
    most_falls: int | None = None,
) -> ProtocolVerdict:
    """Every controller in ``controllers`` that the run at ``run_dir`` builds (``None``:
    every one it can) judged by :func:`judge_controllers`, at the stride ``scale``
    (``None``: the one the run reached); a controller that is an exact copy of another
    (:meth:`~imitwalk.judge.replay.LoadedRun.twin`) is walked once.

    Raises:
        ConfigError: ``seeds`` under 1 or ``first`` under 0 (before the run is read), or a
            controller the run cannot build.
    """
    _check_robots(seeds, first)
    loaded = _loaded(str(run_dir))
    names = _checked_controllers(loaded, controllers)
    twins = {c: loaded.twin(c) for c in names}
    walkers = {t: RunController(str(run_dir), t, scale) for t in dict.fromkeys(twins.values())}
    at = scale if scale is not None else loaded.metrics.scale_reached
    return judge_controllers(
        walkers, robot, protocol, seeds, seconds, at, workers, explain, first, most_falls, twins
    )


def judge_controllers(
    controllers: Mapping[str, Judged],
    robot: Robot,
    protocol: Protocol,
    seeds: int = 40,
    seconds: float = 30.0,
    scale: float | None = None,
    workers: int | None = None,
    explain: bool = False,
    first: int = 0,
    most_falls: int | None = None,
    twins: Mapping[str, str] | None = None,
) -> ProtocolVerdict:
    """Every controller (name → :class:`Judged`) on robots ``first … first + seeds − 1``
    of ``protocol``: a :class:`ControllerVerdict` per controller, and each one's falls
    compared with open loop's (or, without it, ``default``'s) on the same robots
    (McNemar). ``scale`` is reported as the stride the controllers walk at. ``explain``:
    also walk each fall again once per factor, that factor at nominal
    (:func:`~imitwalk.judge.explain.explain_falls`). ``first`` > 0 judges robots that
    evaluation does not, e.g. training robots (1001 on) or validation robots (300 000
    on). ``most_falls`` (one controller only): stop once more robots than that fell; the
    verdict is then on the robots walked, in seed order (fewer than ``seeds``).
    ``twins``: name → the name of the controller walked in its place (an exact copy; by
    default each walks itself).

    Raises:
        ConfigError: ``seeds`` under 1 (or not a whole number) or ``first`` under 0.
    """
    _check_robots(seeds, first)
    twin = dict(twins) if twins is not None else {c: c for c in controllers}
    names = tuple(twin)
    draws = [protocol.draw(first + s, robot, seconds=seconds) for s in range(seeds)]
    jobs = _jobs(controllers, robot, protocol, draws, twin, seconds)
    stop = _stop(names, most_falls)
    res = run_parallel(run_controller, jobs, workers, stop=stop)
    jobs = jobs[: len(res)]  # the robots walked
    by = {c: [r for r, j in zip(res, jobs, strict=True) if j.controller == twin[c]] for c in names}
    saved: dict[str, dict[int, tuple[str, ...]] | None] = dict.fromkeys(names)
    if explain:
        why = explain_falls(run_controller, jobs, res, protocol, robot, seconds, workers)
        for c in names:
            saved[c] = {s: v for (cc, s), v in why.items() if cc == twin[c]}
    return ProtocolVerdict(
        protocol=ProtocolId(protocol.name, protocol.version, protocol.path),
        settings=JudgeSettings(
            seeds=seeds,
            first=first,
            seconds=seconds,
            engine=protocol.engine,
            scale=scale,
            controllers=names,
        ),
        controllers={c: _side(runs, protocol.factors, saved[c]) for c, runs in by.items()},
        comparison=_comparison(by, names),
    )


def _check_robots(seeds: object, first: int) -> None:
    """Refuse a count of robots to judge that is not a whole number >= 1, or a first robot
    under 0."""
    if isinstance(seeds, bool) or not isinstance(seeds, int | np.integer) or seeds < 1:
        raise ConfigError(f"seeds {seeds!r}: expected a whole number of robots >= 1")
    if first < 0:
        raise ConfigError(f"first robot {first}: valid robots are 0 and up")


def _checked_controllers(loaded: LoadedRun, controllers: tuple[str, ...] | None) -> tuple[str, ...]:
    """``controllers`` (``None``: every one ``loaded`` can build); refuses one it cannot."""
    valid = loaded.controllers()
    controllers = valid if controllers is None else tuple(controllers)
    for c in controllers:
        if c not in valid:
            raise unknown_name("controller", c, valid, ConfigError)
    return controllers


def _jobs(
    controllers: Mapping[str, Judged],
    robot: Robot,
    protocol: Protocol,
    draws: list[RobotDraw],
    twin: dict[str, str],
    seconds: float,
) -> list[JudgeJob]:
    """One job per distinct controller (``twin``: each one's exact copy walked in its
    place) and drawn robot, in that order, each walking ``seconds`` [s]."""
    return [
        JudgeJob(c, controllers[c], robot, d.seed, d.options, d.furthest, seconds, protocol.engine)
        for c in dict.fromkeys(twin.values())  # exact copies walk once
        for d in draws
    ]


def _stop(
    controllers: tuple[str, ...], most_falls: int | None
) -> Callable[[list[RobotWalk]], bool] | None:
    """``stop(done)`` for :func:`~imitwalk.parallel.run_parallel`: true once more than
    ``most_falls`` robots fell (one controller only); ``None``: walk every robot."""
    if most_falls is None:
        return None
    if len(controllers) != 1:
        raise ConfigError(f"most_falls needs one controller, not {len(controllers)}")
    return lambda done: sum(r.metrics.fell for r in done) > most_falls


def _comparison(by: dict[str, list[RobotWalk]], controllers: tuple[str, ...]) -> dict:
    """Each controller's falls against open loop's on the same robots, paired (McNemar);
    a stepping run, which has no open loop, against its shipped gains, ``default``."""
    comparison = {}
    against = OPEN_LOOP if OPEN_LOOP in by else ("default" if "default" in by else None)
    if against is not None:
        base = [r.metrics.fell for r in by[against]]
        for c in controllers:
            if c != against:
                comparison[c] = compare_falls([r.metrics.fell for r in by[c]], base)
    return comparison
