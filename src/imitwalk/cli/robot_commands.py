"""The ``imitwalk robot`` subcommands: ``info``, ``stand`` and ``import``."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from imitwalk.cli.progress import emit, progress
from imitwalk.cli.robot_args import robot_from, robot_label

__all__ = ["robot_import", "robot_info", "robot_stand"]


def robot_info(args: argparse.Namespace) -> int:
    from imitwalk.sim.mujoco import SimOptions

    r = robot_from(args)
    opt = SimOptions()
    joints = {
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
    }
    emit(
        {
            "name": r.name,
            "mjcf": str(r.mjcf),
            "dof": r.dof,
            "joints": joints,
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
        },
        args.json,
        finite=True,
    )
    return 0


def robot_stand(args: argparse.Namespace) -> int:
    """Hold the standing posture ``--seconds``; exit 2 with the stand check's one line if
    the robot does not stand (:mod:`imitwalk.sim.standing`)."""
    from imitwalk.cli.arg_checks import check_seconds
    from imitwalk.sim.standing import require_standing

    check_seconds(args.seconds)
    res = require_standing(robot_from(args), robot_label(args), seconds=args.seconds)
    emit(res.to_dict(), args.json, finite=True)
    return 0


def robot_import(args: argparse.Namespace) -> int:
    """Draft and write the joint map of an MJCF robot. A robot that does not stand in the
    drafted posture still gets its joint map written (exit 0): that file is where the user
    makes it stand. An existing ``--out`` is refused unless ``--force`` (its edits would be
    lost). Its summary then says ``"stands": false`` and a ``warning:`` line says
    what to change; ``robot stand`` and ``learn`` refuse it until it stands."""
    from imitwalk.errors import RobotError
    from imitwalk.fileio import atomic_write, check_writable
    from imitwalk.robots.draft import draft_joint_map
    from imitwalk.sim.standing import CHECK_SECONDS, stand_test

    out, mjcf = check_writable(args.out, "--out", RobotError), Path(args.mjcf)
    if out.exists() and mjcf.exists() and out.resolve() == mjcf.resolve():
        raise RobotError(f"--out {out} is the MJCF file itself; imitwalk never edits it")
    if out.exists() and not args.force:  # a joint map is where the user edits: keep it
        raise RobotError(
            f"--out {out} exists (a joint map you may have edited); give another --out, "
            "or --force to replace it"
        )
    draft = draft_joint_map(mjcf, out)
    stand = stand_test(draft.robot, seconds=CHECK_SECONDS)
    for line in (*draft.lines, stand.line()):
        progress(f"  {line}")
    atomic_write(out, lambda tmp: tmp.write_text(json.dumps(draft.jmap, indent=2) + "\n"))
    if not stand.stands:
        progress(f"warning: {stand.refusal(str(out))}; {out} is written for you to edit")
    r = draft.robot
    summary = {
        "out": str(out),
        "name": r.name,
        "dof": r.dof,
        "roles": list(r.joint_names),
        "total_mass_kg": r.total_mass,
        "standing_height_m": r.height,
        "stands": stand.stands,
        "stand": stand.to_dict(),
    }
    emit(summary, args.json, finite=True)
    return 0
