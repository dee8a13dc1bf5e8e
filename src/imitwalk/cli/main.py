"""The ``imitwalk`` command line.

Every subcommand is a thin wrapper over the library, in a module of :mod:`imitwalk.cli`
by concept (``retarget_commands``, ``learn_commands``, ``judge_commands``, ...). Errors
the library raises on purpose (:class:`~imitwalk.errors.ImitwalkError`) print one line
on stderr and exit with status 2; no traceback.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from collections.abc import Sequence
from typing import TextIO

from imitwalk.cli import (
    demo,
    export_commands,
    judge_commands,
    learn_commands,
    motion_commands,
    navigate_commands,
    retarget_commands,
    rl_commands,
    robot_commands,
    sweep_commands,
)
from imitwalk.errors import ImitwalkError
from imitwalk.sim.protocol import PROTOCOLS
from imitwalk.sim.types import ENGINES

__all__ = ["build_parser", "main"]


def _robot_args(p: argparse.ArgumentParser, positional: bool = True) -> None:
    if positional:
        p.add_argument("robot", help="built-in robot (hoap2), an MJCF .xml, or a joint-map .json")
    else:
        p.add_argument("--robot", default="hoap2", help="robot (default hoap2)")
    p.add_argument("--joint-map", help="joint-map JSON for an MJCF robot")


def _engine_arg(p: argparse.ArgumentParser, default: str | None, what: str) -> None:
    p.add_argument(
        "--engine",
        default=default,
        choices=ENGINES,
        help=f"physics engine (bullet: the same robot on PyBullet; default: {what})",
    )


def _mocap_args(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "file",
        nargs="?",
        help="mocap file (.bvh, .amc, .c3d, DeepMimic .txt) or the robot's motion (GMR .pkl, "
        "LocoMuJoCo .npz); default: pybullet's humanoid3d_walk",
    )
    p.add_argument("--skeleton", help="the ASF of an AMC file (default: the .asf beside it)")
    p.add_argument("--units", help="BVH length unit: m, cm, mm, inch, cmu (default: detect)")
    p.add_argument(
        "--up",
        choices=("x", "y", "z", "-x", "-y", "-z"),
        help="the file's up axis, e.g. --up=-x (BVH, ASF/AMC, C3D; default: from the motion)",
    )
    p.add_argument(
        "--joint-names",
        metavar="FILE.json",
        help='BVH: keypoint -> joint name, e.g. {"l_knee": "LowerLeg_L"} (default: by name/shape)',
    )


def _command_args(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("commanded gait (default: straight ahead on level ground)")
    g.add_argument(
        "--turn", type=float, metavar="DEG", help="turn per gait cycle at scale 1, + left"
    )
    g.add_argument(
        "--side", type=float, metavar="M", help="sidestep per gait cycle at scale 1, + left"
    )
    g.add_argument(
        "--forward", type=float, metavar="F", help="forward stride, a fraction of the human's (1)"
    )
    g.add_argument("--slope", type=float, metavar="DEG", help="ground slope to walk on, + uphill")


def _settings(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a setting, e.g. search_config.generations=3 (repeatable)",
    )


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every subcommand."""
    from imitwalk import __version__

    p = argparse.ArgumentParser(prog="imitwalk", description=__doc__.splitlines()[0])
    p.add_argument("--version", action="version", version=f"imitwalk {__version__}")
    sub = p.add_subparsers(dest="command", required=True)
    _add_robot(sub)
    _add_retarget(sub)
    _add_playback(sub)
    _add_learn(sub)
    _add_evaluate(sub)
    _add_report(sub)
    rl_commands.add_parser(sub, PROTOCOLS)
    export_commands.add_parser(sub)
    motion_commands.add_parser(sub)
    sweep_commands.add_parser(sub)
    navigate_commands.add_parser(sub, PROTOCOLS)
    _add_demo(sub)
    return p


def _add_robot(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """The ``robot`` group: ``robot info``, ``robot stand`` and ``robot import``."""
    robot = sub.add_parser("robot", help="inspect and test a robot model")
    rsub = robot.add_subparsers(dest="robot_command", required=True)
    info = rsub.add_parser("info", help="joints, limits, mass, height, sensors, rates")
    _robot_args(info)
    info.add_argument("--json", action="store_true", help="print JSON")
    info.set_defaults(func=robot_commands.robot_info)
    stand = rsub.add_parser(
        "stand",
        help="hold the standing posture; report tilt and forces, exit 2 if it does not stand "
        "(tilt over 20 deg, sinking, still tipping: the check learn makes)",
    )
    _robot_args(stand)
    stand.add_argument("--seconds", type=float, default=10.0, help="simulated seconds (10)")
    stand.add_argument("--json", action="store_true", help="print JSON")
    stand.set_defaults(func=robot_commands.robot_stand)
    imp = rsub.add_parser("import", help="draft a joint map from an MJCF file (never edits it)")
    imp.add_argument("mjcf", help="the robot's MJCF .xml")
    imp.add_argument("--out", required=True, help="the joint map to write (.json)")
    imp.add_argument(
        "--force", action="store_true", help="replace --out if it exists (its edits are lost)"
    )
    imp.add_argument("--json", action="store_true", help="print JSON")
    imp.set_defaults(func=robot_commands.robot_import)


def _add_retarget(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """The ``retarget`` subcommand's arguments."""
    rt = sub.add_parser("retarget", help="mocap -> robot joint trajectory (.npz)")
    _mocap_args(rt)
    _robot_args(rt, positional=False)
    rt.add_argument("--out", required=True, help="output .npz")
    rt.add_argument(
        "--mapping",
        default="walkable",
        choices=("walkable", "paper"),
        help="walkable: IK on the robot (default); paper: human-sized skeleton",
    )
    rt.add_argument(
        "--no-search",
        action="store_true",
        help="skip the reference-parameter search (use the defaults or --set)",
    )
    _settings(rt)
    _command_args(rt)
    rt.add_argument("--json", action="store_true", help="print JSON")
    rt.set_defaults(func=retarget_commands.retarget)


def _add_playback(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """The ``playback`` subcommand's arguments."""
    pb = sub.add_parser("playback", help="play a reference open loop on nominal + perturbed robots")
    pb.add_argument("reference", help="a .npz written by retarget")
    pb.add_argument("--scale", type=float, default=0.5, help="stride scale (0.5)")
    pb.add_argument("--seconds", type=float, default=20.0, help="simulated seconds per robot (20)")
    pb.add_argument("--models", type=int, default=6, help="robots: nominal + perturbed (6)")
    pb.add_argument("--robot", default=None, help="robot (default: the reference's)")
    pb.add_argument("--joint-map", help="joint-map JSON for an MJCF robot")
    pb.add_argument("--workers", type=int, default=None, help="parallel processes (one per core)")
    _engine_arg(pb, "mujoco", "mujoco")
    pb.add_argument("--json", action="store_true", help="print JSON")
    pb.set_defaults(func=retarget_commands.playback)


def _add_learn(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """The ``learn`` subcommand's arguments."""
    ln = sub.add_parser(
        "learn",
        help="learn to walk a mocap clip: the clip's style on the robot's legs, a stepping "
        "gait whose gains are learned on training robots",
    )
    _mocap_args(ln)
    _robot_args(ln, positional=False)
    ln.add_argument("--out", required=True, help="run folder")
    ln.add_argument(
        "--reference",
        help="--variant extended or faithful: a .npz from retarget, learned as it is",
    )
    ln.add_argument(
        "--variant",
        default=None,
        choices=("step", "extended", "faithful"),
        help="step: the stepping gait, footsteps re-planned every tick (default); extended: "
        "the joint trajectory replayed with per-tick balance learned by trials and the "
        "paper's loop (the default with --reference); faithful: the paper as written",
    )
    ln.add_argument(
        "--backward",
        action="store_true",
        help="the stepping gait: learn the clip played backward in time, a backward walk",
    )
    ln.add_argument("--seed", type=int, default=0, help="random seed (0)")
    ln.add_argument("--resume", action="store_true", help="continue an interrupted run")
    ln.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a learning setting (e.g. stop=0.8, lqr.enabled=false), or a "
        "retargeting one with a retarget. prefix (repeatable)",
    )
    _command_args(ln)
    ln.add_argument("--json", action="store_true", help="print JSON")
    ln.set_defaults(func=learn_commands.learn)


def _add_evaluate(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """The ``evaluate`` subcommand's arguments."""
    ev = sub.add_parser(
        "evaluate", help="every controller of a run, side by side, on a protocol's robots"
    )
    ev.add_argument("run_dir", help="a run folder written by learn")
    ev.add_argument(
        "--protocol",
        metavar="NAME|FILE",
        default="eval",
        help="the robots: " + ", ".join(PROTOCOLS) + " (default eval), or a protocol .json",
    )
    ev.add_argument("--seconds", type=float, default=30.0, help="simulated seconds per robot (30)")
    ev.add_argument("--seeds", type=int, default=10, help="robots (10)")
    ev.add_argument(
        "--scale", type=float, default=None, help="judge at this scale (default: the one reached)"
    )
    ev.add_argument(
        "--controllers",
        metavar="A,B",
        help="which of the run's controllers (default: all of them, open_loop included)",
    )
    ev.add_argument(
        "--explain-falls",
        action="store_true",
        help="walk each fall again once per factor, that factor at nominal, and name the "
        "factors whose removal alone saves it",
    )
    ev.add_argument(
        "--push-recovery",
        action="store_true",
        help="instead: the largest kick survived, by direction and gait phase (nominal robot)",
    )
    ev.add_argument("--robot", default=None, help="robot (default: the run's)")
    ev.add_argument("--joint-map", help="joint-map JSON for an MJCF robot")
    ev.add_argument("--workers", type=int, default=None, help="parallel processes")
    ev.add_argument("--json", action="store_true", help="print JSON")
    ev.set_defaults(func=judge_commands.evaluate)


def _add_report(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """The ``report`` subcommand's arguments."""
    rp = sub.add_parser("report", help="write RUN_DIR/report.html (figures, film strips, video)")
    rp.add_argument("run_dir", help="a run folder written by learn")
    rp.add_argument(
        "--seconds",
        type=float,
        default=10.0,
        help="length of the replays [s] (10; a stepping run's last at least to its first "
        "kick and two cycles more)",
    )
    rp.add_argument("--robot", default=None, help="robot (default: the run's)")
    rp.add_argument("--joint-map", help="joint-map JSON for an MJCF robot")
    rp.add_argument("--json", action="store_true", help="print JSON")
    rp.set_defaults(func=judge_commands.report)


def _add_demo(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """The ``demo`` subcommand's arguments."""
    dm = sub.add_parser("demo", help="retarget the default clip, learn, evaluate, report")
    dm.add_argument("--out", default="imitwalk-demo", help="run folder (imitwalk-demo)")
    dm.add_argument("--json", action="store_true", help="print JSON")
    dm.set_defaults(func=demo.demo)


def _one_line_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: TextIO | None = None,
    line: str | None = None,
) -> None:
    """Print a warning as ``warning: <message>`` (no source line)."""
    print(f"warning: {message}", file=sys.stderr if file is None else file)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the process exit status."""
    args = build_parser().parse_args(argv)
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _one_line_warning
            return int(args.func(args) or 0)
    except ImitwalkError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # e.g. piped into `head`
        sys.stderr.close()
        return 0


if __name__ == "__main__":
    raise SystemExit(main())
