"""Orchestration above the judge: learning runs that judge their own candidates.

:mod:`imitwalk.learning.refchoice` is ``imitwalk learn CLIP --variant extended``: it
retargets, learns the per-tick law, searches again under it, learns again, and keeps the
pass that walks the training robots better (judged by :mod:`imitwalk.judge.verdict`).
"""
