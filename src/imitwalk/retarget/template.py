"""The human gait, cut into cycles and averaged into a phase template (pure NumPy).

From a :class:`~imitwalk.mocap.Motion` this extracts what the robot's gait is built
from: cycle time, stride, stance and double-support timing, the swing foot's forward
progress and lift profiles, and the arm swing and trunk counter-rotation, each as a
function of the gait phase ψ ∈ [0, 1) (ψ = 0 at the left heel strike). Positions are
taken in the *ground* frame: a treadmill belt's motion (the stance foot sliding
backwards) is added back, so an overground walk and a treadmill walk give the same
template.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from imitwalk.errors import MocapError
from imitwalk.mocap.cycles import find_cycles, foot_contacts, heading, heel_strikes
from imitwalk.mocap.filters import period_frames, smooth
from imitwalk.mocap.motion import Motion
from imitwalk.mocap.selection import MAX_TURN_DEG, choose_cycles

__all__ = ["PHASES", "GaitTemplate", "extract_template"]

#: Samples per cycle of every phase profile.
PHASES = 100
_ARMS = ("l_shoulder", "r_shoulder", "l_elbow", "r_elbow", "l_wrist", "r_wrist", "neck")


@dataclass(frozen=True)
class GaitTemplate:
    """The averaged human gait cycle.

    Attributes:
        period: cycle time [s]; stride: distance per cycle [m]; leg_length: hip to
            ankle [m]; stance: stance fraction of a cycle, per foot (mean of both);
        double_support: double-support fraction per transition.
        swing_x: ``(PHASES,)`` swing foot's forward progress, 0 → 1 over the swing.
        swing_z: ``(PHASES,)`` swing foot's lift, 0 at lift-off and touch-down, peak 1.
        lift: peak lift of the mid-foot [m].
        shoulder, elbow: ``(PHASES, 2)`` left/right shoulder flexion (positive arm
            forward) and elbow flexion [rad] over ψ.
        waist: ``(PHASES,)`` yaw of the shoulder line relative to the hip line [rad].
        arms_measured: False if the clip has no arm keypoints (arm profiles are zero).
        cycles: ``(start, end)`` source frames of the cycles averaged (the straight,
            steady ones: :func:`~imitwalk.mocap.selection.choose_cycles`).
        meta: ``n_cycles``, ``loop``, ``cycle_choice`` (the
            :class:`~imitwalk.mocap.selection.CycleChoice`) and ``cycles_report`` (one
            line: the frames used and why, those left out and why).
    """

    period: float
    stride: float
    leg_length: float
    stance: float
    double_support: float
    swing_x: np.ndarray
    swing_z: np.ndarray
    lift: float
    shoulder: np.ndarray
    elbow: np.ndarray
    waist: np.ndarray
    arms_measured: bool
    cycles: tuple[tuple[int, int], ...]
    fps: float
    source: str
    meta: dict = field(default_factory=dict)

    @property
    def speed(self) -> float:
        """Walking speed [m/s]."""
        return self.stride / self.period

    @property
    def turn_deg(self) -> float:
        """The heading change per cycle [deg] (+ left): the mean over the cycles averaged
        (:class:`~imitwalk.mocap.selection.CycleChoice`), or 0 within
        :data:`~imitwalk.mocap.selection.MAX_TURN_DEG` (a straight walk's wander)."""
        choice = self.meta.get("cycle_choice")
        used = [c.turn_deg for c in choice.checks if c.used] if choice is not None else []
        turn = float(np.mean(used)) if used else 0.0
        return turn if abs(turn) > MAX_TURN_DEG else 0.0


def _unrolled(motion: Motion) -> tuple[dict[str, np.ndarray], int]:
    """Keypoints of a loop tiled three times (root drift carried on), and its period."""
    k, p = motion.keypoints, period_frames(motion)
    drift = k["pelvis"][p] - k["pelvis"][0] if p < motion.n_frames else np.zeros(3)
    drift[2] = 0.0
    return {n: np.concatenate([v[:p] + i * drift for i in range(3)]) for n, v in k.items()}, p


def _cyclic_interp(x: np.ndarray, n: int) -> np.ndarray:
    """Resample ``(L, ...)`` samples over one cycle to ``(n, ...)`` at ψ = i / n."""
    src = np.linspace(0.0, 1.0, len(x) + 1)[:-1]
    dst = np.arange(n) / n
    flat = x.reshape(len(x), -1)
    cols = [np.interp(dst, src, c, period=1.0) for c in flat.T]
    return np.stack(cols, axis=1).reshape((n, *x.shape[1:]))


def _phase_of(frame: float, a: int, b: int) -> float:
    return ((frame - a) / (b - a)) % 1.0


def _runs(mask: np.ndarray, start: int) -> np.ndarray:
    """Frames where ``mask`` switches from ``start``-valued (True: True→False)."""
    m = mask.astype(np.int8)
    d = np.diff(m)
    return np.flatnonzero(d == (-1 if start else 1)) + 1


def extract_template(
    motion: Motion, cutoff_hz: float = 6.0, *, allow_turn: bool = False
) -> GaitTemplate:
    """Average the straight, steady gait cycles of ``motion`` into a :class:`GaitTemplate`.

    Args:
        allow_turn: a turn is commanded, so cycles that turn may be used
            (:func:`~imitwalk.mocap.selection.choose_cycles`).

    Raises:
        MocapError: the clip holds no straight, steady walking cycle.
    """
    sm = smooth(motion, min(cutoff_hz, 0.4 * motion.fps))
    contacts = foot_contacts(sm)
    if motion.loop:
        kp, p = _unrolled(sm)
        strikes = heel_strikes(sm, "l")
        if len(strikes) == 0:
            raise MocapError(f"no walking cycle found in {motion.source}: no left heel strike")
        a = int(strikes[0]) % p
        cycles = [(a, a + p)]
        contacts = {f: np.tile(c[:p], 3) for f, c in contacts.items()}
    else:
        kp = sm.keypoints
        cycles = find_cycles(sm, "l")
    # a loop's turn shows in its raw frames (smoothing makes the loop periodic)
    choice = choose_cycles(motion if motion.loop else sm, cycles, allow_turn=allow_turn)
    cycles = list(choice.cycles)
    fwd_all = heading(sm)
    if motion.loop:
        fwd_all = np.tile(fwd_all[: period_frames(sm)], (3, 1))
    per = []
    for a, b in cycles:
        per.append(_one_cycle(kp, contacts, fwd_all, a, b, sm.fps))
    if not per:
        raise MocapError(f"no walking cycle found in {motion.source}")
    mean = {key: np.mean([c[key] for c in per], axis=0) for key in per[0]}
    arms = all(n in motion.keypoints for n in _ARMS)
    return GaitTemplate(
        period=float(mean["period"]),
        stride=float(mean["stride"]),
        leg_length=float(mean["leg"]),
        stance=float(mean["stance"]),
        double_support=float(mean["ds"]),
        swing_x=mean["swing_x"],
        swing_z=mean["swing_z"] / max(mean["swing_z"].max(), 1e-9),
        lift=float(mean["lift"]),
        shoulder=mean["shoulder"] if arms else np.zeros((PHASES, 2)),
        elbow=mean["elbow"] if arms else np.zeros((PHASES, 2)),
        waist=mean["waist"] if arms else np.zeros(PHASES),
        arms_measured=arms,
        cycles=tuple((int(a), int(b)) for a, b in cycles),
        fps=float(motion.fps),
        source=motion.source,
        meta={
            "n_cycles": len(cycles),
            "loop": motion.loop,
            "cycle_choice": choice,
            "cycles_report": choice.summary(),
        },
    )


def _one_cycle(
    kp: dict[str, np.ndarray],
    contacts: dict[str, np.ndarray],
    fwd_all: np.ndarray,
    a: int,
    b: int,
    fps: float,
) -> dict:
    """Per-cycle figures; ``[a, b)`` runs from a left heel strike to the next."""
    n = b - a
    fwd = _cycle_heading(fwd_all, a, b)
    t = np.arange(n) / fps
    mids = {f: (kp[f"{f}_ankle"][a:b] + kp[f"{f}_toe"][a:b]) / 2 for f in "lr"}
    belt = _belt_speed(mids, contacts, fwd, a, b, fps)
    pelvis = _ground(kp["pelvis"][a:b], belt, t, fwd)
    stride = float((pelvis[-1] - pelvis[0]) @ fwd) * n / max(n - 1, 1)
    leg = float(
        np.median(
            np.linalg.norm(kp["l_knee"][a:b] - kp["l_hip"][a:b], axis=1)
            + np.linalg.norm(kp["l_ankle"][a:b] - kp["l_knee"][a:b], axis=1)
        )
    )
    l_off, r_on, r_off = _foot_events(contacts, a, b)
    ph_l_off, ph_r_on, ph_r_off = (_phase_of(x[0], 0, n) for x in (l_off, r_on, r_off))
    stance = 0.5 * (ph_l_off + (1.0 - ph_r_on + ph_r_off) % 1.0)
    ds = 0.5 * (ph_r_off + (ph_l_off - ph_r_on) % 1.0)
    swings = (("l", l_off[0], n), ("r", r_off[0], r_on[0]))
    out = {
        "period": n / fps,
        "stride": stride,
        "leg": leg,
        "stance": stance,
        "ds": ds,
        **_swing_profiles(mids, swings, belt, t, fwd),
    }
    if all(k in kp for k in _ARMS):
        out.update(_arm_profiles(kp, fwd, a, b))
    return out


def _cycle_heading(fwd_all: np.ndarray, a: int, b: int) -> np.ndarray:
    """``(3,)`` the cycle's mean horizontal heading (unit) from the per-frame ``(T, 3)``."""
    fwd = fwd_all[a:b].mean(axis=0)
    fwd[2] = 0.0
    fwd /= np.linalg.norm(fwd)
    return fwd


def _belt_speed(
    mids: dict[str, np.ndarray],
    contacts: dict[str, np.ndarray],
    fwd: np.ndarray,
    a: int,
    b: int,
    fps: float,
) -> float:
    """A treadmill belt's speed [m/s] along ``fwd``: the median forward velocity of the
    stance feet (``mids`` ``(n, 3)`` mid-foot per side), about 0 overground."""
    stance_v = []
    for f in "lr":
        c = contacts[f][a:b]
        v = np.gradient(mids[f] @ fwd) * fps
        stance_v.append(v[c])
    return float(np.median(np.concatenate(stance_v))) if any(len(s) for s in stance_v) else 0.0


def _ground(x: np.ndarray, belt: float, t: np.ndarray, fwd: np.ndarray) -> np.ndarray:
    """``(n, 3)`` positions in the ground frame: the belt's travel (``t`` ``(n,)`` [s])
    added back."""
    return x - belt * t[:, None] * fwd


def _foot_events(
    contacts: dict[str, np.ndarray], a: int, b: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frames (from ``a``) of the left toe-off and the right heel strikes and toe-offs."""
    cl, cr = contacts["l"][a:b], contacts["r"][a:b]
    l_off = _runs(cl, True)
    r_on, r_off = _runs(cr, False), _runs(cr, True)
    if len(l_off) == 0 or len(r_on) == 0 or len(r_off) == 0:
        raise MocapError("gait cycle without a clear toe-off / heel strike of both feet")
    return l_off, r_on, r_off


def _swing_profiles(
    mids: dict[str, np.ndarray],
    swings: tuple[tuple[str, int, int], ...],
    belt: float,
    t: np.ndarray,
    fwd: np.ndarray,
) -> dict[str, np.ndarray | float]:
    """``swing_x``, ``swing_z`` ``(PHASES,)`` and ``lift`` [m], averaged over the
    ``(foot, lift-off, touch-down)`` swings of the cycle."""
    sx, sz, lift = [], [], []
    for f, off, on in swings:
        if on <= off:
            continue
        g = _ground(mids[f], belt, t, fwd)
        x = g[off:on] @ fwd
        z = g[off:on, 2] - g[:, 2].min()
        base = np.linspace(z[0], z[-1], len(z))
        prog = (x - x[0]) / max(x[-1] - x[0], 1e-9)
        sig = np.linspace(0.0, 1.0, len(x))
        grid = np.linspace(0.0, 1.0, PHASES)
        sx.append(np.interp(grid, sig, np.maximum.accumulate(np.clip(prog, 0.0, 1.0))))
        sz.append(np.interp(grid, sig, np.clip(z - base, 0.0, None)))
        lift.append(float((z - base).max()))
    if not sx:
        raise MocapError("gait cycle without a swing phase")
    return {
        "swing_x": np.mean(sx, axis=0),
        "swing_z": np.mean(sz, axis=0),
        "lift": float(np.mean(lift)),
    }


def _arm_profiles(kp: dict[str, np.ndarray], fwd: np.ndarray, a: int, b: int) -> dict:
    """``shoulder``, ``elbow`` ``(PHASES, 2)`` and ``waist`` ``(PHASES,)`` [rad] over ψ of
    the cycle ``[a, b)``."""
    trunk = kp["neck"][a:b] - kp["pelvis"][a:b]
    trunk /= np.linalg.norm(trunk, axis=1, keepdims=True)
    fwd_t = fwd - (trunk @ fwd)[:, None] * trunk
    fwd_t /= np.linalg.norm(fwd_t, axis=1, keepdims=True)
    sh, el = [], []
    for f in "lr":
        u = kp[f"{f}_elbow"][a:b] - kp[f"{f}_shoulder"][a:b]
        w = kp[f"{f}_wrist"][a:b] - kp[f"{f}_elbow"][a:b]
        sh.append(np.arctan2(np.sum(u * fwd_t, axis=1), -np.sum(u * trunk, axis=1)))
        cos = np.sum(u * w, axis=1) / np.linalg.norm(u, axis=1) / np.linalg.norm(w, axis=1)
        el.append(np.arccos(np.clip(cos, -1.0, 1.0)))
    sl = kp["l_shoulder"][a:b] - kp["r_shoulder"][a:b]
    hl = kp["l_hip"][a:b] - kp["r_hip"][a:b]
    yaw = np.unwrap(np.arctan2(sl[:, 1], sl[:, 0]) - np.arctan2(hl[:, 1], hl[:, 0]))
    return {
        "shoulder": _cyclic_interp(np.stack(sh, axis=1), PHASES),
        "elbow": _cyclic_interp(np.stack(el, axis=1), PHASES),
        "waist": _cyclic_interp(yaw - yaw.mean(), PHASES),
    }
