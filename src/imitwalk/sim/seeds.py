"""Which seeds are which robots: the one registry of seed ranges (pure Python).

A robot is a seed drawn by a protocol (:meth:`imitwalk.sim.protocol.Protocol.draw`) or,
for the joint-space learners' own training robots, by :func:`imitwalk.sim.perturb.perturbed`.
The ranges below never overlap, so no controller is judged on a robot it learned or was
chosen on:

======================  ==========================  =====================================
range                   name                        used by
======================  ==========================  =====================================
0 … 999                 evaluation                  ``imitwalk evaluate`` (0 … 39 in the
                                                    tables; seed 0 is the nominal robot)
1 001 … 99 999          :data:`TRAIN_FIRST` on      learning: the stepping gait's CMA-ES,
                                                    the per-tick learner's models, the
                                                    reference search, the RL environment,
                                                    the reference choice
100 001 … 199 999       :data:`TRIAL_FIRST` on      the per-tick learner's gain trials,
                                                    the stepping gait's stride trials
200 001 … 299 999       :data:`FINAL_FIRST` on      the stepping gait's final choice
300 000 …               :data:`VALIDATION_FIRST` on validation robots, walked once to
                                                    check a choice, never to make one
======================  ==========================  =====================================
"""

from __future__ import annotations

__all__ = [
    "DRAW_STREAM",
    "FINAL_FIRST",
    "TRAIN_FIRST",
    "TRAIN_SEED_BASE",
    "TRIAL_FIRST",
    "TRIAL_SEED_BASE",
    "VALIDATION_FIRST",
]

#: Seeds at or above this are reserved for learning (the first training robot is one above).
TRAIN_SEED_BASE = 1000
#: The first training robot.
TRAIN_FIRST = TRAIN_SEED_BASE + 1
#: Seeds at or above this are the per-tick learner's gain trials'; learning's draws stay
#: below it.
TRIAL_SEED_BASE = 100_000
#: The first gain-trial robot.
TRIAL_FIRST = TRIAL_SEED_BASE + 1
#: The first robot of the stepping gait's final choice, after its generations' robots.
FINAL_FIRST = 200_001
#: The first validation robot.
VALIDATION_FIRST = 300_000
#: Robot ``seed``'s draws come from ``numpy.random.default_rng([seed, DRAW_STREAM, ...])``,
#: in :func:`~imitwalk.sim.perturb.perturbed` and :class:`~imitwalk.sim.protocol.Protocol`
#: alike (the date of the paper's conference, January 2007).
DRAW_STREAM = 20070106
