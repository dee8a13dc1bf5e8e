"""The retargeting pipeline: a clip in, a reference out (:func:`retarget`).

Two mappings: ``"walkable"`` (the default) solves a task-space gait plan by IK on the
robot itself, with its few parameters found by trials in simulation; ``"paper"`` is
the paper's own mapping (§2), IK on a human-sized copy of the robot's skeleton. This
module runs the IK and the trials, so it imports MuJoCo (through the solvers).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from imitwalk.errors import ConfigError, unknown_name
from imitwalk.mocap.motion import Motion
from imitwalk.retarget.command import GaitCommand, check_side
from imitwalk.retarget.human import build_paper
from imitwalk.retarget.ik import leg_geometry
from imitwalk.retarget.plan import GaitParams
from imitwalk.retarget.provenance import Provenance
from imitwalk.retarget.reference import Reference
from imitwalk.retarget.search import SearchConfig, Walker, search_params
from imitwalk.retarget.searchreport import SearchReport
from imitwalk.retarget.template import GaitTemplate, extract_template
from imitwalk.retarget.walkable import build_walkable
from imitwalk.robots import Robot

__all__ = [
    "MAPPINGS",
    "RetargetConfig",
    "RetargetResult",
    "retarget",
]

MAPPINGS = ("walkable", "paper")


@dataclass(frozen=True)
class RetargetConfig:
    """How a clip is retargeted.

    Attributes:
        mapping: ``"walkable"`` or ``"paper"``.
        control_hz: rate of the output trajectory [Hz].
        scales: stride scales the reference is solved at.
        search: run the parameter search (else ``params`` is used as is).
        params: reference parameters (the search's starting point).
        search_config: the search's budget.
        command: turn, sidestep, stride fraction and slope
            (:class:`~imitwalk.retarget.command.GaitCommand`; default straight, level).
    """

    CHOICES: ClassVar[dict] = {"mapping": MAPPINGS}

    mapping: str = "walkable"
    control_hz: float = 100.0
    scales: tuple[float, ...] = tuple(round(0.1 * i, 2) for i in range(1, 11))
    search: bool = True
    params: GaitParams = field(default_factory=GaitParams)
    search_config: SearchConfig = field(default_factory=SearchConfig)
    command: GaitCommand = field(default_factory=GaitCommand)

    @property
    def searches(self) -> bool:
        """True if :func:`retarget` searches the reference parameters: ``search`` on and
        the walkable mapping (the paper's mapping has no parameters to search)."""
        return self.search and self.mapping == "walkable"


@dataclass
class RetargetResult:
    """A reference and the figures that judge it (see :meth:`stats`)."""

    reference: Reference
    motion_frames: int
    motion_fps: float
    template: GaitTemplate
    frames_solved: int
    solve_seconds: float

    def stats(self) -> dict:
        """The figures ``imitwalk retarget --json`` prints."""
        ref = self.reference
        at_limit = sum(c["ticks"] for c in ref.clipped)
        total = ref.residual_mm.size * len(ref.joint_names)
        out = {
            "frames": self.motion_frames,
            "fps": self.motion_fps,
            "cycles_found": len(self.template.cycles),
            "cycles_used": self.template.meta.get("cycles_report", ""),
            "cycle_period_s": self.template.period,
            "human_stride_m": self.template.stride,
            "human_speed_mps": self.template.speed,
            "mapping": ref.mapping,
            "reference_frames": int(ref.loops.shape[1]),
            "reference_hz": 1.0 / ref.dt,
            "ik_residual_mm_mean": float(ref.residual_mm.mean()),
            "ik_residual_mm_max": float(ref.residual_mm.max()),
            "clipped_fraction": at_limit / total if total else 0.0,
            "clipped": ref.clipped,
            "frames_per_second_solved": self.frames_solved / max(self.solve_seconds, 1e-9),
            "params": ref.params.to_dict() if ref.params is not None else {},
        }
        out.update({k: v for k, v in ref.checks.items() if k != "scale"})
        if (s := ref.search) is not None:
            out["search"] = {
                "evaluations": s.evaluations,
                "sim_seconds": s.sim_seconds,
                "wall_seconds": s.wall_seconds,
                "best_score": s.best_score,
            }
        return out


def retarget(
    motion: Motion,
    robot: Robot,
    config: RetargetConfig | None = None,
    progress: Callable[[int, int, float, dict], None] | None = None,
    walker: Walker | None = None,
) -> RetargetResult:
    """Retarget ``motion`` to ``robot``.

    Args:
        motion: a loaded clip (see :func:`imitwalk.mocap.load_motion`).
        robot: the robot.
        config: settings; progress: optional ``callback(generation, total, score, params)``
            for the parameter search; walker: the
            search walks its candidates under a controller
            (:data:`~imitwalk.retarget.search.Walker`; ``None``: open loop).

    Raises:
        MocapError: the clip has no walking cycle. ConfigError: bad settings.
    """
    cfg = config or RetargetConfig()
    if cfg.mapping not in MAPPINGS:
        raise unknown_name("mapping", cfg.mapping, MAPPINGS, ConfigError)
    template = extract_template(motion, allow_turn=bool(cfg.command.turn_deg))
    dt = 1.0 / cfg.control_hz
    t0 = time.perf_counter()
    if cfg.mapping == "paper" and not cfg.command.straight:
        raise ConfigError("a turn, sidestep, stride fraction or slope needs mapping=walkable")
    if cfg.mapping == "paper":
        ref = build_paper(motion, template, robot, cfg.scales, dt)
        frames, seconds = ref.loops.shape[1], time.perf_counter() - t0
        report: SearchReport | None = None
    else:
        leg = leg_geometry(robot).leg
        check_side(cfg.command, leg)  # before any search: the sidestep scales with the leg
        # a lift left unset is a tenth of this robot's leg
        params, report = cfg.params.for_leg(leg), None
        if cfg.searches:
            params, report = search_params(
                template,
                robot,
                cfg.search_config,
                params,
                dt,
                progress=progress,
                command=cfg.command,
                walker=walker,
            )
        build = build_walkable(template, robot, params, cfg.scales, dt, command=cfg.command)
        ref, frames, seconds = build.reference, build.frames, build.seconds
    ref = replace(
        ref,
        search=report,
        source=motion.source,
        cycles=np.array(template.cycles, dtype=int).reshape(-1, 2),
        provenance=Provenance(
            searched=cfg.search,
            motion_format=motion.format,
            motion_fps=motion.fps,
            filled=tuple(motion.filled),
        ),
    )
    return RetargetResult(ref, motion.n_frames, motion.fps, template, frames, seconds)
