"""Claiming a run folder: a folder made before a setting existed resumes while the setting is
at its default of None, and is refused at any other value."""

import json

import pytest

from hsgplan.domain.errors import InvalidInputError
from hsgplan.runner.run_folder import check_claim, claim


def test_a_folder_claimed_before_a_setting_existed_resumes_at_its_default(tmp_path):
    run = tmp_path / "run"
    run.mkdir()
    (run / "config.json").write_text(json.dumps({"kind": "eval", "seed": 0}) + "\n")
    assert check_claim(run, "eval", {"seed": 0, "scene": None}, "refused")
    claim(run, "eval", {"seed": 0, "scene": None}, "refused")
    assert json.loads((run / "config.json").read_text()) == {"kind": "eval", "seed": 0}
    for other in ({"seed": 0, "scene": "scenes/a.toml"}, {"seed": 1, "scene": None}):
        with pytest.raises(InvalidInputError, match="refused"):
            check_claim(run, "eval", other, "refused")


def test_a_setting_given_when_the_folder_was_claimed_must_match(tmp_path):
    run = tmp_path / "run"
    claim(run, "eval", {"seed": 0, "scene": "scenes/a.toml"}, "refused")
    assert check_claim(run, "eval", {"seed": 0, "scene": "scenes/a.toml"}, "refused")
    with pytest.raises(InvalidInputError, match="refused"):
        check_claim(run, "eval", {"seed": 0, "scene": None}, "refused")
