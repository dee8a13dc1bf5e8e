"""How the stepping gait's shipped gains were learned (``StepGains``'s defaults).

CMA-ES over every gain but ``heading`` from the shipped gains (or ``--start``), on
``hoap2`` walking the clips given (default: the embedded one; the training robots take
them in turn): ``--generations``
generations of ``--population`` candidates, each walked ``--seconds`` on ``--robots``
training robots of the ``hard`` protocol (seeds from 1001, new ones every generation),
then the best of the generations' winners on ``--final`` fresh robots. Checkpointed in
OUT after every generation (``--resume``). The shipped gains came from
``--generations 25 --population 12 --robots 8 --seconds 10 --final 16`` (an interrupted
run of an earlier revision, resumed: the optimiser's draws after the resume differ from
an uninterrupted run's, so a rerun learns gains of the same quality, not the same gains).

``--backward`` learns the clips played backward in time (``learn --backward``): the
shipped backward gains (:data:`~imitwalk.step.gains.BACKWARD`) are what a default
``imitwalk learn --backward`` kept on the embedded walk (G); ``--backward --start G.json
--generations 10 --population 10 --robots 6 --seconds 10 --final 16`` kept G too.

Usage: ``python bench/learn_gains.py OUT [CLIP ...] [--backward] [--resume] [--start
GAINS.json]``; prints JSON.
"""

from __future__ import annotations

import argparse
import json

from imitwalk.mocap import default_clip, load_motion
from imitwalk.robots import load_robot
from imitwalk.sim.protocol import load_protocol
from imitwalk.step.gains import BOUNDS, StepGains
from imitwalk.step.learn import StepLearnConfig, learn_step
from imitwalk.step.pipeline import gait_from_motion


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("clips", nargs="*", help="mocap files (default: the embedded walk)")
    ap.add_argument("--resume", action="store_true")
    ap.add_argument("--backward", action="store_true", help="the clips played backward")
    ap.add_argument("--start", help="a JSON file of gains to start from (default: shipped)")
    ap.add_argument("--generations", type=int, default=25)
    ap.add_argument("--population", type=int, default=12)
    ap.add_argument("--robots", type=int, default=8)
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--final", type=int, default=16)
    ap.add_argument("--sigma", type=float, default=0.2)
    args = ap.parse_args()
    robot = load_robot("hoap2")
    styles = [
        gait_from_motion(load_motion(c), robot, backward=args.backward).style
        for c in args.clips or [default_clip()]
    ]
    names = tuple(n for n in BOUNDS if n != "heading")
    cfg = StepLearnConfig(
        robots=args.robots,
        seconds=args.seconds,
        generations=args.generations,
        population=args.population,
        sigma=args.sigma,
        names=names,
        final_robots=args.final,
    )
    start = StepGains.from_dict(json.loads(open(args.start).read())) if args.start else None
    res = learn_step(
        robot,
        styles,
        cfg,
        args.out,
        load_protocol(cfg.protocol),
        resume=args.resume,
        progress=print,
        start=start,
    )
    out = {
        "gains": res.gains.to_dict(),
        "shipped": StepGains().to_dict(),
        "final": res.final,
        "sim_seconds": res.sim_seconds,
        "wall_seconds": res.wall_seconds,
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
