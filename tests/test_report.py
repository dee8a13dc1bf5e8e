"""The run report: one self-contained HTML page that a real headless Chromium shows
without errors, with every figure and the before/after video."""

from __future__ import annotations

import os
import re
import shutil
from dataclasses import replace

import pytest

from imitwalk.cli.main import main
from imitwalk.config import apply_overrides
from imitwalk.evidence.report import write_report
from imitwalk.judge import pushes
from imitwalk.judge.replay import load_run
from imitwalk.paper.learnconfig import LearnConfig
from imitwalk.paper.learner import learn
from imitwalk.retarget.reference import Reference
from imitwalk.runs import RunDir
from tests.conftest import TINY, _missing

#: Flags for a quiet, offline headless Chromium (Playwright adds a fresh profile).
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
#: alt text of every figure of a full report.
FIGURES = {
    "film strip: human",
    "film strip: robot before",
    "film strip: robot after",
    "learning curves",
    "gyro traces",
    "torso paths",
    "Fig. 3",
    "Fig. 4",
    "Fig. 6",
    "Fig. 7",
    "a kick",
    "push recovery",
}


@pytest.fixture(scope="module")
def run_dir(tick_run, robot, tmp_path_factory):
    """The tiny per-tick run, judged on the eval protocol (2 robots × 6 s) and on the bullet
    one (learned and open loop, 1 robot × 3 s: Bullet is slow), with a push-recovery table
    (its kicks judged by a threshold, not simulated)."""
    out = tmp_path_factory.mktemp("report") / "run"
    shutil.copytree(tick_run, out)
    argv = ["evaluate", str(out), "--seconds", "6", "--seeds", "2", "--workers", "1", "--json"]
    assert main(argv) == 0  # writes protocol_eval.json
    bullet = [*argv[:2], "--seconds", "3", "--seeds", "1", "--workers", "1", "--protocol", "bullet"]
    assert main([*bullet, "--controllers", "learned,open_loop"]) == 0  # protocol_bullet.json
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(pushes, "survives", lambda job: job.speed < 0.3)
        RunDir(out).write_json(
            "push_recovery.json", pushes.push_recovery(out, robot, workers=1).to_dict()
        )
    return out


@pytest.fixture(scope="module")
def report(run_dir, robot):
    lines: list[str] = []
    path = write_report(run_dir, robot, seconds=4.0, progress=lines.append)
    return path, lines


@pytest.fixture(scope="module")
def bare_report(run_dir, robot, tmp_path_factory):
    """The same run without protocol judgements and push recovery, its mocap file gone."""
    bare = tmp_path_factory.mktemp("bare") / "run"
    shutil.copytree(
        run_dir,
        bare,
        ignore=shutil.ignore_patterns(
            "protocol_*.json", "push_recovery.json", "report.html", "*.mp4", "*.png"
        ),
    )
    ref = Reference.load(bare / "reference.npz")
    replace(ref, source=str(bare / "no_such_clip.bvh")).save(bare / "reference.npz")
    return write_report(bare, robot, seconds=2.0), None


def test_report_is_self_contained(report):
    path, lines = report
    text = path.read_text()
    assert path.name == "report.html" and lines and "wrote" in lines[-1]
    links = re.findall(r"""(?:src|href)\s*=\s*["']([^"']*)""", text)
    assert links and all(link.startswith("data:") for link in links), links
    assert "http://" not in text and "https://" not in text
    assert "<script" not in text.lower()
    assert text.count("data:image/png;base64,") == len(FIGURES)
    assert text.count("data:video/mp4;base64,") == 1
    for needed in (
        "distance [m]",
        "McNemar p vs open loop",
        "Protocol <b>eval</b>",
        "Protocol <b>bullet</b>",
        "phase 7/8",
        "<details>",
        "Fig. 8",
        "straight ahead on level ground",
        "trial-picked gains",
        "reference played with feedforward",
    ):
        assert needed in text, needed
    mp4 = path.with_name("before_after.mp4").read_bytes()
    assert mp4[4:8] == b"ftyp" and b"avc1" in mp4  # an H.264 MP4
    assert path.with_name("filmstrip.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_missing_files_are_said(bare_report):
    text = bare_report[0].read_text()
    assert "No <code>protocol_*.json</code>" in text
    assert "No <code>push_recovery.json</code>" in text
    assert "the human motion could not be loaded" in text
    assert "data:video/mp4;base64," in text


def test_figures_take_empty_data(run_dir):
    from imitwalk.evidence import curves, plots
    from imitwalk.evidence.report import _display_gait
    from imitwalk.judge.records import PushSettings, PushVerdict

    lr = load_run(run_dir)
    gait = _display_gait(lr)
    figs = [
        curves.learning_curves([]),
        curves.tick_curves([]),
        plots.fig6_optimized(gait, lr.scale, []),
        plots.fig7_schedule(gait, []),
        curves.gyro_traces([], [], 0.01),
        curves.push_polar(PushVerdict(PushSettings(1.0, 8, (), 5.0, 0.0, 0.0, ()), {})),
        plots.film_strip([], []),
    ]
    for fig in figs:
        assert plots.png_bytes(fig)[:4] == b"\x89PNG"


def test_a_faithful_run_has_a_report(robot, tiny_reference, tmp_path):
    ref, _ = tiny_reference
    out = tmp_path / "run"
    learn(ref, robot, apply_overrides(LearnConfig(), TINY), out)
    text = write_report(out, robot, seconds=2.0).read_text()
    assert "faithful learner" in text and "Fig. 6" in text
    assert text.count("data:video/mp4;base64,") == 1


def _chromium() -> str | None:
    names = (os.environ.get("IMITWALK_CHROMIUM"), "chromium", "chromium-browser", "google-chrome")
    return next((p for n in names if n and (p := shutil.which(n))), None)


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    exe = _chromium()
    if exe is None:
        _missing("no Chromium binary found (apt-get install chromium, or set IMITWALK_CHROMIUM)")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.fail(
            "the browser test needs the playwright package (pip install playwright; "
            "it drives the system Chromium, so never run `playwright install`)"
        )
    with sync_playwright() as pw:
        profile = tmp_path_factory.mktemp("chromium-profile")
        ctx = pw.chromium.launch_persistent_context(
            str(profile),
            executable_path=exe,
            headless=True,
            args=CHROMIUM_ARGS,
            viewport={"width": 1200, "height": 900},
            offline=True,
        )
        yield ctx
        ctx.close()


@pytest.mark.parametrize("which", ["report", "bare_report"])
def test_report_in_a_real_browser(request, browser, which, tmp_path):
    path = request.getfixturevalue(which)[0]
    page = browser.new_page()
    problems: list[str] = []
    page.on(
        "console",
        lambda m: problems.append(f"console {m.type}: {m.text}") if m.type == "error" else None,
    )
    page.on("pageerror", lambda e: problems.append(f"page error: {e}"))
    page.on("requestfailed", lambda r: problems.append(f"request failed: {r.url[:100]}"))
    page.goto(path.resolve().as_uri(), wait_until="load")
    ready = "(v => v.readyState >= 1 || v.error)(document.querySelector('video'))"
    page.wait_for_function(ready, timeout=15_000)  # the video's metadata decoded, or failed
    images = page.evaluate("""() => [...document.images].map(i => ({alt: i.alt,
        natural: i.naturalWidth, w: i.getBoundingClientRect().width,
        h: i.getBoundingClientRect().height, ok: i.complete}))""")
    video = page.evaluate("""() => { const v = document.querySelector('video');
        const r = v.getBoundingClientRect();
        return {w: r.width, h: r.height, vw: v.videoWidth, vh: v.videoHeight,
                duration: v.duration, error: v.error && v.error.code}; }""")
    shot = tmp_path / f"{which}.png"
    page.screenshot(path=str(shot), full_page=True)
    page.close()
    assert not problems, problems
    alts = {i["alt"] for i in images}
    expected = FIGURES if which == "report" else FIGURES - {"film strip: human", "push recovery"}
    assert alts == expected, alts ^ expected
    for i in images:
        assert i["ok"] and i["natural"] > 0 and i["w"] > 0 and i["h"] > 0, i
    assert video["error"] is None and video["vw"] > 0 and video["duration"] > 0, video
    assert video["w"] > 0 and video["h"] > 0, video
    assert shot.stat().st_size > 10_000


def test_a_backward_walk_shows_its_clip_played_backward(robot):
    """The report's human row of a backward run (``learn --backward``) is the clip's gait
    cycle in reverse: the same frames, the other way round, and it says so."""
    import matplotlib.pyplot as plt

    from imitwalk.evidence.media import human_strip
    from imitwalk.mocap import default_clip, load_motion
    from imitwalk.step.pipeline import gait_from_motion
    from imitwalk.step.style import reversed_in_time

    fwd = gait_from_motion(load_motion(default_clip()), robot)
    back = replace(fwd, style=reversed_in_time(fwd.style))
    titles = {}
    for name, gait in (("fwd", fwd), ("back", back)):
        fig, missing = human_strip(gait, 6)
        assert missing is None and fig is not None
        titles[name] = [a.get_title() for a in fig.axes]
        titles[name + "_sup"] = fig.get_suptitle()
        plt.close(fig)
    assert "played backward" in titles["back_sup"] and "played backward" not in titles["fwd_sup"]
    frames = {k: [int(t.split()[1]) for t in titles[k]] for k in ("fwd", "back")}  # "frame N"
    assert frames["back"][0] == frames["fwd"][0] and frames["back"][1:] == frames["fwd"][:0:-1]
