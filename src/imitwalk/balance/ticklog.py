"""The per-tick learner's log: one typed entry per stage's step (pure Python).

Each entry is one line of the run folder's ``log.jsonl``, with a ``stage`` key naming its
kind: a gain or reference setting chosen by trials (:class:`TrialsEntry`), an iteration
of the schedule (:class:`ScheduleEntry`), and the trust in the learned law
(:class:`TrustEntry`). :func:`entry_from_dict` reads a line back; ``to_dict`` writes it,
key for key as the learner always wrote it.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from typing import Any, ClassVar

from imitwalk.errors import RunError

__all__ = [
    "LogEntry",
    "ScheduleEntry",
    "TrialsEntry",
    "TrustEntry",
    "WalkSummary",
    "entry_from_dict",
]


@dataclass(frozen=True)
class WalkSummary:
    """Some walks in a few numbers: falls, robots, mean Γ of the robots that stayed up
    [rad²/s²] (``inf`` if none did), seconds walked in all [s], mean forward distance [m],
    mean |yaw drift| [deg] and that mean's standard error [deg] (0 below two walks)."""

    falls: int
    robots: int
    cost: float
    walked_s: float
    distance_m: float
    abs_yaw_deg: float
    abs_yaw_se_deg: float

    def to_dict(self) -> dict[str, Any]:
        """Plain-JSON dictionary (a row of the learning log's tables)."""
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> WalkSummary:
        """The summary among ``d``'s keys (others ignored)."""
        return cls(**{f.name: d[f.name] for f in fields(cls)})


@dataclass(frozen=True)
class TrialsEntry:
    """A gain (``channel`` and ``feature`` given) or a reference setting chosen by trials:
    the value ``kept`` of its ``gain``, at the trials' ``scale`` on ``protocol``'s training
    robots, and the ``table`` of every value walked (``value`` plus a
    :class:`WalkSummary`'s keys)."""

    STAGE: ClassVar[str] = "trials"
    gain: str
    kept: float
    scale: float
    protocol: str
    table: list[dict[str, Any]]
    channel: str | None = None
    feature: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """The log line."""
        pairs = (("channel", self.channel), ("feature", self.feature))
        feedback = {k: v for k, v in pairs if v is not None}
        return {
            "stage": self.STAGE,
            "gain": self.gain,
            **feedback,
            "kept": self.kept,
            "scale": self.scale,
            "protocol": self.protocol,
            "table": self.table,
        }


@dataclass(frozen=True)
class ScheduleEntry:
    """An iteration of the schedule: its ``scale``, ``iteration`` there and exploration
    noise, the ``walks`` of its robots, and the last model's error on them before it saw
    them (``held_out``; ``None`` on the first iteration)."""

    STAGE: ClassVar[str] = "schedule"
    scale: float
    iteration: int
    explore: float
    walks: WalkSummary
    held_out: dict[str, Any] | None = None

    def to_dict(self) -> dict[str, Any]:
        """The log line."""
        return {
            "stage": self.STAGE,
            "scale": self.scale,
            "iteration": self.iteration,
            "explore": self.explore,
            **self.walks.to_dict(),
            "held_out": self.held_out,
        }


@dataclass(frozen=True)
class TrustEntry:
    """How much of the learned law was kept: the fraction ``kept`` at the trials'
    ``scale``, and the ``table`` of every fraction walked (``fraction`` plus a
    :class:`WalkSummary`'s keys)."""

    STAGE: ClassVar[str] = "trust"
    scale: float
    kept: float
    table: list[dict[str, Any]]

    def to_dict(self) -> dict[str, Any]:
        """The log line."""
        return {"stage": self.STAGE, "scale": self.scale, "kept": self.kept, "table": self.table}


#: An entry of the per-tick learner's log.
LogEntry = TrialsEntry | ScheduleEntry | TrustEntry
_KINDS: dict[str, type[TrialsEntry] | type[ScheduleEntry] | type[TrustEntry]] = {
    k.STAGE: k for k in (TrialsEntry, ScheduleEntry, TrustEntry)
}


def entry_from_dict(d: dict[str, Any]) -> LogEntry:
    """The entry of a log line.

    Raises:
        RunError: the line is not an entry of this log (its stage, or a key, is wrong).
    """
    stage = d.get("stage")
    try:
        if stage == ScheduleEntry.STAGE:
            return ScheduleEntry(
                d["scale"], d["iteration"], d["explore"], WalkSummary.from_dict(d), d["held_out"]
            )
        if stage == TrialsEntry.STAGE:
            keys = ("gain", "kept", "scale", "protocol", "table", "channel", "feature")
            return TrialsEntry(**{k: d[k] for k in keys if k in d})
        if stage == TrustEntry.STAGE:
            return TrustEntry(d["scale"], d["kept"], d["table"])
    except (KeyError, TypeError) as exc:
        raise RunError(f"a {stage} line of the learning log lacks {exc}") from None
    raise RunError(f"a learning log line of stage {stage!r}; expected one of {', '.join(_KINDS)}")
