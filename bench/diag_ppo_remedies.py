"""One-off: residual PPO on the stepping gait with the field's remedies for fine-tuning
a good controller: the critic warmed up with the policy frozen, a smaller learning
rate, a KL target (this commit's ``PPOConfig.critic_warmup`` and ``target_kl``).

Usage (the default clip's stepping run in STEP, ``imitwalk learn --out STEP``)::

    python bench/diag_ppo_remedies.py STEP RES 6000 1000 1e-4 0.01
    imitwalk evaluate RES --protocol hard --seeds 40 --json
    # a snapshot: copy RES, put snapshots/policy_S.npz in place of policy.npz

Arguments: the base run, the output run, the budget [simulated s], the critic's warm-up
[simulated s], the learning rate, the KL target (``none``: no target). Training robots
of protocol ``hard``, 20 s episodes, 2 processes, PPO's other settings the defaults.
"""

import sys

from imitwalk.envs.ppo import PPOConfig, train
from imitwalk.envs.setup import WalkConfig

if __name__ == "__main__":
    base, out, budget, warm, lr, kl = sys.argv[1:7]
    walk = WalkConfig(protocol="hard", action="residual", run=base, seconds=20.0)
    cfg = PPOConfig(
        budget=float(budget),
        critic_warmup=float(warm),
        learning_rate=float(lr),
        target_kl=None if kl == "none" else float(kl),
    )
    train(walk, cfg, out, progress=print)
