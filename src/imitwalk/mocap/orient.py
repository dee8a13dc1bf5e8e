"""Up axis, direction of travel and length unit of a clip, told by its animated skeleton.

Nothing here looks at the rest pose: a rest pose may lie along any axis, and the
posture may come from the rotation channels alone. All inputs are joint positions over
the frames, in file axes and file units.

* **Up** (:func:`decide_up`): the signed file axis along which the head (or, without a
  named head, the middle of the upper body) is highest above the feet, by at least
  :data:`MIN_HEAD_LEGS` leg lengths. If two axes qualify and neither dominates the
  other 1.6 : 1, the one along which the lowest foot stays within
  :data:`MAX_GROUND_SPREAD_LEGS` leg lengths of one height wins; otherwise the clip is
  refused, naming ``--up``.
* **Forward** (:func:`decide_forward`): the pelvis's travel across the ground from the
  first frame to the last; on a treadmill (less than half a leg length of travel), the
  way the toes point.
* **Units** (:func:`decide_units`): the unit that makes the leg (hip -> knee -> ankle)
  and the pelvis height above the lowest foot closest to an adult's
  (:data:`TYPICAL_LEG_M`, :data:`TYPICAL_PELVIS_M`), among those that put the leg
  within :data:`~imitwalk.mocap.bounds.LEG_RANGE_M`; two units nearly as close are
  refused, naming ``--units``.
"""

from __future__ import annotations

import numpy as np

from imitwalk.errors import MocapError
from imitwalk.mocap._common import UP_AXES
from imitwalk.mocap.bounds import LEG_RANGE_M

__all__ = [
    "MAX_GROUND_SPREAD_LEGS",
    "MIN_HEAD_LEGS",
    "TYPICAL_LEG_M",
    "TYPICAL_PELVIS_M",
    "UNITS_FLAG",
    "UP_FLAG",
    "UP_VECTORS",
    "axis_name",
    "decide_forward",
    "decide_units",
    "decide_up",
]

UP_FLAG = "pass --up=" + "|".join(UP_AXES)  # "=": argparse takes "--up -x" for a flag
UNITS_FLAG = "pass --units"
#: Signed file axis -> unit vector.
UP_VECTORS: dict[str, np.ndarray] = {
    a: (-1.0 if a.startswith("-") else 1.0) * np.eye(3)["xyz".index(a[-1])] for a in UP_AXES
}
#: The head must be this many leg lengths above the feet (median over frames) [-].
MIN_HEAD_LEGS = 0.8
#: The lowest foot of a level walk stays within this band (5-95 %) [leg lengths].
MAX_GROUND_SPREAD_LEGS = 0.2
#: An adult's leg (hip -> knee -> ankle) and pelvis height above the ground [m].
TYPICAL_LEG_M, TYPICAL_PELVIS_M = 0.8, 0.95
_UNIT_MARGIN = 0.2  # two units closer than this (log-distance) are ambiguous


def axis_name(v: np.ndarray) -> str:
    """The signed file axis nearest ``v`` ``(3,)``, e.g. ``"+z"``."""
    k = int(np.argmax(np.abs(v)))
    return f"{'-' if v[k] < 0 else '+'}{'xyz'[k]}"


def _join(items: list[str]) -> str:
    return ", ".join(items[:-1]) + " and " + items[-1] if len(items) > 1 else "".join(items)


def decide_up(top: np.ndarray, feet: np.ndarray, leg: float, src: str) -> tuple[str, str]:
    """The up axis of a clip, and why.

    Args:
        top: ``(T, 3)`` head (or upper-body centre) positions; feet: ``(T, K, 3)`` the
            ankles and toes; leg: the leg length, all in file axes and units.

    Returns:
        ``(up, reason)``, ``up`` one of :data:`~imitwalk.mocap._common.UP_AXES`.

    Raises:
        MocapError: no axis, or more than one, fits (naming ``--up``).
    """
    rise = {a: float(np.median((top - feet.mean(axis=1)) @ e)) / leg for a, e in UP_VECTORS.items()}
    if not all(np.isfinite(r) for r in rise.values()):
        raise MocapError(f"{src}: cannot tell the up axis: the joint positions are not finite")
    order = sorted(rise, key=rise.__getitem__, reverse=True)
    best, second = order[0], order[1]
    if rise[best] < MIN_HEAD_LEGS:
        raise MocapError(
            f"{src}: cannot tell the up axis: the head is not above the feet along any axis "
            f"(at most {rise[best]:.2g} leg lengths, along {best}); {UP_FLAG}"
        )
    fits = [a for a in order if rise[a] >= MIN_HEAD_LEGS]
    if len(fits) > 1 and rise[best] >= 1.6 * rise[second]:
        fits = [best]
    why = f"the head is {rise[best]:.2g} leg lengths above the feet along {best}"
    if len(fits) > 1:
        spread = {}
        for a in fits:
            low = np.min(feet @ UP_VECTORS[a], axis=1)  # (T,) the lowest foot
            spread[a] = float(np.ptp(np.percentile(low, [5, 95]))) / leg
        level = [a for a in fits if spread[a] <= MAX_GROUND_SPREAD_LEGS]
        if len(level) != 1:
            where = "all of them" if len(level) == len(fits) else _join(level) or "none of them"
            raise MocapError(
                f"{src}: cannot tell the up axis: the head is above the feet along "
                f"{_join(fits)} alike, and the lowest foot keeps one height along {where}; "
                f"{UP_FLAG}"
            )
        fits = level
        why = f"the head is above the feet and the lowest foot keeps one height along {fits[0]}"
    return fits[0], why


def decide_forward(
    pelvis: np.ndarray, ankles: np.ndarray, toes: np.ndarray, up: np.ndarray, leg: float
) -> tuple[np.ndarray, str]:
    """The horizontal direction of travel ``(3,)`` (unit, file axes) and how it was told.

    Args:
        pelvis: ``(T, 3)``; ankles, toes: ``(T, 2, 3)``; up: ``(3,)`` unit; leg: leg length.
    """
    flat = np.eye(3) - np.outer(up, up)
    travel = flat @ (pelvis[-1] - pelvis[0])
    if np.linalg.norm(travel) >= 0.5 * leg:
        return travel / np.linalg.norm(travel), "the pelvis's travel"
    toes_fwd = flat @ np.median((toes - ankles).mean(axis=1), axis=0)
    if np.linalg.norm(toes_fwd) < 1e-9 * leg:
        return np.zeros(3), "none (no travel, feet without length)"
    return toes_fwd / np.linalg.norm(toes_fwd), "the way the toes point (no travel)"


def decide_units(leg: float, pelvis: float, units: dict[str, float], src: str) -> str:
    """The length unit (a key of ``units``: metres per unit) of a clip whose leg is ``leg``
    and whose pelvis is ``pelvis`` above the lowest foot, both in file units.

    Raises:
        MocapError: no unit, or two alike, fit (naming ``--units``).
    """
    lo, hi = LEG_RANGE_M
    fit = {u: s for u, s in units.items() if lo <= leg * s <= hi}
    if not fit:
        raise MocapError(
            f"{src}: the leg is {leg:.4g} file units long, which no unit of "
            f"{', '.join(units)} makes {lo:g}-{hi:g} m; {UNITS_FLAG}"
        )

    def miss(u: str) -> float:
        off = abs(np.log(leg * fit[u] / TYPICAL_LEG_M))
        if pelvis > 0:
            off = 0.5 * (off + abs(np.log(pelvis * fit[u] / TYPICAL_PELVIS_M)))
        return float(off)

    order = sorted(fit, key=miss)
    if len(order) > 1 and miss(order[1]) - miss(order[0]) < _UNIT_MARGIN:
        a, b = order[:2]
        raise MocapError(
            f"{src}: cannot tell the units: the leg is {leg * fit[a]:.3g} m in {a} and "
            f"{leg * fit[b]:.3g} m in {b}; {UNITS_FLAG} {a} or --units {b}"
        )
    return order[0]
