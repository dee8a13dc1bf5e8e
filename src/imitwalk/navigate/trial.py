"""A course walked by robots of a protocol, judged by the simulator's ground truth.

The robot steers by its own sensors (:class:`~imitwalk.navigate.navigator.Navigator`);
only the judging reads the truth: the torso's path on the floor in the frame the robot
started in, each waypoint counted as reached, in order, when that path first passes
within the course's ``reach`` of it. Many robots walk in parallel
(:func:`imitwalk.parallel.run_parallel`); only the simulator steps the physics.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from imitwalk.navigate.course import Course
from imitwalk.parallel import abandoned
from imitwalk.robots import Robot
from imitwalk.sim.fix import FixSensor, PositionFix
from imitwalk.sim.metrics import yaw_rad
from imitwalk.sim.types import Observation, Rollout, SimOptions
from imitwalk.step.gains import StepGains
from imitwalk.step.odometry import rot2
from imitwalk.step.style import GaitStyle

if TYPE_CHECKING:
    from imitwalk.navigate.navigator import Navigator

__all__ = ["NavJob", "NavResult", "run_nav_job", "start_frame", "truth_path", "walk_course"]

#: A walk ends this long after the robot believes it reached the last waypoint [s].
LINGER_S = 1.0


@dataclass(frozen=True)
class NavJob:
    """One robot walking a course.

    Attributes:
        robot: the robot; style: the walk; gains: the stepping gait's gains; course: the
        waypoints; seed: the robot's seed in its protocol; options: its simulation;
        seconds: the most it may take [s]; fix: a position fix, or ``None`` (dead
        reckoning); dt: the control period [s]; record: keep the walk's ``qpos`` in the
        result (for a video, so that the walk need not be simulated again).
    """

    robot: Robot
    style: GaitStyle
    gains: StepGains
    course: Course
    seed: int
    options: SimOptions
    seconds: float
    fix: PositionFix | None = None
    dt: float = 0.01
    record: bool = False


@dataclass(frozen=True)
class NavResult:
    """How one robot walked a course.

    Attributes:
        seed: the robot; fell, fall_time_s: whether and when it fell [s];
        reached_s: when each waypoint was reached, in order [s] (``None`` from the first
        missed on); closest_m: how near the path came to each waypoint [m];
        finish_s: when the last was reached [s] (``None``: not reached);
        odometry_error_m: the robot's own estimate of where it is, off the truth at the
        end [m]; path: ``(N, 2)`` the torso's true path [m]; estimate: ``(N, 2)`` the
        robot's estimate [m], both in the start frame; start: the frame's origin ``(2,)``
        [m] and heading [rad] in the world (:func:`start_frame`); qpos: ``(N, nq)`` the
        walk's states if the job asked to ``record`` them, else ``None``.
    """

    seed: int
    fell: bool
    fall_time_s: float | None
    reached_s: list[float | None]
    closest_m: list[float]
    finish_s: float | None
    odometry_error_m: float
    path: np.ndarray
    estimate: np.ndarray
    start: tuple[np.ndarray, float]
    qpos: np.ndarray | None = None

    @property
    def finished(self) -> bool:
        """Every waypoint reached, in order, without a fall."""
        return self.finish_s is not None and not self.fell

    def to_dict(self) -> dict:
        """Plain JSON, without the paths."""
        return {
            "seed": self.seed,
            "finished": self.finished,
            "fell": self.fell,
            "fall_time_s": self.fall_time_s,
            "reached_s": self.reached_s,
            "closest_m": [round(c, 4) for c in self.closest_m],
            "finish_s": self.finish_s,
            "odometry_error_m": round(self.odometry_error_m, 4),
        }


def start_frame(ro: Rollout) -> tuple[np.ndarray, float]:
    """The start frame in the world: the torso's first position ``(2,)`` [m] on the floor
    and its heading [rad]."""
    return ro.torso_pos[0, :2].copy(), float(yaw_rad(ro.torso_quat[:1])[0])


def truth_path(ro: Rollout) -> np.ndarray:
    """``(N, 2)`` the torso's path on the floor [m], in the frame of its first pose."""
    if len(ro.t) == 0:
        return np.zeros((0, 2))
    origin, yaw = start_frame(ro)
    return (ro.torso_pos[:, :2] - origin) @ rot2(yaw)


def _reached(path: np.ndarray, t: np.ndarray, course: Course) -> list[float | None]:
    out: list[float | None] = []
    start = 0
    for w in course.waypoints:
        hit = np.flatnonzero(np.linalg.norm(path[start:] - w, axis=1) <= course.reach)
        if len(hit) == 0:
            return out + [None] * (len(course.waypoints) - len(out))
        start += int(hit[0])
        out.append(round(float(t[start]), 3))
    return out


def walk_course(job: NavJob) -> tuple[NavResult, Navigator, Rollout]:
    """Walk ``job``: its :class:`NavResult`, the navigator and the rollout."""
    from imitwalk.navigate.navigator import Navigator
    from imitwalk.sim.mujoco import make_plant, run
    from imitwalk.step.controller import SteppingController

    ctrl = SteppingController(job.robot, job.style, job.gains, job.dt)
    nav = Navigator(ctrl, job.course)
    plant = make_plant(job.robot, replace(job.options, control_hz=1.0 / job.dt))
    sensor = FixSensor(job.fix, job.seed) if job.fix is not None else None

    def policy(k: int, obs: Observation) -> np.ndarray:
        if sensor is not None and (xy := sensor.read(plant, float(obs.t))) is not None:
            nav.fix(xy)
        return nav(k, obs)

    policy.q0 = nav.q0  # type: ignore[attr-defined]
    done: list[float] = []

    def stop() -> bool:
        if nav.finished and not done:
            done.append(nav.track[-1].t)
        return abandoned() or bool(done and nav.track[-1].t > done[0] + LINGER_S)

    ro = run(plant, policy, int(round(job.seconds / job.dt)), abandon=stop)
    path = truth_path(ro)
    est = np.array([[tk.x, tk.y] for tk in nav.track]).reshape(-1, 2)[: len(path)]
    reached = _reached(path, ro.t, job.course)
    closest = [float(np.min(np.linalg.norm(path - w, axis=1))) for w in job.course.waypoints]
    result = NavResult(
        seed=job.seed,
        fell=bool(ro.fell),
        fall_time_s=ro.fall_time,
        reached_s=reached,
        closest_m=closest if len(path) else [float("inf")] * len(closest),
        finish_s=reached[-1],
        odometry_error_m=float(np.linalg.norm(est[-1] - path[-1])) if len(path) else 0.0,
        path=path,
        estimate=est,
        start=start_frame(ro) if len(path) else (np.zeros(2), 0.0),
        qpos=ro.qpos if job.record else None,
    )
    return result, nav, ro


def run_nav_job(job: NavJob) -> NavResult:
    """:func:`walk_course` reduced to its :class:`NavResult` (runs in a worker process)."""
    return walk_course(job)[0]
