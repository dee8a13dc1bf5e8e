"""The house boundary: the NumPy stages and the run folder do not pull in MuJoCo."""

from __future__ import annotations

import subprocess
import sys

#: Modules that must import without MuJoCo (directly or through another module); the stage
#: packages' ``__init__`` files among them.
NUMPY_ONLY = (
    "balance",
    "balance.channels",
    "balance.clock",
    "balance.estimator",
    "balance.feedback",
    "balance.lqr",
    "balance.tickconfig",
    "balance.ticklog",
    "balance.tickmodel",
    "config",
    "evidence",
    "evidence.curves",
    "evidence.navplot",
    "evidence.plots",
    "fileio",
    "judge",
    "judge.records",
    "judge.tables",
    "paper",
    "paper.controller",
    "paper.embedding",
    "paper.gait",
    "paper.learnconfig",
    "paper.models",
    "paper.policy",
    "paper.predictor",
    "paper.rbf",
    "paper.subspace",
    "readback",
    "retarget",
    "retarget.command",
    "retarget.params",
    "retarget.plan",
    "retarget.reference",
    "retarget.reffile",
    "retarget.template",
    "rl",
    "rl.actor",
    "rl.network",
    "rl.observation",
    "runs",
    "sim",
    "sim.fix",
    "sim.metrics",
    "sim.perturb",
    "sim.protocol",
    "sim.protocolcheck",
    "sim.seeds",
    "sim.servo",
    "sim.types",
    "step.odometry",
)


def test_numpy_stages_and_the_run_folder_import_without_mujoco():
    code = (
        "import importlib, sys\n"
        f"for m in {NUMPY_ONLY!r}:\n"
        "    importlib.import_module('imitwalk.' + m)\n"
        "    assert 'mujoco' not in sys.modules, m\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr.strip().splitlines()[-1]


def test_the_retarget_package_names_every_lazy_name_once():
    import importlib

    pkg = importlib.import_module("imitwalk.retarget")  # ``iw.retarget`` is the function
    assert sorted(pkg.__all__) == sorted(pkg._HOME)
    for name in pkg.__all__:
        assert getattr(pkg, name) is not None
    assert not hasattr(pkg, "no_such_name")  # an AttributeError, as for any module


def test_no_module_imports_itself_through_others():
    """No import cycle between imitwalk's modules, function-level imports included."""
    import grimp

    graph = grimp.build_graph("imitwalk")
    cycles = []
    for module in sorted(graph.modules):
        for imported in graph.find_modules_directly_imported_by(module):
            if graph.chain_exists(importer=imported, imported=module):
                cycles.append((module, imported))
    assert cycles == []
