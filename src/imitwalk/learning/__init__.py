"""Orchestration above the judge: the joint-space learners as one call each.

:func:`imitwalk.learning.jointspace.learn_joint_space` is ``imitwalk learn CLIP --variant
extended|faithful``: the clip retargeted, then learned. For the per-tick learner it makes
the reference choice of :mod:`imitwalk.learning.refchoice`: it learns the open-loop
search's reference, searches again under the learned law, learns again, and keeps the
pass that walks the training robots better (judged by :mod:`imitwalk.judge.verdict`).
(The stepping gait, the default, is :func:`imitwalk.step.pipeline.learn`.)
"""
