"""One episode of the per-tick controller on one training robot, and its record.

The learner (:mod:`imitwalk.balance.ticklearn`) runs many of these in parallel
(:func:`imitwalk.parallel.run_parallel`); only the simulator steps the physics.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from imitwalk.balance.feedback import Episode, FeedbackLaw, TickPolicy
from imitwalk.balance.ticklog import WalkSummary
from imitwalk.parallel import abandoned
from imitwalk.robots import Robot
from imitwalk.sim.metrics import WalkMetrics
from imitwalk.sim.types import SimOptions

if TYPE_CHECKING:
    from imitwalk.retarget.reference import Reference
    from imitwalk.sim.types import Rollout

__all__ = [
    "TickJob",
    "TickResult",
    "Trial",
    "best",
    "blind",
    "most_falls",
    "run_tick_episode",
    "summarize",
    "tick_walk_metrics",
]


@dataclass(frozen=True)
class TickJob:
    """One episode.

    Attributes:
        ref_path: the reference (``.npz``); robot: the robot; scale: stride scale;
        laws: the feedback laws (their outputs add up); seed: the training robot;
        options: its simulation; seconds: simulated time [s]; explore: exploration
        amplitude [rad] on the last law; rng: the exploration's seed; engine: the
        physics engine; record: return the recorded episode; feedforward: the fraction
        of the servo feedforward added to the reference (0: none); wait: the load share
        above which the reference waits before a lift-off (0: never;
        :class:`~imitwalk.balance.feedback.TickPolicy`).
    """

    ref_path: str
    robot: Robot
    scale: float
    laws: tuple[FeedbackLaw, ...]
    seed: int
    options: SimOptions
    seconds: float
    explore: float = 0.0
    rng: tuple[int, ...] = (0,)
    engine: str = "mujoco"
    record: bool = True
    feedforward: float = 0.0
    wait: float = 0.0


@dataclass(frozen=True)
class TickResult:
    """What one episode gave.

    Attributes:
        seed: the training robot; fell: whether it fell; fall_time_s: when [s];
        seconds: simulated time [s]; distance_m: forward travel [m]; yaw_drift_deg;
        cost: the measured eq.-6 cost Γ, the mean of |gyro|² over the walk [rad²/s²];
        episode: the recorded ticks (``None`` unless asked for).
    """

    seed: int
    fell: bool
    fall_time_s: float | None
    seconds: float
    distance_m: float
    yaw_drift_deg: float
    cost: float
    episode: Episode | None = None


_REFS: dict = {}


def _reference(path: str) -> Reference:
    from imitwalk.retarget.reference import Reference

    if path not in _REFS:
        _REFS.clear()
        _REFS[path] = Reference.load(path)
    return _REFS[path]


def _walk(
    job: TickJob, ref: Reference | None = None
) -> tuple[Reference, TickPolicy, Rollout, WalkMetrics]:
    """Walk ``job`` on ``ref`` (``None``: the reference at ``job.ref_path``): its reference,
    policy, rollout and metrics."""
    from imitwalk.retarget.feedforward import walk_offsets
    from imitwalk.sim.metrics import walk_metrics
    from imitwalk.sim.mujoco import make_plant, run

    ref = ref if ref is not None else _reference(job.ref_path)
    offsets = walk_offsets(ref, job.robot, job.scale, job.seconds, job.feedforward)
    names = job.robot.joint_names
    policy = TickPolicy(
        ref,
        job.scale,
        job.laws,
        names,
        job.seconds,
        job.explore,
        seed=job.rng,
        offsets=offsets,
        wait=job.wait,
    )
    plant = make_plant(job.robot, ref.sim_options(job.options), job.engine)
    ro = run(plant, policy, len(policy.q_ref), abandon=abandoned)
    m = walk_metrics(
        ro,
        ref.expected_distance(job.scale, ro.seconds),
        policy.q_ref,
        ref.track(job.scale, ro.seconds),
    )
    return ref, policy, ro, m


def tick_walk_metrics(job: TickJob, ref: Reference) -> WalkMetrics:
    """The :class:`~imitwalk.sim.metrics.WalkMetrics` of walking ``job`` on ``ref``, a
    :class:`~imitwalk.retarget.reference.Reference` in memory (``job.ref_path`` unused),
    in the calling process."""
    return _walk(job, ref)[3]


def run_tick_episode(job: TickJob) -> TickResult:
    """Walk ``job``'s laws on its robot (runs in a worker process); a walk its map no
    longer needs (:func:`~imitwalk.parallel.abandoned`) ends there, its seconds paid."""
    ref, policy, ro, m = _walk(job)
    walk = ro.gyro[ref.starts.shape[1] - ref.loops.shape[1] :]  # from the last start-up cycle
    cost = float(np.mean(np.sum(walk**2, axis=1))) if len(walk) else float("inf")
    return TickResult(
        seed=job.seed,
        fell=m.fell,
        fall_time_s=m.fall_time_s,
        seconds=m.seconds,
        distance_m=m.forward_distance_m,
        yaw_drift_deg=m.yaw_drift_deg,
        cost=cost if not m.fell else float("inf"),
        episode=policy.episode() if job.record else None,
    )


def summarize(results: list[TickResult]) -> WalkSummary:
    """:class:`WalkSummary` of ``results`` (over no walks: no falls, the means 0)."""
    up = [r for r in results if not r.fell]
    mean = lambda xs: float(np.mean(xs)) if xs else 0.0  # noqa: E731  (no walks: 0)
    yaws = [abs(r.yaw_drift_deg) for r in results]
    se = float(np.std(yaws, ddof=1) / np.sqrt(len(yaws))) if len(yaws) > 1 else 0.0
    return WalkSummary(
        falls=int(sum(r.fell for r in results)),
        robots=len(results),
        cost=mean([r.cost for r in up]) if up else float("inf"),
        walked_s=float(sum(r.seconds for r in results)),
        distance_m=mean([r.distance_m for r in results]),
        abs_yaw_deg=mean(yaws),
        abs_yaw_se_deg=se,
    )


@dataclass(frozen=True)
class Trial:
    """One candidate's walks at the trial scale, on the training robots: ``results``, the
    first of ``robots`` planned ones (``None``: all of them; fewer once a candidate that
    can no longer be kept was stopped, :func:`~imitwalk.balance.ticktrials.trial`)."""

    results: list
    robots: int | None = None

    def rank(self, value: float, yaw_limit_deg: float | None = None) -> tuple:
        """The order candidates are kept in (least first): the fewest falls; then, where
        the heading drift limits the gain (``yaw_limit_deg``), the least mean |yaw| [deg]
        plus one standard error beyond that limit (a few robots' mean misses the limit
        about half the time where it lands just under it: on the default clip eval's
        robots spread by 10° and six of them keep a mean within ±4°, docs/RESULTS.md);
        where every planned robot fell, the longest walked; then the smallest
        ``|value|``. A lower Γ does not outrank the simpler law: measured, higher gains
        lower Γ right up to the gain where robots start to fall (docs/RESULTS.md)."""
        s = self.summary()
        bound = s.abs_yaw_deg + s.abs_yaw_se_deg
        drift = 0.0 if yaw_limit_deg is None else max(0.0, bound - yaw_limit_deg)
        planned = s.robots if self.robots is None else self.robots
        walked = -s.walked_s if s.falls == planned else 0.0
        return (s.falls, drift, walked, abs(value))

    def summary(self) -> WalkSummary:
        """:func:`summarize` of its walks."""
        return summarize(self.results)


def best(table: list, yaw_limit_deg: float | None = None) -> tuple[float, Trial]:
    """The row ``(value, Trial)`` of ``table`` that is kept (:meth:`Trial.rank`)."""
    return min(table, key=lambda row: row[1].rank(row[0], yaw_limit_deg))


def blind(table: list) -> bool:
    """Whether every candidate of ``table`` (rows ``(value, Trial)``) fell on every one
    of its planned robots: the trials could then rank them only by the time walked, which
    at a scale no candidate can walk says little (on G1 it picked a tilt gain that fell
    every evaluation robot at 0.3, where trials at 0.3 refuse it)."""
    return len(table) > 1 and all(
        t.robots is not None and len(t.results) == t.robots and t.summary().falls == t.robots
        for _, t in table
    )


def most_falls(table: list, value: float, yaw_limit_deg: float | None = None) -> int | None:
    """The most falls a candidate ``value`` may have and still be kept, against the rows
    ``(value, Trial)`` of ``table`` so far (``None`` for an empty table: no limit).

    :meth:`Trial.rank` orders by falls first, so a candidate is out once it has fallen
    more often than the best row. A tie loses too where the rest of the rank already
    favours the best row: not every one of its robots fell, it kept the heading's drift
    within ``yaw_limit_deg``, and its ``|value|`` is the smaller. Then the most is one
    fall fewer, and against a best row with no falls the candidate is not walked at all
    (it could at best tie, and lose on the smaller value)."""
    if not table:
        return None
    v, t = best(table, yaw_limit_deg)
    falls, drift, walked, _ = t.rank(v, yaw_limit_deg)
    ties_lose = drift == 0.0 and walked == 0.0 and abs(value) > abs(v)
    return falls - 1 if ties_lose else falls
