"""Typed records of a protocol's judgement (pure Python).

:func:`imitwalk.judge.verdict.judge_protocol` returns a :class:`ProtocolVerdict`; its
:meth:`~ProtocolVerdict.to_dict` is the JSON that ``imitwalk evaluate`` prints and writes
as ``protocol_NAME.json``, and :meth:`~ProtocolVerdict.from_dict` reads such a file back
(the report's tables do). :func:`imitwalk.judge.pushes.push_recovery` returns a
:class:`PushVerdict`, written as ``push_recovery.json``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, fields
from typing import TYPE_CHECKING, Any, TypeVar

from imitwalk.errors import RunError

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

__all__ = [
    "ControllerVerdict",
    "JudgeSettings",
    "ProtocolId",
    "ProtocolVerdict",
    "PushSettings",
    "PushSide",
    "PushVerdict",
    "SeedRow",
]


T = TypeVar("T")


def _read(build: Callable[[], T], where: str, what: str) -> T:
    """``build()``, with a file of another layout (an older release's) as one line."""
    try:
        return build()
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise RunError(
            f"{where}: not {what} of this imitwalk ({type(exc).__name__}: {exc})"
        ) from None


@dataclass(frozen=True)
class SeedRow:
    """One robot's walk under one controller.

    Attributes:
        seed: the protocol's robot; fell: it fell; fall_time_s: when [s] (``None``: it did
        not); forward_distance_m: torso travel along the heading [m]; furthest: the factor
        the robot drew furthest from nominal; yaw_drift_deg: heading change beyond the
        commanded turn [deg]; saved_by: for a fall explained by
        :func:`~imitwalk.judge.explain.explain_falls`, the factors whose removal alone
        lets it walk (empty: none does); ``None``: not asked, or it did not fall.
    """

    seed: int
    fell: bool
    fall_time_s: float | None
    forward_distance_m: float
    furthest: str | None
    yaw_drift_deg: float
    saved_by: tuple[str, ...] | None = None


@dataclass(frozen=True)
class ControllerVerdict:
    """One controller on every robot of a protocol.

    Attributes:
        robots, survived, falls: counts; survival: survived ÷ robots, with its 95 % Wilson
        interval ``survival_ci95``; distance_m [m], speed_mps [m/s], abs_yaw_deg [deg]:
        means over the robots (``None`` for none); progress_ratio_min: the slowest robot's
        progress ratio, its distance over the one commanded over the whole judged time
        (1: the commanded walk; a robot that falls at once: about 0, at most its
        standing height over that distance; :func:`~imitwalk.sim.metrics.walk_metrics`);
        falls_by_furthest_factor: falls counted under the factor each robot drew furthest
        from nominal; per_seed: the robots' rows, in seed order;
        falls_saved_by_factor: with the falls explained, factor → the falls its removal
        alone saves (a fall saved by two factors counts under both), and
        falls_no_single_factor: the falls no single removal saves (``None``: not asked).
    """

    robots: int
    survived: int
    falls: int
    survival: float
    survival_ci95: tuple[float, float]
    distance_m: float | None
    speed_mps: float | None
    abs_yaw_deg: float | None
    progress_ratio_min: float | None
    falls_by_furthest_factor: dict[str, int]
    per_seed: tuple[SeedRow, ...]
    falls_saved_by_factor: dict[str, int] | None = None
    falls_no_single_factor: int | None = None

    def explained(self) -> str | None:
        """The falls explained, as one line (``None``: not asked, or none fell)."""
        if self.falls_saved_by_factor is None or not self.falls:
            return None
        saved = ", ".join(f"{f} {n}" for f, n in self.falls_saved_by_factor.items() if n)
        return f"{saved or 'none'}; by no single factor: {self.falls_no_single_factor}"

    def to_dict(self) -> dict:
        """Plain-JSON dictionary."""
        out = asdict(self)
        out["survival_ci95"] = list(self.survival_ci95)
        out["per_seed"] = [_row_dict(r) for r in self.per_seed]
        return out

    @classmethod
    def from_dict(cls, d: dict) -> ControllerVerdict:
        """The record :meth:`to_dict` wrote."""
        rows = tuple(_row(r) for r in d["per_seed"])
        lo, hi = d["survival_ci95"]
        own = _own(cls, d)
        return cls(**{**own, "survival_ci95": (float(lo), float(hi)), "per_seed": rows})


def _own(cls: type[DataclassInstance], d: dict) -> dict[str, Any]:
    """``cls``'s fields as ``d`` holds them; a field later releases added with a default
    of ``None`` is ``None`` where ``d``, written before, lacks it."""
    return {
        f.name: d[f.name] if f.name in d or f.default is not None else None for f in fields(cls)
    }


def _row_dict(r: SeedRow) -> dict:
    out = asdict(r)
    out["saved_by"] = None if r.saved_by is None else list(r.saved_by)
    return out


def _row(r: dict) -> SeedRow:
    own = _own(SeedRow, r)
    if own["saved_by"] is not None:
        own["saved_by"] = tuple(own["saved_by"])
    return SeedRow(**own)


@dataclass(frozen=True)
class ProtocolId:
    """Which protocol: its name, version, and where it came from (a built-in's name, or
    its file's path)."""

    name: str
    version: int
    path: str = ""


@dataclass(frozen=True)
class JudgeSettings:
    """How it was judged: robots, seconds per robot [s], engine, stride scale, the
    controllers asked for, in order, and the first robot's seed."""

    seeds: int
    seconds: float
    engine: str
    scale: float | None
    controllers: tuple[str, ...]
    first: int = 0


@dataclass(frozen=True)
class ProtocolVerdict:
    """Every controller of a run on the same robots of a protocol.

    Attributes:
        protocol, settings: what was judged and how; controllers: name → its verdict;
        comparison: name → the paired comparison of its falls with open loop's
        (:func:`imitwalk.paper.evaluate.compare_falls`; empty without open loop).
    """

    protocol: ProtocolId
    settings: JudgeSettings
    controllers: dict[str, ControllerVerdict]
    comparison: dict[str, dict]

    def to_dict(self) -> dict:
        """Plain-JSON dictionary (the layout of ``protocol_NAME.json``)."""
        settings = asdict(self.settings)
        settings["controllers"] = list(self.settings.controllers)
        return {
            "protocol": asdict(self.protocol),
            "settings": settings,
            "controllers": {c: v.to_dict() for c, v in self.controllers.items()},
            "comparison": dict(self.comparison),
        }

    @classmethod
    def from_dict(cls, d: dict, where: str = "the verdict") -> ProtocolVerdict:
        """The record :meth:`to_dict` wrote (read from ``where``; a one-line
        :class:`~imitwalk.errors.RunError` for another layout)."""

        def build() -> ProtocolVerdict:
            st = d["settings"]
            return cls(
                protocol=ProtocolId(**d["protocol"]),
                settings=JudgeSettings(**{**st, "controllers": tuple(st["controllers"])}),
                controllers={
                    c: ControllerVerdict.from_dict(v) for c, v in d["controllers"].items()
                },
                comparison=dict(d.get("comparison", {})),
            )

        return _read(build, where, "a protocol verdict")


@dataclass(frozen=True)
class PushSettings:
    """How push recovery was measured: the stride scale, phases per gait cycle, kick
    directions, how long the robot must stay up after a kick [s], the largest kick tried
    and the bisection's resolution [m/s], and each phase's kick time [s]."""

    scale: float
    phases: int
    directions: tuple[str, ...]
    after_s: float
    top_mps: float
    resolution_mps: float
    kick_times_s: tuple[float, ...]


@dataclass(frozen=True)
class PushSide:
    """One controller's push recovery: the largest kick survived [m/s] per direction and
    phase (``table``), the least per direction, and the mean of the table."""

    table: dict[str, list[float]]
    min_by_direction: dict[str, float]
    mean: float


@dataclass(frozen=True)
class PushVerdict:
    """Push recovery of every controller of a run
    (:func:`imitwalk.judge.pushes.push_recovery`); JSON as ``push_recovery.json``."""

    settings: PushSettings
    controllers: dict[str, PushSide]

    def to_dict(self) -> dict:
        """Plain-JSON dictionary."""
        st = asdict(self.settings)
        st["directions"], st["kick_times_s"] = list(st["directions"]), list(st["kick_times_s"])
        return {"settings": st, "controllers": {c: asdict(v) for c, v in self.controllers.items()}}

    @classmethod
    def from_dict(cls, d: dict, where: str = "the push recovery") -> PushVerdict:
        """The record :meth:`to_dict` wrote (read from ``where``; a one-line
        :class:`~imitwalk.errors.RunError` for another layout)."""

        def build() -> PushVerdict:
            st = d["settings"]
            tuples = {k: tuple(st[k]) for k in ("directions", "kick_times_s")}
            settings = PushSettings(**{**st, **tuples})
            return cls(settings, {c: PushSide(**v) for c, v in d["controllers"].items()})

        return _read(build, where, "a push-recovery table")
