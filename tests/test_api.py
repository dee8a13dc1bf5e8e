"""The flat API: ``import imitwalk`` is light, every name resolves, and the README's Python
example runs as written."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


def test_import_imitwalk_does_not_import_mujoco_and_every_name_resolves():
    code = (
        "import sys, imitwalk as iw\n"
        "assert 'mujoco' not in sys.modules\n"
        "for name in iw.__all__:\n"
        "    assert getattr(iw, name) is not None, name\n"
        "assert set(iw.__all__) <= set(dir(iw))\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_an_unknown_name_is_an_attribute_error():
    import imitwalk

    with pytest.raises(AttributeError, match="has no attribute 'learn_step'"):
        imitwalk.learn_step  # noqa: B018


def _readme_python() -> list[str]:
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)
    assert len(blocks) == 2, "the README has two Python examples: the library, the environment"
    return blocks


@pytest.mark.slow
def test_the_readmes_python_example_runs(tmp_path):
    subprocess.run([sys.executable, "-c", _readme_python()[0]], check=True, cwd=tmp_path)
    assert (tmp_path / "RUN" / "metrics.json").exists()


@pytest.mark.slow
def test_the_readmes_environment_example_runs(tmp_path):
    out = subprocess.run([sys.executable, "-c", _readme_python()[1]], check=True, cwd=tmp_path,
                         capture_output=True, text=True)  # fmt: skip
    assert "alive" in out.stdout
