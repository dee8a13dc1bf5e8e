"""The ``imitwalk`` command line.

Every subcommand is a thin wrapper over the library. Errors the library raises on
purpose (:class:`~imitwalk.errors.ImitwalkError`) print one line on stderr and exit
with status 2; no traceback.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence

from imitwalk.errors import ImitwalkError

__all__ = ["build_parser", "main"]


def _emit(obj: dict, as_json: bool) -> None:
    if as_json:
        print(json.dumps(obj, indent=2, default=float))
        return
    for key, val in obj.items():
        if isinstance(val, dict | list) and len(json.dumps(val, default=float)) > 80:
            val = json.dumps(val, default=float)[:77] + "..."
        print(f"{key:>28}: {val}")


def _robot_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("robot", help="built-in robot name (hoap2), an MJCF .xml, or a joint-map .json")
    p.add_argument("--joint-map", help="joint-map JSON for an MJCF given as ROBOT")
    p.add_argument("--json", action="store_true", help="print JSON")


def _cmd_robot_info(args: argparse.Namespace) -> int:
    from imitwalk.robots import load_robot
    from imitwalk.sim import SimOptions

    r = load_robot(args.robot, args.joint_map)
    opt = SimOptions()
    info = {
        "name": r.name,
        "mjcf": str(r.mjcf),
        "dof": r.dof,
        "joints": {
            n: {
                "mjcf": j,
                "min_rad": float(lo),
                "max_rad": float(hi),
                "kp_nm_per_rad": float(kp),
                "torque_limit_nm": float(tl),
            }
            for n, j, (lo, hi), kp, tl in zip(
                r.joint_names, r.mj_joints, r.limits, r.kp, r.torque_limit, strict=True
            )
        },
        "total_mass_kg": r.total_mass,
        "standing_height_m": r.height,
        "standing_torso_height_m": r.torso_height,
        "sensors": {
            "gyro": r.gyro,
            "accelerometer": r.accelerometer,
            "foot_force": {s: list(v) for s, v in r.foot_force.items()},
            "all": list(r.sensors),
        },
        "control_hz": opt.control_hz,
        "physics_hz": opt.physics_hz,
    }
    _emit(info, args.json)
    return 0


def _cmd_robot_stand(args: argparse.Namespace) -> int:
    from imitwalk.robots import load_robot
    from imitwalk.standing import stand_test

    res = stand_test(load_robot(args.robot, args.joint_map), seconds=args.seconds)
    _emit(res.to_dict(), args.json)
    return 1 if res.fell else 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every subcommand."""
    p = argparse.ArgumentParser(prog="imitwalk", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True)

    robot = sub.add_parser("robot", help="inspect and test a robot model")
    rsub = robot.add_subparsers(dest="robot_command", required=True)
    info = rsub.add_parser("info", help="joints, limits, mass, height, sensors, rates")
    _robot_args(info)
    info.set_defaults(func=_cmd_robot_info)
    stand = rsub.add_parser("stand", help="hold the standing keyframe and report tilt and forces")
    _robot_args(stand)
    stand.add_argument("--seconds", type=float, default=10.0, help="simulated seconds (default 10)")
    stand.set_defaults(func=_cmd_robot_stand)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the process exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except ImitwalkError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    raise SystemExit(main())
