"""Files are written atomically and durably."""

from __future__ import annotations

import os

import pytest

from imitwalk import fileio


@pytest.fixture
def calls(monkeypatch):
    """Each ``fsync`` (the path it flushed) and ``replace`` (``"rename"``), in order."""
    seen: list = []
    fsync, replace = os.fsync, os.replace
    monkeypatch.setattr(
        os, "fsync", lambda fd: (seen.append(os.readlink(f"/proc/self/fd/{fd}")), fsync(fd))
    )
    monkeypatch.setattr(os, "replace", lambda a, b: (seen.append("rename"), replace(a, b)))
    return seen


@pytest.mark.skipif(not os.path.isdir("/proc/self/fd"), reason="names a descriptor by /proc")
def test_a_file_is_on_disk_before_it_is_named_and_its_name_after(tmp_path, calls):
    path = tmp_path / "a.json"
    fileio.atomic_write(path, lambda tmp: tmp.write_text("new"))
    assert path.read_text() == "new"
    assert len(calls) == 3 and calls[1:] == ["rename", str(tmp_path)]
    assert calls[0].startswith(str(tmp_path / ".a.json."))  # the data, under its temporary name


@pytest.mark.skipif(not os.path.isdir("/proc/self/fd"), reason="names a descriptor by /proc")
def test_an_export_is_on_disk_before_it_is_named(step_run, robot, tmp_path, calls):
    from imitwalk.judge.export import export_run

    out = tmp_path / "walk"
    export_run(step_run, robot, out)
    renamed = calls.index("rename")
    files = [
        p for p in calls[:renamed] if os.path.basename(os.path.dirname(p)).startswith(".walk.")
    ]
    assert sorted(os.path.basename(p) for p in files) == sorted(p.name for p in out.iterdir())
    assert calls[renamed + 1 :] == [str(tmp_path)]
