"""The per-tick balance controller: the reference plus measured feedback (pure NumPy).

Every control tick ``k`` (100 Hz) the controller commands

    q_k = q_ref(k) + E a_k,   a_k = clip(K(ψ_k) z_k, −box, box),

where ``q_ref`` is the reference (its start-up, then its loop), ``E`` maps the named
balance channels to joints (:func:`imitwalk.balance.channels.channel_matrix`), ψ_k is the
loop tick of the gait phase and ``z_k`` what the robot measures: the features of
:data:`imitwalk.balance.channels.FEATURES` less their nominal value at that phase (``x_k``),
and, for a law with ``memory``, also the previous tick's ``x`` and ``a`` — the state of
the paper's second-order model (eqs. 3–4). A :class:`FeedbackLaw` holds ``K``: one gain
matrix for every phase (from :mod:`imitwalk.balance.lqr`), or one for all (picked by trials,
:mod:`imitwalk.balance.ticklearn`). Several laws add up (the learned one on top of the
trial-picked one). During learning, piecewise-constant exploration noise is added to
the last law's ``a``, and every tick's phase, features and that ``a`` are recorded.

Two optional parts are the reference's, not feedback: a servo feedforward added to
``q_ref`` (``offsets``, :mod:`imitwalk.retarget.feedforward`), and the phase wait (``wait``,
eq. 9's phase advance made by the sole forces): before a planned lift-off the reference's
clock waits while the sole about to lift still carries more than ``wait`` of the
measured load, at most :data:`~imitwalk.balance.clock.MAX_WAIT_S` per lift-off
(:class:`~imitwalk.balance.clock.LoadClock`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from imitwalk.balance.channels import FEATURES, channel_matrix, check_names
from imitwalk.balance.clock import LoadClock
from imitwalk.balance.estimator import StateEstimator
from imitwalk.errors import ConfigError
from imitwalk.retarget.reference import Reference

if TYPE_CHECKING:
    from imitwalk.sim.types import Observation

__all__ = ["Episode", "FeedbackLaw", "TickPolicy"]


@dataclass(frozen=True)
class FeedbackLaw:
    """A per-tick feedback law.

    Attributes:
        channels: the ``m`` channels it acts on; features: the ``d`` features it reads.
        gains: ``(P, m, D)`` [rad per unit of each feature], P = 1 (every phase alike) or
            the loop's ticks N; D = d, or 2d + m with ``memory``.
        nominal: ``(N, d)`` each feature's nominal value per loop tick (subtracted), or
            ``(1, d)``.
        box: ``(m,)`` each channel's limit [rad].
        memory: the gains also read the previous tick's x and a.
    """

    channels: tuple[str, ...]
    features: tuple[str, ...]
    gains: np.ndarray
    nominal: np.ndarray
    box: np.ndarray
    memory: bool = False

    def __post_init__(self) -> None:
        check_names("channel", self.channels, channel_names())
        check_names("feature", self.features, FEATURES)
        m, d = len(self.channels), len(self.features)
        D = 2 * d + m if self.memory else d
        g, nom, box = np.asarray(self.gains), np.asarray(self.nominal), np.asarray(self.box)
        if g.ndim != 3 or g.shape[1:] != (m, D):
            raise ConfigError(f"feedback gains have shape {g.shape}; expected (P, {m}, {D})")
        if nom.ndim != 2 or nom.shape[1] != d or box.shape != (m,):
            raise ConfigError(f"feedback nominal {nom.shape} / box {box.shape} do not fit")
        if not (np.isfinite(g).all() and np.isfinite(nom).all() and (box >= 0).all()):
            raise ConfigError("feedback gains, nominal and box must be finite (box >= 0)")

    @classmethod
    def zero(
        cls,
        channels: Sequence[str],
        features: Sequence[str],
        box: float,
        n_ticks: int = 1,
        memory: bool = False,
    ) -> FeedbackLaw:
        """A law that does nothing: zero gains, zero nominal (``box``: one limit for all)."""
        m, d = len(channels), len(features)
        D = 2 * d + m if memory else d
        return cls(
            tuple(channels),
            tuple(features),
            np.zeros((1, m, D)),
            np.zeros((n_ticks, d)),
            np.full(m, float(box)),
            memory,
        )

    def with_gain(self, channel: str, feature: str, value: float) -> FeedbackLaw:
        """This law with one gain (every phase alike) set to ``value``."""
        g = np.array(self.gains, dtype=float)
        g[:, self.channels.index(channel), self.features.index(feature)] = value
        return replace(self, gains=g)

    def gain(self, channel: str, feature: str) -> float:
        """The mean over phases of one gain."""
        c, f = self.channels.index(channel), self.features.index(feature)
        return float(np.mean(self.gains[:, c, f]))

    def to_arrays(self, prefix: str) -> dict[str, np.ndarray]:
        """The law as arrays for a run's ``.npz`` (keys start with ``prefix``)."""
        return {
            f"{prefix}gains": np.asarray(self.gains),
            f"{prefix}nominal": np.asarray(self.nominal),
            f"{prefix}box": np.asarray(self.box),
            f"{prefix}names": np.array(
                [",".join(self.channels), ",".join(self.features), str(int(self.memory))]
            ),
        }

    @classmethod
    def from_arrays(cls, arrays: Mapping[str, np.ndarray], prefix: str) -> FeedbackLaw:
        """Inverse of :meth:`to_arrays`."""
        ch, feat, mem = (str(x) for x in arrays[f"{prefix}names"])
        return cls(
            tuple(ch.split(",")),
            tuple(feat.split(",")),
            np.asarray(arrays[f"{prefix}gains"], dtype=float),
            np.asarray(arrays[f"{prefix}nominal"], dtype=float),
            np.asarray(arrays[f"{prefix}box"], dtype=float),
            bool(int(mem)),
        )


def channel_names() -> tuple[str, ...]:
    from imitwalk.balance.channels import CHANNELS

    return tuple(CHANNELS)


@dataclass(frozen=True)
class Episode:
    """What one episode recorded for learning: ``T`` ticks.

    Attributes:
        phase: ``(T,)`` loop tick ψ of each tick; features: ``(T, 6)`` every feature of
        :data:`~imitwalk.balance.channels.FEATURES`, as measured (no nominal subtracted);
        actions: ``(T, m)`` the values the explored law commanded (exploration included).
    """

    phase: np.ndarray
    features: np.ndarray
    actions: np.ndarray

    def states(self, law: FeedbackLaw) -> np.ndarray:
        """``(T, d)`` the law's features less its nominal profile."""
        pick = [FEATURES.index(f) for f in law.features]
        return self.features[:, pick] - law.nominal[self.phase % len(law.nominal)]


class TickPolicy:
    """``policy(tick, observation) -> (n,) joint targets``: feedback laws on a reference.

    The laws' outputs add up: ``q = q_ref + Σ_l E_l a_l`` (each law clipped to its box).

    Args:
        ref: the reference; scale: its stride scale; laws: the feedback laws;
        joint_names: the robot's roles (for the channel maps); seconds: how long the
            walk runs [s]; explore: exploration amplitude [rad] on every channel of the
            last law (0: none); hold: ticks each exploration draw is held; seed: its
            random stream; offsets: ``(T', n)`` [rad] added to every target, ``T'`` at
            least the ticks of twice ``seconds`` if it waits, else of ``seconds`` (the
            servo feedforward, :func:`imitwalk.retarget.feedforward.walk_offsets`;
            ``None``: none);
            wait: the load share [0, 1) above which the reference waits before a lift-off
            (0: it never waits). ``q_ref`` ``(T, n)`` stays the reference for ``seconds``
            (what a walk is measured against).
    """

    def __init__(
        self,
        ref: Reference,
        scale: float,
        laws: tuple[FeedbackLaw, ...],
        joint_names: tuple[str, ...],
        seconds: float,
        explore: float = 0.0,
        hold: int = 8,
        seed: int | tuple[int, ...] = 0,
        offsets: np.ndarray | None = None,
        wait: float = 0.0,
    ) -> None:
        self.laws = tuple(laws)
        self.q_ref = ref.trajectory(scale, seconds)  # (T, n)
        horizon = 2.0 * seconds if wait else seconds  # how far a waiting clock may reach
        q = ref.trajectory(scale, horizon)  # (T', n)
        self.q_cmd = q if offsets is None else q + offsets[: len(q)]
        self.heading_ref = ref.track(scale, horizon)[:, 2]  # (T',) commanded heading [rad]
        down = ref.planned_load(scale, len(q))[0] if wait else None  # (T', 2)
        self.clock = None if down is None else LoadClock(down, wait, ref.dt)
        names, stance = tuple(joint_names), ref.stance
        self.E = [channel_matrix(names, law.channels, stance) for law in self.laws]  # (P, n, m)
        self.start, self.n_loop = ref.starts.shape[1], ref.loops.shape[1]
        self.pick = [[FEATURES.index(f) for f in law.features] for law in self.laws]
        self.estimator = StateEstimator(ref.dt)
        self.explore, self.hold = float(explore), max(1, int(hold))
        self.rng = np.random.default_rng(seed)
        m = len(self.laws[-1].channels) if self.laws else 0
        self._noise = np.zeros(m)
        self._x_prev: list[np.ndarray | None] = [None] * len(self.laws)
        self._a_prev = [np.zeros(len(law.channels)) for law in self.laws]
        self._phase: list[int] = []
        self._f: list[np.ndarray] = []
        self._a: list[np.ndarray] = []

    @property
    def q0(self) -> np.ndarray:
        """``(n,)`` the posture the walk starts from (:func:`imitwalk.sim.mujoco.run` uses it)."""
        return self.q_cmd[0]

    def phase_of(self, k: int) -> int:
        """The loop tick ψ of control tick ``k`` (the start-up shares the loop's timing)."""
        return (k - self.start) % self.n_loop

    def _tick(self, k: int, obs: Observation) -> int:
        """The reference's tick at control tick ``k`` (``k`` itself unless it waits)."""
        return k if self.clock is None else self.clock.tick(k, obs.foot_force)

    def __call__(self, k: int, obs: Observation) -> np.ndarray:
        k = min(self._tick(k, obs), len(self.q_cmd) - 1)
        est = self.estimator.update(obs.gyro, obs.accel, obs.foot_force)
        full = np.array([*est.gyro, est.roll, est.pitch, est.heading - self.heading_ref[k]])
        i = self.phase_of(k)
        q = self.q_cmd[k].copy()
        a = np.zeros(0)
        for j, law in enumerate(self.laws):
            x = full[self.pick[j]] - law.nominal[i % len(law.nominal)]
            if law.memory:
                prev = x if self._x_prev[j] is None else self._x_prev[j]
                z = np.concatenate([x, prev, self._a_prev[j]])
            else:
                z = x
            a = law.gains[i % len(law.gains)] @ z
            if self.explore > 0.0 and j == len(self.laws) - 1:
                if k % self.hold == 0:
                    self._noise = self.explore * self.rng.uniform(-1.0, 1.0, len(a))
                a = a + self._noise
            a = np.clip(a, -law.box, law.box)
            self._x_prev[j], self._a_prev[j] = x, a
            q += self.E[j][i % len(self.E[j])] @ a
        self._phase.append(i)
        self._f.append(full)
        self._a.append(a)
        return q

    def episode(self) -> Episode:
        """The ticks recorded so far (the last law's actions)."""
        m = len(self.laws[-1].channels) if self.laws else 0
        return Episode(
            np.asarray(self._phase, dtype=int),
            np.asarray(self._f, dtype=float).reshape(-1, len(FEATURES)),
            np.asarray(self._a, dtype=float).reshape(-1, m),
        )
