"""imitwalk's tests: a package, so that test modules and :mod:`tests.helpers` import as
``tests.<module>`` with the repository root on ``sys.path`` (pytest's default import mode
puts it there; ``python -m tests.helpers.<module>`` from the root does too)."""
