"""Judging a learned run: the verdict on a protocol's robots (the robots themselves are
drawn by :mod:`imitwalk.sim.protocol`), push recovery, loading runs back, and result
tables."""
