"""``imitwalk convert``: a reference or a robot motion written in the field's formats."""

from __future__ import annotations

import argparse
from pathlib import Path

from imitwalk.cli.progress import emit, progress
from imitwalk.cli.robot_args import robot_from

__all__ = ["add_parser", "convert"]

#: What ``--to`` writes, and the extension of each.
TARGETS = {"gmr": ".pkl", "locomujoco": ".npz"}
#: A reference's gait cycles written by default, and at most (each about a second).
CYCLES, MAX_CYCLES = 4, 1000


def _is_reference(path: Path) -> bool:
    """An imitwalk reference ``.npz`` (not a LocoMuJoCo trajectory, which has ``qpos``).

    The archive is read by the checked reader that ``playback`` uses
    (:func:`~imitwalk.readback.read_npz`), so a missing, empty, truncated or corrupt
    ``.npz`` of either kind is one line (MocapError), never a zip or zlib traceback.
    """
    from imitwalk.errors import MocapError
    from imitwalk.readback import read_npz

    arrays = read_npz(path, "a reference .npz (from retarget) or a LocoMuJoCo .npz", MocapError)
    return "qpos" not in arrays


def convert(args: argparse.Namespace) -> int:
    from imitwalk.errors import ConfigError, unknown_name
    from imitwalk.fileio import check_writable
    from imitwalk.retarget.motionfiles import read_robot_motion, write_gmr, write_locomujoco
    from imitwalk.retarget.robotmotion import motion_of_reference

    if args.to not in TARGETS:
        raise unknown_name("format", args.to, TARGETS, ConfigError)
    out = Path(args.out)
    if out.suffix.lower() != TARGETS[args.to]:
        raise ConfigError(f"--to {args.to} writes a {TARGETS[args.to]} file, not {out.name}")
    if args.cycles is not None and not 1 <= args.cycles <= MAX_CYCLES:
        raise ConfigError(f"--cycles {args.cycles}: expected 1 to {MAX_CYCLES}")
    check_writable(out)
    src = Path(args.source)
    if src.is_dir():
        from imitwalk.errors import MocapError

        raise MocapError(
            f"{src} is a folder; give a reference .npz, a GMR .pkl or a LocoMuJoCo .npz"
        )
    if src.suffix.lower() == ".npz" and _is_reference(src):
        from imitwalk.retarget import Reference

        ref = Reference.load(src)
        if args.robot is None:  # the robot the reference was retargeted to
            args.robot = ref.provenance.robot or ref.robot
            args.joint_map = args.joint_map or ref.provenance.joint_map
        robot = robot_from(args)
        cycles = CYCLES if args.cycles is None else args.cycles
        motion = motion_of_reference(ref, robot, args.scale, cycles)
    else:
        given = [
            f for f, v in (("--scale", args.scale), ("--cycles", args.cycles)) if v is not None
        ]
        if given:
            raise ConfigError(
                f"{' and '.join(given)}: only for a reference .npz (from retarget); "
                f"{src.name} is a robot motion, written as it is"
            )
        args.robot = args.robot or "hoap2"
        robot = robot_from(args)
        motion = read_robot_motion(src, robot)
    (write_gmr if args.to == "gmr" else write_locomujoco)(motion, robot, out)
    progress(f"convert: {src} -> {out} ({args.to}, {motion.n_frames} frames at {motion.fps:g} Hz)")
    emit(
        {
            "out": str(out),
            "format": args.to,
            "robot": robot.name,
            "frames": motion.n_frames,
            "fps": motion.fps,
        },
        args.json,
    )
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """The ``convert`` subcommand's arguments."""
    p = sub.add_parser(
        "convert",
        help="write a reference (.npz from retarget) or a robot motion as GMR's .pkl or "
        "LocoMuJoCo's .npz",
    )
    p.add_argument("source", help="a reference .npz, a GMR .pkl or a LocoMuJoCo .npz")
    p.add_argument("--to", required=True, metavar="FORMAT", help="gmr or locomujoco")
    p.add_argument(
        "--out", required=True, help="the file to write (.pkl for gmr, .npz for locomujoco)"
    )
    p.add_argument("--robot", default=None, help="the robot (default: the reference's; hoap2)")
    p.add_argument("--joint-map", help="joint-map JSON for an MJCF robot")
    p.add_argument(
        "--scale", type=float, default=None, help="a reference's stride scale (its largest)"
    )
    p.add_argument(
        "--cycles",
        type=int,
        default=None,
        help=f"a reference's gait cycles after the start ({CYCLES}; at most {MAX_CYCLES})",
    )
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=convert)
