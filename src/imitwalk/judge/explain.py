"""Why a robot fell: each of its drawn factors set back to nominal, one at a time.

A protocol's robot draws every factor at once, and the factor drawn furthest from
nominal (:attr:`~imitwalk.sim.protocol.RobotDraw.furthest`) need not be the one that
fells it. Eval's seed 14, for example, drew its initial twist furthest from nominal, yet
under the default clip's learned controller it still falls with the twist taken away,
and walks with its servo stiffnesses alone set back to nominal. :func:`explain_falls`
walks every fallen robot again once per factor of the protocol, with that factor at
nominal and every other one exactly as drawn
(:meth:`~imitwalk.sim.protocol.Protocol.only` keeps each factor's own draws), and
names the factors whose removal alone lets the robot walk the whole time. A fall that no
single removal saves comes from several factors together, or, on the nominal robot, from
none.

The cost is one walk per fall and factor, so it is asked for (``imitwalk evaluate
--explain-falls``), never implied.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import TYPE_CHECKING

from imitwalk.parallel import run_parallel
from imitwalk.sim.protocol import Protocol

if TYPE_CHECKING:
    from imitwalk.robots import Robot

__all__ = ["explain_falls"]


def explain_falls(
    walker: Callable,
    jobs: list,
    walks: list,
    protocol: Protocol,
    robot: Robot,
    seconds: float,
    workers: int | None = None,
) -> dict[tuple[str, int], tuple[str, ...]]:
    """The factors whose removal alone saves each fallen robot.

    Args:
        walker: ``walker(job) -> RobotWalk``, run in worker processes
            (:func:`imitwalk.judge.verdict.run_controller`, passed in by the judge);
        jobs: the judge's :class:`~imitwalk.judge.verdict.JudgeJob` list; walks: their
            :class:`~imitwalk.judge.verdict.RobotWalk` results, in the same order.
        protocol: the protocol the robots were drawn from; robot: the robot;
        seconds: simulated time per walk [s] (pushes are drawn up to it, as the judge's).
        workers: parallel processes (``None``: one per core).

    Returns:
        ``(controller, seed)`` → the factors, in the protocol's order, whose removal
        alone lets that fallen robot walk ``seconds`` (empty: none does). Robots that
        did not fall are not listed.
    """
    factors = tuple(protocol.factors)
    without = {f: protocol.only([g for g in factors if g != f]) for f in factors}
    retry, asked = [], []
    for job, walk in zip(jobs, walks, strict=True):
        if not walk.metrics.fell:
            continue
        # the nominal robot (seed 0 of a nominal-first protocol) has no factor to take away
        tried = () if protocol.nominal_first and job.seed == 0 else factors
        asked.append(((job.controller, job.seed), tried))
        for f in tried:
            options = without[f].draw(job.seed, robot, seconds=seconds).options
            retry.append(replace(job, options=options))
    res = run_parallel(walker, retry, workers) if retry else []
    out: dict[tuple[str, int], tuple[str, ...]] = {}
    at = 0
    for key, tried in asked:
        part, at = res[at : at + len(tried)], at + len(tried)
        out[key] = tuple(f for f, r in zip(tried, part, strict=True) if not r.metrics.fell)
    return out
