"""Simulation: the MuJoCo plant (:mod:`imitwalk.sim.mujoco`), the PyBullet plant
(:mod:`imitwalk.sim.bullet`), their shared types (:mod:`imitwalk.sim.types`), the servo
model, rendering, standing and playback checks, perturbed robots, and the walking metrics
of a rollout.

Import the modules themselves: this package does not import MuJoCo.
"""
