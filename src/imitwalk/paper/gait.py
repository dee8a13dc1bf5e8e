"""The reference gait in the paper's representation (§3): PCA subspace + cylindrical loop.

:class:`GaitModel` fits one :class:`~imitwalk.paper.subspace.PostureSubspace` on the reference
loops of every scale of a schedule (so one subspace serves the whole schedule), and one
:class:`~imitwalk.paper.embedding.GaitEmbedding` per scale. An action χ = (φ, r, h) maps to
joint targets through g and C⁺; the nominal action sequence of a scale is its reference
loop in cylindrical coordinates. Pure NumPy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imitwalk.errors import ConfigError, unknown_name
from imitwalk.paper.embedding import GaitEmbedding
from imitwalk.paper.subspace import PostureSubspace
from imitwalk.retarget.reference import Reference

__all__ = ["GaitConfig", "GaitModel"]

PHASE_SOURCES = ("angle", "time")


@dataclass(frozen=True)
class GaitConfig:
    """Representation settings.

    Attributes:
        n_components: k, the subspace size (the paper: 3; its 2009 follow-up found 3 too
            few for some motions; beyond 3 the components follow the phase).
        phase_source: ``"angle"`` (the paper's φ, the data's angle about z_θ) or ``"time"``
            (the reference's time phase, robust where the angle runs backwards).
        n_centers: kernels of the periodic fit g(φ) (eq. 2).
        residual: add back, as a fixed function of the phase, what the representation
            does not reproduce of the reference (the posture outside the subspace, and the
            error of the cylinder's round trip), so that the nominal action reproduces the
            reference exactly; actions still move the posture only within the subspace.
    """

    n_components: int = 3
    phase_source: str = "angle"
    n_centers: int = 24
    residual: bool = False


class GaitModel:
    """Subspace and per-scale embeddings of a reference.

    Args:
        ref: the reference; scales: the schedule's scales; config: representation.
    """

    def __init__(self, ref: Reference, scales: list[float] | tuple[float, ...], config: GaitConfig):
        if config.phase_source not in PHASE_SOURCES:
            raise unknown_name("phase source", config.phase_source, PHASE_SOURCES, ConfigError)
        if not 3 <= config.n_components <= len(ref.joint_names):
            raise ConfigError(
                f"n_components must be 3..{len(ref.joint_names)}, got {config.n_components}"
            )
        self.ref, self.config = ref, config
        self.scales = tuple(float(s) for s in scales)
        loops = [ref.at_scale(s)[1] for s in self.scales]
        self.subspace = PostureSubspace(config.n_components).fit(loops)
        self.embeddings: dict[float, GaitEmbedding] = {}
        self.nominal: dict[float, np.ndarray] = {}
        self.residuals: dict[float, np.ndarray] = {}
        self._phase_tables: dict[float, tuple[float, np.ndarray]] = {}
        self._by_tick: dict[float, np.ndarray] = {}
        for s, loop in zip(self.scales, loops, strict=True):
            X = self.subspace.transform(loop)  # (N, k)
            emb = GaitEmbedding(n_centers=config.n_centers, phase_source=config.phase_source)
            emb.fit(X, phase=ref.phase if config.phase_source == "time" else None)
            self.embeddings[s] = emb
            cyl = emb.to_cylinder(X)  # (N, 3)
            cyl[:, 0] = np.unwrap(cyl[:, 0])
            self.nominal[s] = cyl
            # what the representation does not reproduce: the subspace's truncation and
            # the cylinder's round trip (with the time phase, its angle is a fit of φ)
            # (row by row, as :meth:`joints` maps one action; batched, the round trip
            # differs in the last bit, and a marginal robot's fate can hang on that)
            back = np.array([emb.from_cylinder(c) for c in cyl])
            self.residuals[s] = loop - self.subspace.inverse_transform(back)  # (N, n)
            self._index_phase(s)

    def _index_phase(self, s: float) -> None:
        """The φ → tick table of scale ``s`` for looking up its residual by phase.

        Where φ runs backwards over a few ticks (it can, with the time phase), the lookup
        finds another tick: those ticks, and their neighbours (a later cycle's φ differs
        in the last bit), are marked to take their own residual when the tick is known.
        Only those: elsewhere the lookup by φ stays, since in later cycles it reproduces
        the tick's residual only to the last bit, and a learned run depends on those bits.
        """
        phi0 = self.nominal[s][:, 0]
        sign = 1.0 if phi0[-1] >= phi0[0] else -1.0
        table = np.maximum.accumulate(sign * (phi0 - phi0[0]))  # ascending from 0
        self._phase_tables[s] = (sign, table)
        wrong = np.zeros(len(phi0), dtype=bool)
        for c in range(4):
            found = np.array([self._residual_at(s, f + 2 * np.pi * c * sign) for f in phi0])
            wrong |= np.abs(found - self.residuals[s]).max(axis=1) > 1e-9
        if wrong.any():
            wrong = wrong | np.roll(wrong, 1) | np.roll(wrong, -1)
        self._by_tick[s] = wrong

    @property
    def n_ticks(self) -> int:
        """Ticks per cycle ``N``."""
        return self.ref.loops.shape[1]

    def embedding(self, scale: float) -> GaitEmbedding:
        """The embedding of a schedule scale."""
        return self.embeddings[self.key(scale)]

    def key(self, scale: float) -> float:
        """The schedule scale ``scale`` is (to 1e-9); unknown scales list the valid ones."""
        for s in self.scales:
            if abs(s - scale) < 1e-9:
                return s
        raise unknown_name("scale", f"{scale:g}", [f"{s:g}" for s in self.scales], ConfigError)

    def nominal_action(self, scale: float, tick: int) -> np.ndarray:
        """χ = (φ, r, h) of the reference at loop tick ``tick`` (φ unwrapped over cycles)."""
        nom = self.nominal[self.key(scale)]
        n = len(nom)
        cycles, i = divmod(tick, n)
        out = nom[i].copy()
        out[0] += 2 * np.pi * cycles * np.sign(nom[-1, 0] - nom[0, 0] or 1.0)
        return out

    def joints(self, scale: float, action: np.ndarray, tick: int | None = None) -> np.ndarray:
        """Joint targets ``(n,)`` [rad] of an action (φ, r, h): g and C⁺ (the way back).

        ``tick``: the loop tick the action is for, if known (see :meth:`_residual_at`).
        """
        action = np.asarray(action, dtype=float)
        q = self.subspace.inverse_transform(self.embedding(scale).from_cylinder(action))
        if self.config.residual:
            q = q + self._residual_at(scale, float(action[0]), tick)
        return q

    def _residual_at(self, scale: float, phi: float, tick: int | None = None) -> np.ndarray:
        """The out-of-subspace posture ``(n,)`` at phase φ, interpolated between ticks.

        Where the reference's φ runs backwards (it can, with the time phase), φ alone does
        not say which tick it is; there, given the ``tick`` whose nominal φ this is, the
        residual is that tick's own.
        """
        key = self.key(scale)
        res, (sign, table) = self.residuals[key], self._phase_tables[key]
        by_tick = self._by_tick.get(key)
        if tick is not None and by_tick is not None and by_tick[tick % len(res)]:
            if abs(phi - self.nominal_action(scale, tick)[0]) < 1e-12:
                return res[tick % len(res)]
        u = (sign * (phi - self.nominal[key][0, 0])) % (2 * np.pi)
        t = float(np.interp(u, table, np.arange(len(table)), right=np.nan))
        if not np.isfinite(t):  # between the last tick and the next cycle's first
            span = 2 * np.pi - table[-1]
            t = len(table) - 1 + ((u - table[-1]) / span if span > 0 else 0.0)
        i = int(np.floor(t))
        w = t - i
        return (1.0 - w) * res[i % len(res)] + w * res[(i + 1) % len(res)]

    def phase_step(self, scale: float) -> float:
        """Mean φ advance per tick of the nominal loop [rad]."""
        nom = self.nominal[self.key(scale)]
        return float((nom[-1, 0] - nom[0, 0]) / (len(nom) - 1))

    def report(self) -> dict:
        """Explained variance, per-joint reconstruction error, φ monotonicity per scale."""
        out = {
            "n_components": self.config.n_components,
            "explained_variance_ratio": self.subspace.explained_variance_ratio_.tolist(),
            "reconstruction_rms_rad": {},
            "phase_backwards_fraction": {},
        }
        for s in self.scales:
            loop = self.ref.at_scale(s)[1]
            err = self.subspace.reconstruction_error(loop)
            out["reconstruction_rms_rad"][f"{s:g}"] = {
                "max": float(err.max()),
                "worst_joint": self.ref.joint_names[int(np.argmax(err))],
            }
            d = np.diff(self.nominal[s][:, 0])
            out["phase_backwards_fraction"][f"{s:g}"] = float(np.mean(d * np.sign(d.sum()) < 0))
        return out
