"""Sweeps: learn and judge clips × robots × settings × seeds, on Ray
(``imitwalk sweep CONFIG``).

:mod:`~imitwalk.sweep.config` reads and checks the sweep's file and lists its cells;
:mod:`~imitwalk.sweep.cell` learns and judges one cell; :mod:`~imitwalk.sweep.runner`
runs the cells not yet done as Ray tasks and resumes an interrupted sweep;
:mod:`~imitwalk.sweep.table` writes the results table (CSV, Parquet) and its summary page.
"""
