"""``imitwalk rl``: PPO on the walking environment, into a run folder the judge reads."""

from __future__ import annotations

import argparse
from pathlib import Path

from imitwalk.cli.progress import emit, progress

__all__ = ["rl"]


def _robot_setting(robot: str) -> str:
    """A robot as the environment records it: a name, or a joint map's absolute path."""
    return str(Path(robot).resolve()) if Path(robot).is_file() else robot


def rl(args: argparse.Namespace) -> int:
    from imitwalk.envs.setup import WalkConfig
    from imitwalk.errors import ConfigError
    from imitwalk.runs import RunDir

    try:
        import stable_baselines3  # noqa: F401
        import torch  # noqa: F401
    except ImportError:
        raise ConfigError(
            "imitwalk rl needs PyTorch and Stable-Baselines3: pip install 'imitwalk[rl]'"
        ) from None
    from imitwalk.envs.ppo import PPOConfig, train

    rd = RunDir(args.out)
    rd.check_writable()
    if args.base is not None and not args.residual:
        raise ConfigError("--base is the stepping run a residual adds to: pass --residual too")
    cfg = PPOConfig(budget=args.budget, envs=args.envs, seed=args.seed)
    walk = WalkConfig(
        clip=str(Path(args.file).resolve()) if args.file else None,
        robot=_robot_setting(args.robot),
        protocol=args.protocol,
        action="residual" if args.residual else "joints",
        run=str(Path(args.base).resolve()) if args.base else None,
        seconds=args.seconds,
    )
    summary = train(walk, cfg, args.out, resume=args.resume, progress=progress)
    out = summary.to_dict()
    out["out"] = str(Path(args.out))
    emit(out, args.json)
    return 0


def add_parser(
    sub: argparse._SubParsersAction[argparse.ArgumentParser], protocols: tuple[str, ...]
) -> None:
    """The ``rl`` subcommand's arguments."""
    p = sub.add_parser(
        "rl",
        help="train a PPO policy on the walking environment (needs: pip install 'imitwalk[rl]')",
    )
    p.add_argument("file", nargs="?", help="mocap clip (default: the embedded walk)")
    p.add_argument("--out", required=True, help="run folder")
    p.add_argument("--robot", default="hoap2", help="a built-in robot or a joint-map .json")
    p.add_argument(
        "--residual",
        action="store_true",
        help="offsets on imitwalk's stepping gait (default: joint targets, from scratch)",
    )
    p.add_argument(
        "--base",
        metavar="RUN",
        help="with --residual: the stepping run whose learned gains it adds to "
        "(default: the gains imitwalk ships)",
    )
    p.add_argument(
        "--budget",
        type=float,
        default=20_000.0,
        help="simulated seconds of experience (20000)",
    )
    p.add_argument(
        "--protocol",
        metavar="NAME|FILE",
        default="hard",
        help="the training robots' protocol: " + ", ".join(protocols) + " (default hard)",
    )
    p.add_argument("--seconds", type=float, default=20.0, help="episode length [s] (20)")
    p.add_argument("--envs", type=int, default=2, help="environment processes (2)")
    p.add_argument("--seed", type=int, default=0, help="random seed (0)")
    p.add_argument("--resume", action="store_true", help="continue an interrupted run")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=rl)
