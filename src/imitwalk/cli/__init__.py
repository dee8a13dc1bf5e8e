"""The ``imitwalk`` command line (:mod:`imitwalk.cli.main`)."""

from imitwalk.cli.main import main

__all__ = ["main"]
