"""`train motion-search`: every combination of a grid trained once and judged by its held-out
training loss, resumable, refusing in one line a grid it cannot judge."""

import json

import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.domain.errors import InvalidInputError
from hsgplan.motion.search import combinations, parse_grid
from hsgplan.motion.train import MotionTrainConfig

TINY = {"epochs": 2, "samples": 64, "hidden": 16, "embed": 8, "rounds": 1, "loss": "ce",
        "validation": 0.2, "model": "mlp"}  # fmt: skip


def test_the_search_trains_each_combination_and_chooses_the_lowest_held_out_loss(tmp_path):
    config = tmp_path / "base.json"
    config.write_text(json.dumps(TINY))
    grid = "dropout=0,0.3;weight_decay=0,0.01"
    args = ["train", "motion-search", "--config", str(config), "--grid", grid,
            "--out", str(tmp_path / "s"), "--markdown"]  # fmt: skip
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0, r.output
    report = json.loads((tmp_path / "s" / "search.json").read_text())
    losses = [row["validation_loss"] for row in report["rows"]]
    assert len(losses) == 4 and losses[report["chosen"]] == min(losses)
    chosen = MotionTrainConfig.from_json(json.loads((tmp_path / "s" / "chosen.json").read_text()))
    assert (chosen.dropout, chosen.weight_decay) == tuple(
        report["rows"][report["chosen"]]["settings"].values()
    )
    weights = sorted((tmp_path / "s").glob("combination-*/model.safetensors"))
    stamps = [w.stat().st_mtime_ns for w in weights]
    again = CliRunner().invoke(app, args)  # finished trainings are not trained again
    assert again.exit_code == 0 and [w.stat().st_mtime_ns for w in weights] == stamps


@pytest.mark.parametrize(
    ("grid", "why"),
    [
        ("loss=ce,bce", "need SETTING=V1,V2"),  # losses of two kinds cannot be compared
        ("lr=0.1;lr=0.2", "given twice"),
        ("", "at least one setting"),
        ("lr=" + ",".join(["0.001"] * 65), "at most 64"),
    ],
)
def test_a_grid_it_cannot_judge_is_refused_in_one_line(grid, why):
    with pytest.raises(InvalidInputError, match=why):
        combinations(MotionTrainConfig.from_json(TINY), parse_grid(grid))


def test_a_base_that_holds_no_scenes_out_is_refused():
    with pytest.raises(InvalidInputError, match="validation 0"):
        combinations(MotionTrainConfig.from_json({**TINY, "validation": 0}), {"lr": [0.001]})
