"""A prototype: the reference's clock hurried to the landing when the swing foot lands early.

A kick towards the swinging foot in mid-swing is the hardest one on hoap2 (the push-recovery
table: 0.13 m/s, against 0.2–0.5 elsewhere). The body tips onto the swing foot before the
plan lands it, and the plan goes on swinging a foot that is already on the floor. Here the
clock (the phase wait's, :class:`imitwalk.balance.clock.LoadClock`) also runs ``rate``
reference ticks per control tick while a foot the plan has in the air carries more than
``share`` of the soles' measured load, until the plan's own touchdown: the sole forces
advance the phase (eq. 9), as they hold it back before a lift-off.

Walks the run's learned controller with each (share, rate) on validation robots (seeds from
``--first``) of hard's kicks alone and of eval.

Usage: ``python bench/early_landing.py RUN [--variants 0.3:3,0.5:3] [--robots 20]``; prints
JSON lines.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from imitwalk.balance.clock import LoadClock
from imitwalk.balance.feedback import TickPolicy
from imitwalk.judge.protocol import load_protocol
from imitwalk.judge.replay import load_run
from imitwalk.parallel import run_parallel
from imitwalk.retarget.feedforward import walk_offsets
from imitwalk.robots import load_robot
from imitwalk.sim.mujoco import make_plant, run


class EarlyClock(LoadClock):
    """:class:`LoadClock` that also runs ``rate`` ticks per tick through an early landing."""

    def __init__(self, down, wait, dt, share, rate):
        super().__init__(down, wait, dt)
        self.share, self.rate, self.hurried = share, int(rate), 0

    def tick(self, k, foot_force):
        before = self.clock
        out = super().tick(k, foot_force)
        if not k or self.share <= 0 or out == before:  # waiting, or the first tick
            return out
        load = np.asarray(foot_force).sum(axis=1)
        share = load / max(float(load.sum()), 1e-9)
        j = min(self.clock, len(self.down) - 2)
        up = ~self.down[j]
        if np.any(up & (share > self.share)):
            for _ in range(self.rate - 1):  # on to the plan's touchdown, not past it
                j = min(self.clock, len(self.down) - 2)
                if not np.any(up & ~self.down[j + 1]):
                    break
                self.clock += 1
                self.hurried += 1
        return self.clock


def walk(job) -> dict:
    r, robot, options, share, rate = job
    ref, seconds = r.ref, 30.0
    st = r.settings_of("learned")
    off = walk_offsets(ref, robot, r.scale, 2 * seconds, st["feedforward"])
    pol = TickPolicy(ref, r.scale, tuple(r.laws["learned"]), robot.joint_names, seconds,
                     offsets=off, wait=st["wait"])  # fmt: skip
    q = ref.trajectory(r.scale, 2 * seconds)
    pol.q_cmd = q + off[: len(q)]
    pol.heading_ref = ref.track(r.scale, 2 * seconds)[:, 2]
    down = ref.planned_load(r.scale, len(q))[0]
    wait = st["wait"] or 1.0  # a share never above 1: no wait, as without a clock
    pol.clock = EarlyClock(down, wait, ref.dt, share, rate)
    ro = run(make_plant(robot, ref.sim_options(options)), pol, len(pol.q_ref))
    return {"fell": bool(ro.fell), "hurried": pol.clock.hurried}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir")
    ap.add_argument("--variants", default="0:1,0.3:3,0.5:3,0.3:2")
    ap.add_argument("--robots", type=int, default=20)
    ap.add_argument("--first", type=int, default=300_000)
    ap.add_argument("--protocols", default="kicks,eval")
    a = ap.parse_args()
    r, robot = load_run(a.run_dir), load_robot("hoap2")
    hard = load_protocol("hard")
    protos = {"kicks": hard.only(("pushes",)), "eval": load_protocol("eval"), "hard": hard,
              "no kicks": hard.only(tuple(f for f in hard.factors if f != "pushes"))}  # fmt: skip
    for v in a.variants.split(","):
        share, rate = (float(x) for x in v.split(":"))
        row = {"share": share, "rate": rate}
        for p in a.protocols.split(","):
            draws = [protos[p].draw(a.first + s, robot, r.ref.sim_options(), 30.0)
                     for s in range(a.robots)]  # fmt: skip
            res = run_parallel(walk, [(r, robot, d.options, share, rate) for d in draws])
            row[p] = sum(x["fell"] for x in res)
            row[p + " hurried ticks"] = int(np.mean([x["hurried"] for x in res]))
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
