"""A run's report: one self-contained HTML page, viewable offline.

:func:`write_report` replays the run at the scale it reached from standing, twice (the
open-loop reference, "before", and the learned controller, "after", nominal robot),
renders both offscreen and writes ``RUN_DIR/report.html`` with the paper's figures
(3, 4, 6, 7 and 8), the learning curves, the gyro traces, the judgements on every
protocol the run was evaluated on, push recovery with a film strip of one kick, and the
configuration. Figures are inline base64 PNGs and the before/after video an inline
base64 H.264 MP4: no external URL, no JavaScript. The video and the Fig. 8 film strip
are also saved as ``before_after.mp4`` and ``filmstrip.png``.
"""

from __future__ import annotations

import html
import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from imitwalk.config import schedule_scales
from imitwalk.evidence import curves, media, plots
from imitwalk.evidence.page import STYLE, b64, evaluations, figure, img, robustness, section
from imitwalk.fileio import atomic_write
from imitwalk.judge.replay import LoadedRun, load_run
from imitwalk.paper.gait import GaitConfig, GaitModel
from imitwalk.robots import Robot, load_robot
from imitwalk.runs import RunDir

if TYPE_CHECKING:
    import numpy as np
    from matplotlib.figure import Figure

    from imitwalk.retarget.reference import Reference
    from imitwalk.step.gait import StepGait

__all__ = ["write_report"]


def _fmt(v: object) -> str:
    if isinstance(v, dict) and "mean" in v:
        if v["mean"] is None:  # a figure no seed recorded
            return "–"
        return f"{v['mean']:.3g} <small>({v['min']:.3g} … {v['max']:.3g})</small>"
    if isinstance(v, float):
        return f"{v:.4g}"
    if v is None:
        return "–"
    return html.escape(str(v))


def write_report(
    run_dir: str | Path,
    robot: Robot | None = None,
    seconds: float = 10.0,
    progress: Callable[[str], None] | None = None,
    settings: media.ReportSettings | None = None,
) -> Path:
    """Write ``RUN_DIR/report.html`` (and ``before_after.mp4``, ``filmstrip.png``).

    Args:
        run_dir: a finished learning run (see :mod:`imitwalk.runs`).
        robot: the robot (default: the one named in ``config.json``).
        seconds: length of the two replays from standing [s].
        progress: optional ``callback(line)``.
        settings: rendering settings.
    Returns:
        the path of ``report.html``.
    Raises:
        RunError: ``run_dir`` is not a finished run.
    """
    say = progress or (lambda _line: None)
    s = settings or media.ReportSettings()
    t0 = time.perf_counter()
    rd = RunDir(run_dir)
    lg = load_run(run_dir)
    config = rd.read_json("config.json")
    made = lg.ref.provenance
    where = made.robot or config.get("robot", lg.ref.robot)  # a file, or a name
    robot = robot or load_robot(where, made.joint_map)
    if lg.learner in ("step", "rl"):
        from imitwalk.evidence.step_report import write_step_report

        return write_step_report(run_dir, lg, robot, seconds, progress, s)
    say(f"report: replaying {seconds:g} s at scale {lg.scale:g} (open loop, learned)")
    rp = media.replay(lg, robot, seconds)
    gait = _display_gait(lg)

    say("report: rendering the video")
    from imitwalk.sim.render import Renderer, write_mp4

    frames = media.video(robot, rp.runs, seconds, s)
    mp4 = write_mp4(frames, rd.file("before_after.mp4"), s.fps)
    h, w = frames[0].shape[:2]
    video = (
        f'<video controls muted loop playsinline width="{w}" height="{h}" '
        f'src="data:video/mp4;base64,{b64(mp4.read_bytes())}"></video>'
    )

    say("report: rendering film strips and poses")
    renderer = Renderer(robot, s.strip_width, s.strip_height, *s.strip_camera)
    try:
        strips = [
            media.robot_strip(renderer, ro, lg.ref.period, s.strip_frames) for _, ro in rp.runs
        ]
        ticks = plots.example_ticks(gait.n_ticks, s.strip_frames)
        loop = lg.reference.at_scale(rp.scale)[1]  # (N, n)
        poses = [renderer.frame(media.pose_qpos(robot, loop[k])) for k in ticks]
        say("report: replaying and rendering one kick")
        kick = media.kick_strip(renderer, lg, robot, s.strip_frames)
    finally:
        renderer.close()

    say("report: drawing figures")
    fig8 = _fig8(lg.ref, rp, strips, s.strip_frames, rd.file("filmstrip.png"))
    body = _sections(rd, lg, gait, rp, config, video, fig8, poses, ticks, kick)
    title = html.escape(f"imitwalk run {rd.path.name}")
    m = lg.metrics
    page = (
        f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8"><title>{title}'
        f'</title><link rel="icon" href="data:,"><style>{STYLE}</style></head><body>\n'
        f"<h1>{title}</h1>\n<p>{html.escape(lg.learner)} learner; scale "
        f"reached {lg.scale:g}; {m.iterations} learning iterations; report made in "
        f"{time.perf_counter() - t0:.0f} s.</p>\n{body}</body></html>\n"
    )
    out = atomic_write(rd.file("report.html"), lambda tmp: tmp.write_text(page, "utf-8"))
    say(f"report: wrote {out} in {time.perf_counter() - t0:.1f} s")
    return out


def _fig8(
    ref: Reference | StepGait,
    rp: media.Replays,
    strips: list[tuple[list[np.ndarray], list[str]]],
    count: int,
    png: Path,
) -> str:
    """Fig. 8's rows as HTML; also saved, stacked, as ``png``."""
    human, missing = media.human_strip(ref, count)
    rows = [] if human is None else [(human, "film strip: human")]
    for (images, titles), (name, ro) in zip(strips, rp.runs, strict=True):
        label = f"robot {name} (last gait cycle; {media.outcome(ro)})"
        rows.append(
            (plots.film_strip(images, titles, label), f"film strip: robot {name.split(':')[0]}")
        )
    media.save_strip([f for f, _ in rows], png)
    out = "".join(img(f, alt) for f, alt in rows)
    if missing:
        out = f'<p class="missing">{html.escape(missing)}</p>' + out
    return figure(
        out,
        "Rows: the human demonstration (mocap keypoints, side view), the "
        "robot playing the reference open loop (before), the robot with the learned "
        "controller (after).",
    )


def _display_gait(lg: LoadedRun) -> GaitModel:
    """The paper's representation of the run's reference, for Figs. 3, 4, 6 and 7: the
    faithful run's own; for a per-tick run, the paper's (k = 3, the angle as the phase)
    over the schedule's scales."""
    if lg.gait is not None:
        return lg.gait.gait
    cfg = lg.metrics.config
    start, step = float(cfg.get("start", 0.3)), float(cfg.get("step", 0.1))
    scales = sorted({*schedule_scales(start, step, max(lg.scale, start)), lg.scale})
    return GaitModel(lg.reference, scales, GaitConfig())


def _sections(
    rd: RunDir,
    lg: LoadedRun,
    gait: GaitModel,
    rp: media.Replays,
    config: dict,
    video: str,
    fig8: str,
    poses: list[np.ndarray],
    ticks: np.ndarray,
    kick: tuple[Figure, str],
) -> str:
    """The report's body: every section's HTML, in page order."""
    scale, log, m = rp.scale, rd.read_log(), lg.metrics
    passed = [float(p) for p in m.scales_passed]
    at_final = bool(passed) and abs(lg.scale - scale) < 1e-9
    gyro = _gyro(rp)
    learning = curves.tick_curves(log) if lg.laws is not None else curves.learning_curves(log)
    actions = rp.actions if (at_final and len(rp.actions)) else None
    fig7 = plots.fig7_schedule(gait, passed, actions, lg.scale)
    fig6 = _fig6(gait, rp, lg.scale)
    sections = [
        *_outcome_sections(rd, rp, video, fig8, kick),
        *_learning_sections(lg, rp, learning, gyro, passed),
        *_paper_sections(gait, scale, poses, ticks, fig6, fig7),
        (
            "Configuration",
            "<details><summary>config.json</summary><pre>"
            + html.escape(json.dumps(config, indent=2))
            + "</pre></details>",
        ),
    ]
    return "".join(section(t, b) for t, b in sections)


def _gyro(rp: media.Replays) -> Figure:
    """Both replays' torso gyro traces [rad/s] up to just after a fall."""
    return curves.gyro_traces(
        media.gyro_until_fall(rp.before),
        media.gyro_until_fall(rp.after),
        rp.before.control_dt,
        fall_times=(rp.before.fall_time, rp.after.fall_time),
    )


def _fig6(gait: GaitModel, rp: media.Replays, reached: float) -> tuple[Figure, str]:
    """Fig. 6 and its caption: the learned actions (φ, r, h) of the replay at
    ``rp.scale``; for a per-tick run, which has none, the loop at the ``reached`` scale."""
    if len(rp.actions):
        fig = plots.fig6_optimized(gait, rp.scale, rp.actions, rp.postures(gait))
        return fig, (
            "The actions (φ, r, h) the learned controller executed in the replay above (red, "
            "up to its fall, if it fell); in green, the joint targets it actually sent, "
            "projected into the subspace."
        )
    return plots.fig7_schedule(gait, [], None, reached), (
        "A per-tick run acts on the legs' joints, beside the paper's (φ, r, h): "
        "its actions have no place in this figure; the loop is drawn at the scale reached."
    )


def _outcome_sections(
    rd: RunDir, rp: media.Replays, video: str, fig8: str, kick: tuple[Figure, str]
) -> list[tuple[str, str]]:
    """(title, HTML) of the outcome: the before/after video, Fig. 8, the evaluations and
    robustness."""
    return [
        (
            "Before and after",
            video + f"<p>Nominal robot, from standing, at the scale reached "
            f"({rp.scale:g}). Open loop: {media.outcome(rp.before)}. "
            f"Learned: {media.outcome(rp.after)}.</p>",
        ),
        ("Fig. 8: learning to walk through imitation", fig8),
        ("Evaluation", evaluations(rd)),
        ("Robustness", robustness(rd, kick)),
    ]


def _learning_sections(
    lg: LoadedRun, rp: media.Replays, learning: Figure, gyro: Figure, passed: list[float]
) -> list[tuple[str, str]]:
    """(title, HTML) of the learning curves, the torso paths and the gyro traces;
    ``passed``: the scales the schedule passed."""
    m = lg.metrics
    return [
        (
            "Learning",
            figure(
                img(learning, "learning curves"),
                f"{m.iterations} iterations; {m.sim_seconds_used_for_learning:.0f} "
                f"s simulated; scales passed: {', '.join(f'{p:g}' for p in passed) or 'none'}; "
                f"{html.escape(media.summary_phrase(m))}.",
            ),
        ),
        (
            "Path",
            figure(
                img(rp.paths(lg.ref), "torso paths"),
                f"The replays above from above; dashed: the path the reference commands "
                f"({lg.reference.command.describe()}).",
            ),
        ),
        (
            "Torso gyro",
            figure(
                img(gyro, "gyro traces"),
                "The replays above, up to just "
                "after a fall (dashed: the fall); eq. 6 weighs their squares.",
            ),
        ),
    ]


def _paper_sections(
    gait: GaitModel,
    scale: float,
    poses: list[np.ndarray],
    ticks: np.ndarray,
    fig6: tuple[Figure, str],
    fig7: Figure,
) -> list[tuple[str, str]]:
    """(title, HTML) of the paper's Figs. 3, 4, 6 and 7 at ``scale``; ``poses``: the
    robot rendered at ``ticks`` of the loop."""
    evr = gait.subspace.explained_variance_ratio_
    return [
        (
            "Fig. 3: posture subspace",
            figure(
                img(plots.fig3_subspace(gait, scale, poses, ticks), "Fig. 3"),
                "Explained variance: "
                + ", ".join(f"PC{i + 1} {100 * v:.1f} %" for i, v in enumerate(evr))
                + ".",
            ),
        ),
        (
            "Fig. 4: embedded action space",
            figure(
                img(plots.fig4_embedding(gait, scale), "Fig. 4"),
                "The frame of eq. 1 and g(φ) of eq. 2.",
            ),
        ),
        ("Fig. 6: optimised pattern", figure(img(fig6[0], "Fig. 6"), fig6[1])),
        (
            "Fig. 7: motion pattern scaling",
            figure(
                img(fig7, "Fig. 7"),
                "The schedule's scales; red circles: the last cycle the learned "
                "controller executed above (a faithful run's).",
            ),
        ),
    ]
