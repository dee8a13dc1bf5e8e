"""``imitwalk navigate``: a stepping run walks a course of waypoints on a protocol's robots."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING

from imitwalk.cli.arg_checks import check_count, check_joint_map_alone, check_seconds, check_workers
from imitwalk.cli.progress import emit, progress
from imitwalk.cli.robot_args import robot_from, run_robot

if TYPE_CHECKING:
    from imitwalk.judge.replay import LoadedRun
    from imitwalk.navigate.course import Course
    from imitwalk.navigate.trial import NavJob, NavResult
    from imitwalk.robots import Robot
    from imitwalk.runs import RunDir
    from imitwalk.sim.fix import PositionFix
    from imitwalk.sim.protocol import Protocol

__all__ = ["add_parser", "navigate"]


def _robot(args: argparse.Namespace, rd: RunDir, cfg: dict) -> Robot:
    """The run's robot; ``--robot`` must name the same one."""
    from imitwalk.errors import ConfigError

    name, joint_map = run_robot(rd, cfg)
    own = robot_from(argparse.Namespace(robot=name, joint_map=joint_map))
    if args.robot is None:
        return own
    robot = robot_from(args)
    if robot.name != own.name:
        raise ConfigError(
            f"--robot {args.robot}: {rd.path} learned on {own.name!r}, not {robot.name!r}"
        )
    return robot


def _fix(args: argparse.Namespace) -> PositionFix | None:
    from imitwalk.errors import ConfigError
    from imitwalk.sim.fix import PositionFix

    if args.fix_rate is None:
        if args.fix_noise is not None:
            raise ConfigError("--fix-noise needs --fix-rate HZ (a position fix's rate)")
        return None
    return PositionFix(args.fix_rate, 0.05 if args.fix_noise is None else args.fix_noise)


def _video(job: NavJob, result: NavResult, path: Path) -> Path:
    """``result``'s recorded walk (of ``job``) rendered to ``path`` (written beside, then
    renamed), the course's waypoints drawn on the floor as discs of its reach."""
    from imitwalk.sim.render import render_frames, write_mp4
    from imitwalk.step.odometry import rot2

    assert result.qpos is not None  # the job was recorded (record=True)
    origin, yaw = result.start  # the start frame, as the judge takes it
    marks = origin + job.course.waypoints @ rot2(yaw).T
    frames = render_frames(
        job.robot,
        result.qpos,
        job.dt,
        30.0,
        distance=3.5,
        elevation=-50.0,
        markers=marks,
        marker_radius=job.course.reach,
    )
    return write_mp4(frames, path, 30.0)


def navigate(args: argparse.Namespace) -> int:
    from imitwalk.fileio import atomic_write
    from imitwalk.navigate.trial import run_nav_job
    from imitwalk.parallel import run_parallel

    course = _course(args)
    check_count(args.seeds, "--seeds")
    check_seconds(args.seconds)
    check_workers(args.workers)
    check_joint_map_alone(args)
    fix = _fix(args)
    rd, lr, robot = _stepping_run(args)
    out = _out_dir(args, rd)
    protocol, jobs = _nav_jobs(args, lr, robot, course, fix)
    what = "dead reckoning" if fix is None else f"a fix at {fix.rate_hz:g} Hz, {fix.sigma_m:g} m"
    progress(
        f"navigate: {len(course.waypoints)} waypoints, {args.seeds} robots of "
        f"{protocol.name}, at most {args.seconds:g} s each, by {what}"
    )
    results = run_parallel(run_nav_job, jobs, workers=args.workers)
    summary = _summary(rd, robot, protocol, course, fix, results)
    _write_plot(out, rd, protocol, course, results)
    if args.video:
        summary["video"] = str(_video(jobs[0], results[0], out / "video.mp4"))
    summary["plot"] = str(out / "path.png")
    text = json.dumps(summary, indent=2)
    atomic_write(out / "navigate.json", lambda tmp: tmp.write_text(text))
    done = summary["finished"]
    progress(f"navigate: {done}/{len(results)} finished, {summary['fell']} fell; -> {out}")
    emit(summary, args.json)
    return 0


def _course(args: argparse.Namespace) -> Course:
    """The course to walk: ``--waypoints`` (default :data:`DEFAULT_COURSE`), ``(K, 2)`` [m],
    and ``--reach`` [m]."""
    import numpy as np

    from imitwalk.navigate.course import DEFAULT_COURSE, Course, parse_waypoints

    wp = np.array(DEFAULT_COURSE) if args.waypoints is None else parse_waypoints(args.waypoints)
    return Course(wp, args.reach)


def _stepping_run(args: argparse.Namespace) -> tuple[RunDir, LoadedRun, Robot]:
    """The run folder, its loaded run (a stepping one, else refused) and its robot."""
    from imitwalk.errors import ConfigError
    from imitwalk.judge.replay import load_run
    from imitwalk.runs import RunDir
    from imitwalk.step.gait import StepGait

    rd = RunDir(args.run_dir)
    cfg = rd.read_json("config.json")
    lr = load_run(rd.path)
    if lr.learner != "step":
        raise ConfigError(
            f"{rd.path} is a {lr.learner!r} run; navigate steers the stepping gait (learner: step)"
        )
    if isinstance(lr.ref, StepGait) and lr.ref.style.backward:
        raise ConfigError(
            f"{rd.path} walks backward (learn --backward); navigate steers a forward walk"
        )
    return rd, lr, _robot(args, rd, cfg)


def _out_dir(args: argparse.Namespace, rd: RunDir) -> Path:
    """The folder to write to (``--out``, default ``RUN/navigate``); refuses, before the
    walks, a file or a folder that cannot be written (:meth:`RunDir.check_writable
    <imitwalk.runs.RunDir.check_writable>`)."""
    from imitwalk.runs import RunDir

    out = Path(args.out) if args.out else Path(rd.path) / "navigate"
    RunDir(out).check_writable("--out")
    return out


def _nav_jobs(
    args: argparse.Namespace,
    lr: LoadedRun,
    robot: Robot,
    course: Course,
    fix: PositionFix | None,
) -> tuple[Protocol, list[NavJob]]:
    """The protocol and one job per robot ``0 … --seeds − 1`` (the first recorded for
    ``--video``), each walking the run's learned gains for at most ``--seconds`` [s]."""
    from imitwalk.navigate.trial import NavJob
    from imitwalk.sim.protocol import load_protocol

    gait = lr.step_gait
    assert lr.step_gains is not None  # a stepping run has its gains
    style, gains = gait.at_scale(lr.scale), lr.step_gains["learned"]
    protocol = load_protocol(args.protocol)
    jobs = [
        NavJob(
            robot,
            style,
            gains,
            course,
            seed,
            protocol.draw(seed, robot, gait.sim_options(), args.seconds).options,
            args.seconds,
            fix,
            gait.dt,
            record=args.video and seed == 0,
        )
        for seed in range(args.seeds)
    ]
    return protocol, jobs


def _summary(
    rd: RunDir,
    robot: Robot,
    protocol: Protocol,
    course: Course,
    fix: PositionFix | None,
    results: list[NavResult],
) -> dict:
    """``navigate.json``'s content: the settings, the counts and times [s], distances [m]
    and every robot's result (without the plot and video paths)."""
    import numpy as np

    done = [r for r in results if r.finished]
    finish_s = [r.finish_s for r in done if r.finish_s is not None]  # all of them: finished
    return {
        "run": str(rd.path),
        "robot": robot.name,
        "protocol": protocol.name,
        "waypoints": course.waypoints.tolist(),
        "reach_m": course.reach,
        "fix": None if fix is None else {"rate_hz": fix.rate_hz, "sigma_m": fix.sigma_m},
        "robots": len(results),
        "finished": len(done),
        "fell": sum(r.fell for r in results),
        "finish_s_mean": float(np.mean(finish_s)) if done else None,
        "finish_s_max": float(max(finish_s)) if done else None,
        "closest_m_max": float(max(max(r.closest_m) for r in results)),
        "odometry_error_m_mean": float(np.mean([r.odometry_error_m for r in results])),
        "results": [r.to_dict() for r in results],
    }


def _write_plot(
    out: Path, rd: RunDir, protocol: Protocol, course: Course, results: list[NavResult]
) -> None:
    """Draw every robot's path over the course into ``out/path.png``."""
    from imitwalk.evidence.navplot import course_figure
    from imitwalk.evidence.plots import png_bytes
    from imitwalk.fileio import atomic_write

    done = sum(r.finished for r in results)
    title = (
        f"{rd.path}: {done}/{len(results)} robots of {protocol.name} reached all "
        f"{len(course.waypoints)} waypoints"
    )
    fig = course_figure(course.waypoints, course.reach, results, title)
    png = png_bytes(fig)
    atomic_write(out / "path.png", lambda tmp: tmp.write_bytes(png))


def add_parser(
    sub: argparse._SubParsersAction[argparse.ArgumentParser], protocols: tuple[str, ...]
) -> None:
    """The ``navigate`` subcommand's arguments."""
    from imitwalk.navigate.course import DEFAULT_COURSE, REACH_M

    p = sub.add_parser(
        "navigate", help="walk a course of waypoints with a stepping run, steered by odometry"
    )
    p.add_argument("run_dir", help="a stepping run (learn)")
    course = " ".join(f"{x:g},{y:g}" for x, y in DEFAULT_COURSE)
    p.add_argument(
        "--waypoints",
        nargs="*",
        metavar="X,Y",
        default=None,
        help=f"waypoints [m] in the start frame (x ahead, y left; default {course})",
    )
    p.add_argument(
        "--reach",
        type=float,
        default=REACH_M,
        help=f"a waypoint is reached within this [m] ({REACH_M:g})",
    )
    p.add_argument(
        "--protocol",
        metavar="NAME|FILE",
        default="eval",
        help="the robots: " + ", ".join(protocols) + " (default eval), or a protocol .json",
    )
    p.add_argument("--seeds", type=int, default=10, help="robots (10)")
    p.add_argument("--seconds", type=float, default=90.0, help="the most each may take [s] (90)")
    p.add_argument(
        "--fix-rate",
        type=float,
        default=None,
        help="a position fix (a camera, a mocap room) this often [Hz]; default none",
    )
    p.add_argument(
        "--fix-noise", type=float, default=None, help="the fix's noise per axis [m] (0.05)"
    )
    p.add_argument(
        "--video",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="render the first robot's walk to video.mp4 (default on)",
    )
    p.add_argument("--out", default=None, help="where to write (default RUN/navigate)")
    p.add_argument("--robot", default=None, help="robot (default: the run's; must be the same)")
    p.add_argument("--joint-map", help="joint-map JSON for an MJCF robot")
    p.add_argument("--workers", type=int, default=None, help="parallel processes")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=navigate)
