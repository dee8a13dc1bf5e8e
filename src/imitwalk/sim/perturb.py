"""Perturbed robots for evaluation and for training (pure NumPy).

Seed 0 is the nominal robot. Every other seed draws a perturbed one: each body's mass
±5 %, the floor friction 0.7-1.0, each servo's stiffness ±10 %, and (for the
evaluation of a learned gait) a small initial disturbance of the base velocity. Each
of these *factors* (:data:`FACTORS`) can be left out; the others keep their draws, so
a robot with one factor left out differs from the full one in that factor only.
Which seeds are which robots is :mod:`imitwalk.sim.seeds`'s registry: learning and the
reference search only use seeds above :data:`~imitwalk.sim.seeds.TRAIN_SEED_BASE`, so they
never see an evaluation robot; the learner's gain trials use seeds above
:data:`~imitwalk.sim.seeds.TRIAL_SEED_BASE`, robots it never learned on.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from imitwalk.errors import ConfigError, unknown_name
from imitwalk.sim.seeds import DRAW_STREAM, TRAIN_SEED_BASE, TRIAL_SEED_BASE
from imitwalk.sim.types import SimOptions

__all__ = [
    "FACTORS",
    "FRICTION_RANGE",
    "perturbed",
    "train_seeds",
    "trial_seeds",
]

#: What a perturbed robot differs in: body masses, floor friction, servo stiffness, and
#: the initial push of the base (only drawn with ``disturbance=True``).
FACTORS = ("mass", "friction", "servo", "disturbance")

#: The range a perturbed robot's floor friction is drawn from (evaluation's, and by default
#: the learner's ``train_friction``).
FRICTION_RANGE = (0.7, 1.0)


def perturbed(
    seed: int,
    base: SimOptions | None = None,
    disturbance: bool = False,
    factors: tuple[str, ...] = FACTORS,
    friction_range: tuple[float, float] = FRICTION_RANGE,
) -> SimOptions:
    """Simulation options of robot ``seed`` (0: nominal, as ``base``).

    Args:
        seed: which robot; also seeds its sensor noise.
        base: options to perturb (rates, noise, slope ... are kept).
        disturbance: also give the base a small random initial velocity
            (σ 0.02 m/s linear, 0.1 rad/s angular).
        factors: which of :data:`FACTORS` to perturb (default: all); the others stay
            nominal. The draws do not depend on it.
        friction_range: the floor friction is drawn uniformly from this range (the
            learner may widen it for its own robots; evaluation keeps the default).
    """
    for f in factors:
        if f not in FACTORS:
            raise unknown_name("perturbation factor", f, FACTORS, ConfigError)
    base = base or SimOptions()
    if seed == 0:
        return replace(base, seed=0)
    rng = np.random.default_rng([seed, DRAW_STREAM])
    twist = (0.0,) * 6
    if disturbance:
        twist = tuple(np.concatenate([rng.normal(0, 0.02, 3), rng.normal(0, 0.1, 3)]).tolist())
    friction = float(rng.uniform(*friction_range))
    return replace(
        base,
        seed=seed,
        mass_jitter=0.05 if "mass" in factors else 0.0,
        kp_jitter=0.10 if "servo" in factors else 0.0,
        friction=friction if "friction" in factors else base.friction,
        init_twist=twist if "disturbance" in factors else base.init_twist,
    )


def train_seeds(n: int, draw: int = 0) -> tuple[int, ...]:
    """``n`` robots for learning: the nominal one, then ``n - 1`` training perturbations.

    ``draw`` picks a set: draw 0 is seeds ``TRAIN_SEED_BASE + 1 …``, draw k the k-th set
    of ``n - 1`` fresh ones after it (a learner that meets new robots every iteration).
    """
    first = TRAIN_SEED_BASE + 1 + draw * max(n - 1, 0)
    return (0, *range(first, first + n - 1))


def trial_seeds(
    n: int, stratify: bool = False, friction_range: tuple[float, float] = FRICTION_RANGE
) -> tuple[int, ...]:
    """``n`` robots for the gain trials: the nominal one, then ``n - 1`` perturbations that
    neither learning nor evaluation uses.

    Args:
        n: how many robots.
        stratify: pick the ``n - 1`` perturbed robots so that their floor frictions cover
            ``friction_range`` evenly: one robot in each of ``n - 1`` equal bands of it,
            the first trial seed (in order) whose draw falls in that band. Without it they
            are the first ``n - 1`` trial seeds, whose frictions are whatever they drew (the
            first 23 draw 14 below 0.8 and 4 above 0.94 of 0.7-1.0). A handful of robots
            decides the trials, and the grippiest floors are where learned corrections
            have hurt (README, "Why robots 5 and 9"); stratifying removes that luck of the
            draw without choosing the robots by how they walk.
        friction_range: the range the trial robots' friction is drawn from (the learner's
            ``train_friction``).
    """
    lo, hi = friction_range
    if not stratify or n <= 2 or hi <= lo:
        return (0, *range(TRIAL_SEED_BASE + 1, TRIAL_SEED_BASE + n))
    bands: list[int | None] = [None] * (n - 1)
    seed = TRIAL_SEED_BASE
    while None in bands:
        seed += 1
        f = perturbed(seed, disturbance=True, friction_range=(lo, hi)).friction
        assert f is not None  # a perturbed seed (not 0) always draws a friction
        band = min(int((f - lo) / (hi - lo) * (n - 1)), n - 2)
        if bands[band] is None:
            bands[band] = seed
    return (0, *sorted(b for b in bands if b is not None))  # every band is filled
