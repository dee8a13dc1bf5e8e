"""Recipes: named sets of settings for ``imitwalk learn --recipe``."""

from __future__ import annotations

import pytest

import imitwalk.learner
from imitwalk.cli import main
from imitwalk.commands import _split_settings
from imitwalk.config import RECIPES, apply_overrides, recipe_settings
from imitwalk.errors import ConfigError
from imitwalk.learnconfig import preset
from imitwalk.retarget import RetargetConfig


@pytest.mark.parametrize("name", RECIPES)
def test_every_shipped_recipe_names_settings_that_exist(name):
    rt, learn = _split_settings(recipe_settings(name))
    assert rt or learn
    apply_overrides(RetargetConfig(), rt)  # raises on a key that no longer exists
    apply_overrides(preset("extended"), learn)


def test_the_recipes_of_issue_5_are_shipped():
    assert set(RECIPES) >= {"landing-offsets", "refined-per-scale", "refined-back-off"}
    cfg = apply_overrides(
        preset("extended"), _split_settings(recipe_settings("refined-back-off"))[1]
    )
    assert cfg.back_off_to == 0.8 and cfg.back_off_when == ("consolidation", "trials")
    assert cfg.gains == (0.0, 0.25, 0.5, 1.0) and cfg.stratify_trials


def test_a_recipe_file_with_comments_and_its_errors(tmp_path):
    good = tmp_path / "mine.txt"
    good.write_text("# a comment\n\ngain_robots=6  # trailing comment\nseed = 3\n")
    assert recipe_settings(str(good)) == ["gain_robots=6", "seed = 3"]
    bad = tmp_path / "bad.txt"
    bad.write_text("gain_robots=6\ngain_seconds\n")
    with pytest.raises(ConfigError, match=r"line 2: 'gain_seconds' is not key=value"):
        recipe_settings(str(bad))
    with pytest.raises(ConfigError, match="valid: landing-offsets, refined-back-off"):
        recipe_settings("refined")


class _Captured(Exception):
    pass


def test_learn_applies_a_recipe_before_set_and_says_what_a_given_reference_ignores(
    tiny_reference, tmp_path, monkeypatch, capsys
):
    seen = {}

    def capture(ref, robot, config, run_dir, resume=False, progress=None):
        seen["config"] = config
        raise _Captured

    monkeypatch.setattr(imitwalk.learner, "learn", capture)
    _, path = tiny_reference
    argv = ["learn", "--reference", str(path), "--out", str(tmp_path / "run")]
    with pytest.raises(_Captured):
        main([*argv, "--recipe", "refined-back-off", "--set", "gain_robots=3"])
    cfg = seen["config"]
    assert cfg.gain_robots == 3 and cfg.gain_seconds == 30 and cfg.back_off_to == 0.8
    err = capsys.readouterr().err
    assert "retarget.search_config.refine_rounds=2: not used, the reference is given" in err
    assert main([*argv, "--recipe", "nope"]) == 2
    assert capsys.readouterr().err.strip().startswith("error: unknown recipe 'nope'")
