"""What the report shows of the robot: replays from standing, rendered video and strips.

:func:`replay` runs a learned run's open-loop reference ("before") and its learned
controller ("after") on the nominal robot; :func:`video` renders both side by side,
labelled; :func:`robot_strip` and :func:`human_strip` give Fig. 8's film-strip rows.
Rendering goes through :mod:`imitwalk.sim.render` (offscreen, fast settings).
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from imitwalk.balance.tickstore import TRIAL_GAINS
from imitwalk.evidence import curves, plots
from imitwalk.fileio import atomic_write
from imitwalk.judge.replay import LoadedRun
from imitwalk.robots import Robot
from imitwalk.runs import LearnSummary, TickOutcome
from imitwalk.sim.mujoco import MujocoPlant, Rollout, SimOptions, make_plant, run

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from imitwalk.paper.gait import GaitModel
    from imitwalk.retarget.reference import Reference
    from imitwalk.sim.render import Renderer
    from imitwalk.step.gait import StepGait

__all__ = [
    "Replays",
    "ReportSettings",
    "gyro_until_fall",
    "human_strip",
    "kick_strip",
    "outcome",
    "pose_qpos",
    "replay",
    "robot_strip",
    "save_strip",
    "summary_phrase",
    "video",
]


@dataclass(frozen=True)
class ReportSettings:
    """Rendering settings (kept small so a report takes seconds).

    Attributes:
        fps: video frame rate [Hz]; width, height: size of each video half [px].
        strip_frames: images per film-strip row and example poses of Fig. 3.
        strip_width, strip_height: film-strip and pose image size [px].
        video_camera, strip_camera: (distance [the robot's standing heights], azimuth
            [deg], elevation [deg]); the strips and poses are seen from the side, like the
            human skeleton.
    """

    fps: float = 25.0
    width: int = 384
    height: int = 288
    strip_frames: int = 6
    strip_width: int = 240
    strip_height: int = 300
    video_camera: tuple[float, float, float] = (2.5, 120.0, -20.0)
    strip_camera: tuple[float, float, float] = (1.85, 90.0, -12.0)


def gyro_until_fall(ro: Rollout, margin: float = 0.3) -> np.ndarray:
    """Gyro ``(N, 3)`` up to a little after the fall (afterwards it is the robot lying)."""
    if ro.fall_time is None:
        return ro.gyro
    return ro.gyro[: int(np.searchsorted(ro.t, ro.fall_time + margin))]


def outcome(ro: Rollout) -> str:
    d = ro.torso_pos[-1, :2] - ro.torso_pos[0, :2] if len(ro.t) else np.zeros(2)
    fell = f"fell at {ro.fall_time:.2f} s" if ro.fell else "did not fall"
    return f"{fell}; torso moved {d[0]:+.2f} m along x, {d[1]:+.2f} m along y in {ro.seconds:.1f} s"


def summary_phrase(metrics: LearnSummary) -> str:
    """What a run kept, in a phrase: a per-tick run's trial-picked reference settings,
    gains and the fraction of its model-based law; a faithful run's iterations."""
    kept = metrics.outcome
    if not isinstance(kept, TickOutcome) or kept.feedback_gains is None:
        return f"{metrics.iterations} iterations of the paper's learner"
    gains = kept.feedback_gains
    names = {g.name: f"{g.feature} → {g.channel.replace('_', ' ')}" for g in TRIAL_GAINS}
    chosen = ", ".join(f"{names.get(k, k)} {v:g}" for k, v in gains.items())
    trust = kept.trust
    learned = "" if trust is None else f"; model-based law kept at {trust:g}"
    played = kept.reference_settings or {}
    ref = ", ".join(f"{k} {v:g}" for k, v in played.items())
    ref = f"reference played with {ref}; " if ref else ""
    return f"{ref}trial-picked gains {chosen}{learned}"


def _label(frame: np.ndarray, lines: list[tuple[str, tuple[int, int, int]]]) -> np.ndarray:
    from PIL import Image, ImageDraw, ImageFont

    img = Image.fromarray(frame)
    draw = ImageDraw.Draw(img)
    font = ImageFont.load_default(size=15)
    for i, (text, color) in enumerate(lines):
        draw.text((8, 6 + 18 * i), text, fill=color, font=font, stroke_width=2, stroke_fill="white")
    return np.asarray(img)


def video(
    robot: Robot, runs: list[tuple[str, Rollout]], seconds: float, s: ReportSettings
) -> list[np.ndarray]:
    """Side-by-side frames ``(H, 2W + 4, 3)`` of the two runs, labelled."""
    from imitwalk.sim.render import render_frames

    halves = []
    n = max(1, round(seconds * s.fps))
    view = dict(zip(("distance", "azimuth", "elevation"), s.video_camera, strict=True))
    for name, ro in runs:
        frames = render_frames(
            robot, ro.qpos, ro.control_dt, s.fps, width=s.width, height=s.height, **view
        )
        frames = (frames + frames[-1:] * n)[:n]  # hold the last frame of a short run
        out = []
        for k, f in enumerate(frames):
            t = k / s.fps
            lines = [(name, (0, 0, 0)), (f"t = {t:4.1f} s", (40, 40, 40))]
            if ro.fell:
                assert ro.fall_time is not None  # a run that fell says when
                if t >= ro.fall_time:
                    lines.append((f"fell at {ro.fall_time:.1f} s", (200, 0, 0)))
            out.append(_label(f, lines))
        halves.append(out)
    gap = np.full((s.height, 4, 3), 255, np.uint8)
    return [np.hstack([a, gap, b]) for a, b in zip(*halves, strict=True)]


def robot_strip(
    renderer: Renderer, ro: Rollout, period: float, count: int
) -> tuple[list[np.ndarray], list[str]]:
    """Images of the last gait cycle of a run (the fallen robot, if it fell)."""
    t_end = ro.seconds
    times = np.linspace(max(0.0, t_end - period), t_end, count, endpoint=False)
    idx = np.clip(np.round(times / ro.control_dt).astype(int), 0, len(ro.qpos) - 1)
    return [renderer.frame(ro.qpos[i]) for i in idx], [f"t = {ro.t[i]:.2f} s" for i in idx]


def human_strip(ref: Reference | StepGait, count: int) -> tuple[Figure | None, str | None]:
    """Fig. 8's first row (or the reason it is missing): one gait cycle of the clip, in
    reverse for a backward walk (``learn --backward`` imitates the clip played backward)."""
    from imitwalk.errors import MocapError
    from imitwalk.mocap import load_motion
    from imitwalk.step.gait import StepGait

    try:
        motion = load_motion(ref.source)
    except (MocapError, OSError) as exc:  # a missing or unreadable source: say so
        return None, f"the human motion could not be loaded from {ref.source!r}: {exc}"
    if len(ref.cycles):
        a, b = (int(v) for v in ref.cycles[0])
    else:
        a, b = 0, motion.n_frames
    backward = isinstance(ref, StepGait) and ref.style.backward
    ends = (b, a) if backward else (a, b)
    frames = np.linspace(*ends, count, endpoint=False).astype(int)
    if motion.loop:  # cycles of a looping clip count frames of the clip repeated
        frames %= int(motion.meta.get("period_frames", motion.n_frames))
    frames = np.clip(frames, 0, motion.n_frames - 1)
    played = ", played backward" if backward else ""
    label = f"human demonstration ({Path(ref.source).name}, one gait cycle{played})"
    return plots.skeleton_strip(motion, frames, label), None


def pose_qpos(robot: Robot, q: np.ndarray) -> np.ndarray:
    plant = MujocoPlant(robot, SimOptions())
    plant.reset(q)  # puts the posture on the floor, no physics step
    return plant.data.qpos.copy()


@dataclass
class Replays:
    """The report's two runs from standing at one scale (nominal robot).

    ``before``: the reference played open loop; ``after``: the learned controller;
    ``actions``: ``(T, 3)`` the (φ, r, h) it executed in the gait loop, up to its fall
    (a faithful run's; empty for a per-tick run, whose actions are joint offsets).
    """

    scale: float
    before: Rollout
    after: Rollout
    actions: np.ndarray

    def postures(self, gait: GaitModel) -> np.ndarray:
        """``(T, k)`` the learned run's commanded joint targets in the subspace, over its
        last two gait cycles (up to its fall)."""
        q = self.after.q_cmd
        if self.after.fell:
            assert self.after.fall_time is not None  # a run that fell says when
            q = q[: max(1, round(self.after.fall_time / self.after.control_dt))]
        return gait.subspace.transform(q[-2 * gait.n_ticks :])

    def paths(self, ref: Reference | StepGait) -> Figure:
        """Top view of the two runs' torso paths and the path ``ref`` commands."""
        commanded = ref.ground_path(self.scale, self.after.seconds)
        return curves.torso_paths([(n, ro.torso_pos) for n, ro in self.runs], commanded)

    @property
    def runs(self) -> list[tuple[str, Rollout]]:
        """(label, rollout) of each run, before first."""
        return [("before: open loop", self.before), ("after: learned", self.after)]


def replay(
    run_: LoadedRun,
    robot: Robot,
    seconds: float,
    scale: float | None = None,
    options: SimOptions | None = None,
) -> Replays:
    """Run the open-loop reference and the learned controller of a loaded run
    (:func:`~imitwalk.judge.replay.load_run`) for ``seconds`` [s] at ``scale`` (default: the
    scale reached) on the engine it learned on, without stopping at a fall; ``options``:
    the robot (default: the nominal one, on the ground the gait was built for)."""
    scale = run_.scale if scale is None else scale
    opts = run_.ref.sim_options(options)
    runs = []
    for name in ("open_loop", "learned"):
        policy = run_.policy(name, robot, scale, seconds)
        plant = make_plant(robot, opts, run_.engine)
        steps = round(seconds / run_.ref.dt)
        runs.append((run(plant, policy, steps, stop_on_fall=False), policy))
    (before, _), (after, policy) = runs
    actions = np.asarray(getattr(policy, "tick_actions", []), dtype=float).reshape(-1, 3)
    if after.fell and len(actions):
        assert after.fall_time is not None  # a run that fell says when
        first = policy.first_loop_tick
        actions = actions[: max(0, round(after.fall_time / after.control_dt) - first)]
    return Replays(scale, before, after, actions)


def kick_strip(
    renderer: Renderer, run_: LoadedRun, robot: Robot, count: int, controller: str = "learned"
) -> tuple[Figure, str]:
    """One kick, rendered: ``controller`` on the nominal robot kicked to the left
    at the left heel strike two cycles after the start-up, by half the hard protocol's
    largest kick; ``count`` images over the 1.5 s after it. Returns (figure, caption)."""
    from imitwalk.judge.pushes import kick_time, top_speed

    ref, speed = run_.ref, 0.25 * top_speed(robot.height)
    t = kick_time(ref, 0)
    heading = float(ref.track(run_.scale, t + ref.dt)[-1, 2])
    dv = (t, -speed * np.sin(heading), speed * np.cos(heading))
    seconds = t + 1.5
    opts = ref.sim_options(SimOptions(pushes=(dv,)))
    policy = run_.policy(controller, robot, run_.scale, seconds)
    steps = round(seconds / ref.dt)
    ro = run(make_plant(robot, opts, run_.engine), policy, steps, stop_on_fall=False)
    idx = np.linspace(round(t / ref.dt), len(ro.qpos) - 1, count).astype(int)
    images = [renderer.frame(ro.qpos[i]) for i in idx]
    titles = [f"t = {ro.t[i]:.2f} s" for i in idx]
    label = f"{controller} controller, kicked {speed:.2f} m/s to the left at t = {t:.2f} s"
    fig = plots.film_strip(images, titles, label)
    return fig, f"A kick of {speed:.2f} m/s to the left; the robot {outcome(ro)}."


def save_strip(figs: Sequence[Figure], path: Path) -> Path:
    """The film-strip figures stacked into one PNG (white-padded to the widest)."""
    from PIL import Image

    imgs = [Image.open(io.BytesIO(plots.png_bytes(f))).convert("RGB") for f in figs]
    w = max(i.width for i in imgs)
    out = Image.new("RGB", (w, sum(i.height for i in imgs)), "white")
    y = 0
    for i in imgs:
        out.paste(i, (0, y))
        y += i.height
    return atomic_write(path, lambda tmp: out.save(tmp, format="PNG"))
