"""Judging a learned run: evaluation protocols (JSON in :mod:`imitwalk.judge.protocols`),
the verdict on a protocol's robots, push recovery, loading runs back, and result tables."""
