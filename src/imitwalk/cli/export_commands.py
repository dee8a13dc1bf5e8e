"""``imitwalk export``: a run's controller written for :mod:`imitwalk.runtime`."""

from __future__ import annotations

import argparse

from imitwalk.cli.arg_checks import check_scale
from imitwalk.cli.progress import emit, progress
from imitwalk.cli.robot_args import robot_from, run_robot

__all__ = ["add_parser", "export"]


def export(args: argparse.Namespace) -> int:
    from imitwalk import readback
    from imitwalk.judge.export import export_run
    from imitwalk.runs import RunDir
    from imitwalk.runtime.bundle import MANIFEST, check_out

    rd = RunDir(args.run_dir)
    cfg = rd.read_json("config.json")
    check_scale(args.scale)
    check_out(args.out)  # before anything is built: a file, a link, a folder of other things
    RunDir(args.out).check_writable("--out")  # its parent missing, or not writable
    args.robot, args.joint_map = run_robot(rd, cfg)
    robot = robot_from(args)
    out = export_run(rd.path, robot, args.out, args.controller, args.scale)
    m = readback.read_json(out / MANIFEST, "the export's manifest")
    progress(f"export: {m['controller']} controller of {rd.path} -> {out}")
    emit(
        {
            "out": str(out),
            "controller": m["controller"],
            "source": m["source"],
            "robot": m["robot"],
            "rate_hz": m["control"]["rate_hz"],
            "sensors": m["sensors"]["size"],
            "joints": len(m["joints"]),
            "files": sorted(m["files"]),
        },
        args.json,
    )
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """The ``export`` subcommand's arguments."""
    p = sub.add_parser(
        "export",
        help="write a run's controller as a folder that imitwalk.runtime plays on a robot",
    )
    p.add_argument("run_dir", help="a stepping run (learn) or a PPO run (rl)")
    p.add_argument(
        "--out",
        required=True,
        help="the folder to write: new, empty, or an earlier export (replaced); not a symlink",
    )
    p.add_argument(
        "--controller",
        default=None,
        help="which of the run's controllers (default: learned; rl for a PPO run)",
    )
    p.add_argument(
        "--scale",
        type=float,
        default=None,
        help="the stride scale, one the run learned (default: the one reached)",
    )
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=export)
