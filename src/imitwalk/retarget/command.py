"""Commanded gaits: turning, sidestepping and walking on a slope (pure NumPy).

The human clip gives one gait, straight ahead on level ground. A :class:`GaitCommand`
bends the robot's task-space plan (:mod:`imitwalk.retarget.plan`) into another one:

* **turn**: the walking frame yaws at a constant rate, so the path is an arc (or, with
  ``forward=0``, a turn on the spot); each foot lands turned to the frame's heading at
  its landing time, the pelvis follows the heading;
* **sidestep**: the walking frame also moves sideways at a constant speed, so each
  foot lands a little further to that side;
* **slope**: the gait is built for ground inclined along the walk: the soles stay flat on
  the ground, the pelvis (and so the upright torso) pitches into the hill and the centre
  of mass moves over the feet along gravity, by its height × tan(slope).

The plan is laid out in the *walking frame* — a point ``P(t)`` with heading ``θ(t)``
that moves forward by the stride and sideways by the sidestep, and yaws by the turn —
and every foothold, the centre of mass and the pelvis are placed relative to it. The
straight command is the identity: it gives back the straight plan exactly. Joint
angles of a steady cycle still repeat, so a commanded reference goes through PCA,
the embedding and the learner like a straight one; one cycle of it moves the walking
frame by a fixed rigid motion (:func:`cycle_motion`), which repeats.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from imitwalk.errors import ConfigError

__all__ = [
    "PATH_COLUMNS",
    "GaitCommand",
    "advance",
    "check_side",
    "cycle_motion",
    "place",
    "walking_frame",
]

#: Columns of a plan's ``path`` array: the walking frame's position x, y [m] and heading
#: [rad] on the ground, and the forward and sideways travel commanded so far [m]
#: (measured in the walking frame, so a turn's forward travel is its arc length).
PATH_COLUMNS = ("x", "y", "heading", "forward", "side")

#: Allowed ranges of the command's fields. The sidestep's is for a leg of
#: :data:`~imitwalk.retarget.params.REFERENCE_LEG`: a robot's own is scaled by its leg
#: (:func:`check_side`, when the plan is laid out).
LIMITS = {
    "turn_deg": (-30.0, 30.0),
    "side_m": (-0.05, 0.05),
    "forward": (0.0, 1.5),
    "slope_deg": (-10.0, 10.0),
}


#: The command-line flag of each field (``imitwalk retarget`` and ``learn``), which
#: messages name first; ``--set command.<field>=...`` sets the same value.
FLAGS = {"turn_deg": "--turn", "side_m": "--side", "forward": "--forward", "slope_deg": "--slope"}


def _out_of_range(name: str, value: float, lo: float, hi: float, note: str = "") -> ConfigError:
    """The one-line error for a command field outside ``[lo, hi]``, by its flag."""
    flag = FLAGS[name]
    return ConfigError(
        f"{flag} {value:g} (setting command.{name}): expected {lo:g} <= {flag} <= {hi:g}{note}"
    )


#: A command is built before the robot is known: its sidestep may be this many times
#: :data:`LIMITS`' (a robot up to this many times hoap2's leg); :func:`check_side` then
#: holds it to the robot's own.
SIDE_SLACK = 10.0


def check_side(command: GaitCommand, leg: float) -> None:
    """Refuse a sidestep beyond :data:`LIMITS`' scaled to a robot whose leg is ``leg`` [m].

    Raises:
        ConfigError: ``|side_m|`` is larger (the message gives this robot's range).
    """
    from imitwalk.retarget.params import leg_scaled

    lo, hi = (leg_scaled(x, leg) for x in LIMITS["side_m"])
    if not lo <= command.side_m <= hi:
        raise _out_of_range("side_m", command.side_m, lo, hi, " (scaled with this robot's leg)")


@dataclass(frozen=True)
class GaitCommand:
    """What the reference should do besides walking straight ahead on level ground.

    Turn and sidestep scale with the stride scale, like the stride does, so a learning
    run that climbs from scale 0.3 to 1 keeps the same path radius all the way.

    Attributes:
        turn_deg: heading change per gait cycle at scale 1 [deg]; positive turns left.
        side_m: sideways travel per gait cycle at scale 1 [m]; positive to the left.
            Where the closing step would bring the soles within ``FOOT_GAP`` of each
            other, the stance widens (see :func:`~imitwalk.retarget.plan.plan_walk`).
        forward: the forward stride as a fraction of the retargeted human stride
            (0 steps on the spot: with ``turn_deg`` a turn in place, with ``side_m`` a
            pure sidestep).
        slope_deg: ground slope along the walk the gait is built for [deg], positive
            uphill; :meth:`imitwalk.retarget.reference.Reference.sim_options` puts the
            robot on it.
    """

    turn_deg: float = 0.0
    side_m: float = 0.0
    forward: float = 1.0
    slope_deg: float = 0.0

    def __post_init__(self) -> None:
        for name, (lo, hi) in LIMITS.items():
            v = getattr(self, name)
            if name == "side_m":  # scaled with the robot's leg: checked by check_side
                lo, hi = lo * SIDE_SLACK, hi * SIDE_SLACK
            if not (np.isfinite(v) and lo <= v <= hi):
                raise _out_of_range(name, v, lo, hi)

    @property
    def straight(self) -> bool:
        """True for the human's own gait: straight ahead, full stride, level ground."""
        return self == GaitCommand()

    def describe(self) -> str:
        """The command in words, e.g. ``"turn 10° per cycle at scale 1; on a 3° slope"``."""
        if self.straight:
            return "straight ahead on level ground"
        per = [f"turn {self.turn_deg:g}°" * bool(self.turn_deg)]
        per.append(f"sidestep {self.side_m:g} m" * bool(self.side_m))
        per = [p for p in per if p]
        parts = [" and ".join(per) + " per cycle at scale 1"] if per else []
        if self.forward != 1.0:
            parts.append(f"stride × {self.forward:g}")
        if self.slope_deg:
            parts.append(f"on a {self.slope_deg:g}° slope")
        return "; ".join(parts)

    def to_dict(self) -> dict:
        """Plain dictionary."""
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict | None) -> GaitCommand:
        """The command stored in a reference (straight if ``d`` is empty)."""
        return cls(**(d or {}))


def walking_frame(
    e: np.ndarray, v: float, command: GaitCommand, scale: float, period: float, dt: float
) -> np.ndarray:
    """The walking frame per tick, ``(N, 5)`` in :data:`PATH_COLUMNS` order.

    Args:
        e: ``(N,)`` amplitude envelope (0 standing … 1 steady); the frame's speeds are
            scaled by it, as the stride is. v: forward speed at ``e = 1`` [m/s].
        command: the command; scale: stride scale; period: cycle time [s]; dt: tick [s].

    The frame starts at the origin, heading +x; its yaw rate is
    ``e · scale · turn_deg / period``, its sideways speed ``e · scale · side_m / period``.
    """
    e = np.asarray(e, dtype=float)
    w = np.radians(command.turn_deg) * scale / period  # [rad/s] at e = 1
    vs = command.side_m * scale / period  # [m/s] at e = 1

    def integral(rate: np.ndarray) -> np.ndarray:  # 0 at the first tick, as the plan's x
        return (np.cumsum(rate) - rate[0]) * dt

    heading = integral(e * w)
    vx, vy = e * v, e * vs
    c, s = np.cos(heading), np.sin(heading)
    x = integral(vx * c - vy * s)
    y = integral(vx * s + vy * c)
    return np.stack([x, y, heading, integral(vx), integral(vy)], axis=1)


def place(path: np.ndarray, t: float, local: np.ndarray) -> tuple[np.ndarray, float]:
    """A point ``local`` ``(2,)`` [m] of the walking frame at fractional tick ``t``, on the
    ground ``(2,)`` [m], and the frame's heading there [rad]."""
    k = np.arange(len(path))
    x, y, th = (float(np.interp(t, k, path[:, j])) for j in range(3))
    c, s = np.cos(th), np.sin(th)
    return np.array([x + c * local[0] - s * local[1], y + s * local[0] + c * local[1]]), th


def cycle_motion(path: np.ndarray, i: int, n: int) -> np.ndarray:
    """How one cycle from tick ``i`` (``n`` ticks) moves the walking frame, ``(5,)``: the
    displacement x, y in the frame at ``i`` [m], the heading change [rad], and the
    forward and sideways travel [m]."""
    d = path[i + n] - path[i]
    c, s = np.cos(path[i, 2]), np.sin(path[i, 2])
    return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1], d[2], d[3], d[4]])


def _se2(x: float, y: float, th: float) -> np.ndarray:
    c, s = np.cos(th), np.sin(th)
    return np.array([[c, -s, x], [s, c, y], [0.0, 0.0, 1.0]])


def advance(row: dict, anchor: np.ndarray, motion: np.ndarray, cycles: int) -> dict:
    """A plan row (one tick's arrays, :data:`imitwalk.retarget.reference.PLAN_KEYS`) of
    the loop moved on by ``cycles`` whole cycles.

    Args:
        row: ``{"l_sole": (3,), "r_sole": (3,), "com": (2,), "yaw": (2,), "path": (5,), ...}``.
        anchor: ``(5,)`` the walking frame at the loop's first tick (``path`` row).
        motion: ``(5,)`` one cycle's :func:`cycle_motion`; cycles: how many cycles on.

    Each cycle is the same rigid motion of the ground plane, ``G = A · M · A⁻¹`` with
    ``A`` the frame at the loop's start and ``M`` the motion in that frame; a straight
    walk's ``G`` is a shift by one stride.
    """
    if cycles == 0:
        return dict(row)
    dth = cycles * motion[2]
    if motion[2] == 0.0:  # no turn: a plain shift (exactly k strides for a straight walk)
        c, s = np.cos(anchor[2]), np.sin(anchor[2])
        dx, dy = cycles * motion[0], cycles * motion[1]
        g = np.array([[1.0, 0.0, c * dx - s * dy], [0.0, 1.0, s * dx + c * dy]])
    else:
        a = _se2(*anchor[:3])
        g = a @ np.linalg.matrix_power(_se2(*motion[:3]), cycles) @ np.linalg.inv(a)
    out = dict(row)
    for key in ("l_sole", "r_sole", "com", "path"):
        if key in row:
            p = np.array(row[key], dtype=float)
            p[:2] = g[:2, :2] @ p[:2] + g[:2, 2]
            out[key] = p
    if "yaw" in row:
        out["yaw"] = np.asarray(row["yaw"], dtype=float) + dth
    if "path" in row:
        out["path"][2] += dth
        out["path"][3:] += cycles * motion[3:]
    return out
