"""A stepping or PPO run's report: one self-contained HTML page, viewable offline.

The stepping gait has no joint-space loop for the paper's Figs. 3–7 (those are a
per-tick or faithful run's report, :mod:`imitwalk.evidence.report`). Its page shows:
the walk from standing on the nominal robot with the shipped gains and the learned
ones, side by side (video); the human demonstration beside the robot, and the style's
cadence and stride beside what the robot's sole forces measured; every protocol the
run was judged on; push recovery and one kick; the learning curve; the path from above;
the configuration. A PPO run's page (:mod:`imitwalk.envs.ppo`) shows the stepping gait it
was trained beside and its policy in place of the two gains, and its episode lengths
as the learning curve.
"""

from __future__ import annotations

import html
import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from imitwalk.evidence import curves, media, plots
from imitwalk.evidence.page import STYLE, b64, evaluations, figure, img, robustness, section
from imitwalk.fileio import atomic_write
from imitwalk.judge.replay import LoadedRun
from imitwalk.robots import Robot
from imitwalk.runs import RunDir
from imitwalk.sim.metrics import gait_timing
from imitwalk.sim.mujoco import Rollout, make_plant, run

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["imitation_rows", "write_step_report"]

#: The two walks shown: the shipped gains, then the learned ones (a PPO run: the
#: stepping gait it was trained beside, then its policy).
SHOWN = ("default", "learned")
SHOWN_RL = ("default", "rl")


def shown(lg: LoadedRun) -> tuple[str, str]:
    """The two controllers a report shows, the learned one last."""
    return SHOWN_RL if lg.learner == "rl" else SHOWN


def _label(lg: LoadedRun, name: str) -> str:
    if lg.learner == "rl":
        return "PPO policy" if name == "rl" else "stepping gait"
    return f"{name} gains"


def _replays(lg: LoadedRun, robot: Robot, seconds: float) -> list[tuple[str, Rollout]]:
    out = []
    for name in shown(lg):
        policy = lg.policy(name, robot, lg.scale, seconds)
        plant = make_plant(robot, lg.ref.sim_options(), lg.engine)
        steps = round(seconds / lg.ref.dt)
        out.append((_label(lg, name), run(plant, policy, steps, stop_on_fall=False)))
    return out


def _fmt(value: float | None, spec: str) -> str:
    return "–" if value is None else format(value, spec)


def imitation_rows(lg: LoadedRun, ro: Rollout, robot: Robot) -> list[tuple[str, str, str, str]]:
    """The style against the walk: (figure, human, the style on the robot, the robot
    measured) rows. The robot's cadence and stride are measured from its sole forces
    after the start-up (:func:`~imitwalk.sim.metrics.gait_timing`)."""
    gait = lg.step_gait
    st, human = gait.at_scale(lg.scale), gait.style.human
    after = gait.kick_time(0, 1) - gait.period
    weight = robot.total_mass * 9.81
    timing = gait_timing(ro, weight, after_s=after, lifted_s=0.5 * st.single_support)
    speed = None
    if timing.stride_m is not None and timing.cycle_s:
        speed = timing.stride_m / timing.cycle_s
    return [
        (
            "cadence [steps/min]",
            _fmt(120.0 / human["period"], ".1f"),
            _fmt(60.0 / st.step_time, ".1f"),
            _fmt(timing.cadence_spm, ".1f"),
        ),
        (
            "stride [m]",
            _fmt(human["stride"], ".3f"),
            _fmt(2 * st.step_length, ".3f"),
            _fmt(timing.stride_m, ".3f"),
        ),
        ("speed [m/s]", _fmt(human["speed"], ".2f"), _fmt(st.speed, ".3f"), _fmt(speed, ".3f")),
        ("leg [m]", _fmt(human["leg"], ".3f"), _fmt(st.geometry.leg, ".3f"), ""),
        ("toe scuffs mid-swing", "", "0", str(timing.scuffs)),
    ]


def _imitation(lg: LoadedRun, robot: Robot, runs: list[tuple[str, Rollout]], strip: str) -> str:
    rows = imitation_rows(lg, runs[-1][1], robot)
    head = "<tr><th></th><th>human</th><th>style on the robot</th><th>robot, measured</th></tr>"
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>" for r in rows
    )
    note = (
        "<p>The style keeps the human's cadence and scales the stride by the robot's leg "
        "over the human's; the robot's figures are measured from its sole forces after "
        "the start-up, with the learned gains.</p>"
    )
    caption = "One gait cycle of the clip (mocap keypoints, side view) above the robot's last."
    return figure(strip, caption) + "<table>" + head + body + "</table>" + note


def _learning_rl(log: list[dict], lg: LoadedRun) -> str:
    m = lg.metrics
    fig = plots._figure(6.0, 3.0)
    ax = fig.add_subplot(111)
    rows = [e for e in log if e.get("episode_seconds") is not None]
    ax.plot([e["sim_seconds"] for e in rows], [e["episode_seconds"] for e in rows], "-")
    ax.set_xlabel("simulated seconds of experience")
    ax.set_ylabel("mean episode length [s]")
    caption = (
        f"PPO: {m.iterations} rollouts on training robots; "
        f"{m.sim_seconds_used_for_learning:.0f} s simulated, "
        f"{m.wall_seconds_for_learning:.0f} s of wall time. An episode ends on a fall."
    )
    return figure(img(fig, "learning curve"), caption)


def _learning(rd: RunDir, lg: LoadedRun) -> str:
    log, m = rd.read_log(), lg.metrics
    if not log:
        return '<p class="missing">No learning log.</p>'
    if lg.learner == "rl":
        return _learning_rl(log, lg)
    fig = plots._figure(6.0, 3.0)
    ax = fig.add_subplot(111)
    gens = [e["generation"] for e in log]
    ax.plot(gens, [e["best_cost"] for e in log], "o-", label="best candidate")
    ax.plot(gens, [e["mean_cost"] for e in log], "s--", label="mean of the generation")
    ax.axhline(1.0, color="grey", lw=0.8, ls=":")
    ax.set_xlabel("CMA-ES generation")
    ax.set_ylabel("cost (1 and above: a fall)")
    ax.legend(fontsize=8)
    kept = ", ".join(f"{k} {v:.3g}" for k, v in m.step().gains.items())
    caption = (
        f"{m.iterations} CMA-ES generations on training robots; "
        f"{m.sim_seconds_used_for_learning:.0f} s simulated, "
        f"{m.wall_seconds_for_learning:.0f} s of wall time. Kept: {html.escape(kept)}."
    )
    return figure(img(fig, "learning curve"), caption)


def _strips(
    lg: LoadedRun,
    robot: Robot,
    runs: list[tuple[str, Rollout]],
    rd: RunDir,
    s: media.ReportSettings,
) -> tuple[str, tuple[Figure, str]]:
    """Fig. 8's rows (the human, the robot) as HTML, and one kick's strip and caption."""
    from imitwalk.sim.render import Renderer

    renderer = Renderer(robot, s.strip_width, s.strip_height, *s.strip_camera)
    try:
        images, titles = media.robot_strip(renderer, runs[-1][1], lg.ref.period, s.strip_frames)
        kick = media.kick_strip(renderer, lg, robot, s.strip_frames, shown(lg)[-1])
    finally:
        renderer.close()
    human, missing = media.human_strip(lg.ref, s.strip_frames)
    rows = [] if human is None else [(human, "film strip: human")]
    last = _label(lg, shown(lg)[-1])
    robot_row = plots.film_strip(images, titles, f"robot, {last} (last gait cycle)")
    rows.append((robot_row, "film strip: robot"))
    media.save_strip([f for f, _ in rows], rd.file("filmstrip.png"))
    strip = "".join(img(f, alt) for f, alt in rows)
    if missing:
        strip = f'<p class="missing">{html.escape(missing)}</p>' + strip
    return strip, kick


def write_step_report(
    run_dir: str | Path,
    lg: LoadedRun,
    robot: Robot,
    seconds: float = 10.0,
    progress: Callable[[str], None] | None = None,
    settings: media.ReportSettings | None = None,
) -> Path:
    """Write ``RUN_DIR/report.html`` of a stepping run (see the module doc); the walks
    last at least long enough for a few steady cycles."""
    from imitwalk.sim.render import write_mp4

    say = progress or (lambda _line: None)
    s = settings or media.ReportSettings()
    t0 = time.perf_counter()
    rd = RunDir(run_dir)
    gait = lg.step_gait
    seconds = max(seconds, gait.kick_time(0, 1) + 2 * gait.period)
    say(f"report: replaying {seconds:g} s: " + " and ".join(_label(lg, n) for n in shown(lg)))
    runs = _replays(lg, robot, seconds)
    frames = media.video(robot, runs, seconds, s)
    mp4 = write_mp4(frames, rd.file("before_after.mp4"), s.fps)
    h, w = frames[0].shape[:2]
    video = (
        f'<video controls muted loop playsinline width="{w}" height="{h}" '
        f'src="data:video/mp4;base64,{b64(mp4.read_bytes())}"></video>'
    )
    say("report: film strips, one kick")
    strip, kick = _strips(lg, robot, runs, rd, s)
    outcomes = "; ".join(f"{html.escape(n)}: {html.escape(media.outcome(ro))}" for n, ro in runs)
    paths = curves.torso_paths(
        [(n, ro.torso_pos) for n, ro in runs], lg.ref.ground_path(lg.scale, seconds)
    )
    config = rd.read_json("config.json")
    sections = [
        ("The walk", video + f"<p>Nominal robot, from standing: {outcomes}.</p>"),
        ("The human and the robot", _imitation(lg, robot, runs, strip)),
        ("Evaluation", evaluations(rd)),
        ("Robustness", robustness(rd, kick)),
        ("Learning", _learning(rd, lg)),
        ("Path", figure(img(paths, "paths"), "The walks above, from above; dashed: ahead.")),
        (
            "Configuration",
            "<details><summary>config.json</summary><pre>"
            + html.escape(json.dumps(config, indent=2))
            + "</pre></details>",
        ),
    ]
    body = "".join(section(t, b) for t, b in sections)
    title = html.escape(f"imitwalk run {rd.path.name}")
    page = (
        f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8"><title>{title}'
        f'</title><link rel="icon" href="data:,"><style>{STYLE}</style></head><body>\n'
        f"<h1>{title}</h1>\n<p>{'PPO policy' if lg.learner == 'rl' else 'stepping gait'}; "
        f"{html.escape(Path(lg.ref.source).name)}; "
        f"report made in {time.perf_counter() - t0:.0f} s.</p>\n{body}</body></html>\n"
    )
    out = atomic_write(rd.file("report.html"), lambda tmp: tmp.write_text(page, "utf-8"))
    say(f"report: wrote {out}")
    return out
