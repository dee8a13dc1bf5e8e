"""What the reference search did: a typed record of its trials (pure Python).

:func:`~imitwalk.retarget.search.search_params` returns one; a reference keeps it
(:attr:`~imitwalk.retarget.reference.Reference.search`) and its file stores it as a JSON
object of the same keys.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields
from typing import Any

__all__ = ["SearchReport"]


@dataclass(frozen=True)
class SearchReport:
    """The reference search's report.

    Attributes:
        method: how the candidates were walked (open loop, or under a learned law).
        score: how a candidate is scored, in words.
        evaluations: candidates tried; sim_seconds: simulated time they walked [s];
            wall_seconds: the search's wall time [s].
        best: the best candidate: ``params`` (a
            :class:`~imitwalk.retarget.params.GaitParams` as a dict), ``score`` and its
            ``runs`` (one dict per robot and scale: seed, fell, seconds, progress ratio,
            heading drift).
        history: every candidate, as ``best``, with its ``generation`` and ``candidate``
            index.
        config: the :class:`~imitwalk.retarget.search.SearchConfig` it ran with, as a
            dict; bounds: each parameter's range, scaled to the robot's leg.
    """

    method: str = ""
    score: str = ""
    evaluations: int = 0
    sim_seconds: float = 0.0
    wall_seconds: float = 0.0
    best: dict[str, Any] = field(default_factory=dict)
    history: tuple[dict[str, Any], ...] = ()
    config: dict[str, Any] | None = None
    bounds: dict[str, Any] | None = None

    @property
    def best_score(self) -> float:
        """The best candidate's score (NaN if the report does not say)."""
        score = self.best.get("score") if isinstance(self.best, dict) else None
        return float(score) if isinstance(score, int | float) else float("nan")

    def to_dict(self) -> dict[str, Any]:
        """Plain-JSON dictionary (the reference file's ``search`` object)."""
        out = asdict(self)
        out["history"] = list(self.history)
        return out

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> SearchReport | None:
        """The report stored in a reference file (``None`` for an empty object: the
        reference was not searched)."""
        if not d:
            return None
        known = {f.name for f in fields(cls)}
        kept = {k: v for k, v in d.items() if k in known}
        kept["history"] = tuple(kept.get("history") or ())
        return cls(**kept)
