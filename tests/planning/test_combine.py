"""A task checkpoint combined from two others' networks (the f_preimage x f_reach grid)."""

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.domain.errors import InvalidInputError
from hsgplan.planning.regression.combine import COMBINED, combine
from hsgplan.planning.regression.planner import RegressionPlanner

ROOT = Path(__file__).resolve().parents[2] / "checkpoints"
PAPER, OURS = ROOT / "task-paper", ROOT / "task"


def _same(a: Path, b: Path) -> bool:
    return all((a / f).read_bytes() == (b / f).read_bytes() for f in ("model.safetensors",))


def test_the_combination_holds_one_checkpoints_preimage_and_the_others_reach(tmp_path):
    out = tmp_path / "grid"
    record = combine(PAPER, OURS, out)
    assert _same(out / "preimage", PAPER / "preimage") and _same(out / "forward", PAPER / "forward")
    assert _same(out / "reach", OURS / "reach") and not _same(out / "reach", PAPER / "reach")
    assert json.loads((out / COMBINED).read_text()) == record
    assert record["preimage"] == str(PAPER) and record["reach"] == str(OURS)
    RegressionPlanner(out)  # loads as any task checkpoint
    assert combine(PAPER, OURS, out) == record  # made again in place: the same


def test_a_missing_network_or_an_occupied_folder_is_refused_before_writing(tmp_path):
    with pytest.raises(InvalidInputError, match="no trained f_reach"):
        combine(PAPER, tmp_path / "nothing", tmp_path / "a")
    assert not (tmp_path / "a").exists()
    taken = tmp_path / "taken"
    taken.mkdir()
    (taken / "notes.txt").write_text("mine")
    result = CliRunner().invoke(
        app,
        ["train", "combine", "--preimage", str(PAPER), "--reach", str(OURS), "--out", str(taken)],
    )
    assert result.exit_code == 2 and "holds something else" in result.output
    assert (taken / "notes.txt").read_text() == "mine"
