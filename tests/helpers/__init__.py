"""Helpers of the tests that are not tests themselves: the fuzz case generators
(:mod:`~tests.helpers.fuzz_files`, :mod:`~tests.helpers.fuzz_mocap`,
:mod:`~tests.helpers.fuzz_robot`, each also a command line:
``python -m tests.helpers.fuzz_<x> --help`` from the repository root) and a BVH writer
(:mod:`~tests.helpers.bvh_writer`)."""
