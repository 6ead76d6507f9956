"""The motion level end to end on a tiny scale: collect, train both networks, evaluate."""

import json

import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.collect.motion import CollectConfig, collect
from hsgplan.domain.parameters import MotionPrimitive
from hsgplan.evaluation.motion_eval import evaluate_motion
from hsgplan.motion.train import MotionTrainConfig, train_motion

runner = CliRunner()


@pytest.fixture(scope="module")
def checkpoints(tmp_path_factory):
    root = tmp_path_factory.mktemp("motion")
    collect(CollectConfig(MotionPrimitive.PLACE, 6, workers=1, tasks_per_chunk=2), root / "data")
    # as shipped: the GNN learns from every trial (bce), the MLP from the successes (ce)
    for model, head, loss in (("gnn", "bins", "bce"), ("mlp", "mlp", "ce")):
        config = MotionTrainConfig(
            model=model, head=head, loss=loss, data=str(root / "data"), epochs=2, hidden=16, embed=8
        )
        train_motion(config, root / "ck" / f"place-{model}")
    return root / "ck"


@pytest.mark.slow
def test_every_model_is_tried_once_in_the_same_scenes(checkpoints):
    report = evaluate_motion(["place"], 3, 0, checkpoints, workers=1)
    place = report["place"]
    assert set(place) == {"gnn", "mlp", "random"}  # no paper-head checkpoint here
    trials = {name: entry["trials"] for name, entry in place.items()}
    assert len(set(trials.values())) == 1 and 1 <= trials["gnn"] <= 3
    for entry in place.values():
        levels = entry["by_crowding"].values()
        assert sum(v["trials"] for v in levels) == entry["trials"]
        wins = sum(v["success_rate"] * v["trials"] for v in levels)
        assert abs(wins - entry["success_rate"] * entry["trials"]) < 1e-9
    # the same seed, the same result
    assert evaluate_motion(["place"], 3, 0, checkpoints, workers=1) == report


@pytest.mark.slow
def test_eval_motion_cli_prints_json(checkpoints):
    r = runner.invoke(
        app,
        ["eval", "motion", "--trials", "2", "--primitives", "place", "--motion-checkpoints",
         str(checkpoints), "--workers", "1", "--json"],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    assert set(json.loads(r.stdout)["place"]) >= {"gnn", "mlp", "random"}


@pytest.mark.parametrize(
    "args,message",
    [
        (["collect", "place", "--samples", "-3"], "greater than or equal to 1"),
        (
            ["eval", "motion", "--motion-checkpoints", "nowhere", "--trials", "2"],
            "no trained motion",
        ),
        (["eval", "motion", "--primitives", "pour"], "place or push"),
        (["train", "motion", "--model", "cnn"], "'cnn' is not one of 'gnn', 'mlp'"),
        (["train", "motion", "--data", "nowhere"], "no such motion data"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(args, message, tmp_path):
    r = runner.invoke(app, [*args, *(["--out", str(tmp_path / "x")] if "train" in args else [])])
    assert r.exit_code == 2, r.output
    assert message in r.output and "Traceback" not in r.output


@pytest.mark.slow
def test_eval_motion_resumes_from_its_run_folder(checkpoints, tmp_path):
    run = tmp_path / "run"
    report = evaluate_motion(["place"], 3, 0, checkpoints, workers=1, run_dir=run)
    log = run / "episodes.jsonl"
    assert [json.loads(x)["key"] for x in log.read_text().splitlines()] == ["place/0"]
    log.write_text(log.read_text() + '{"key": "place/8", "resu')  # a line cut short
    again = evaluate_motion(["place"], 3, 0, checkpoints, workers=1, run_dir=run)
    assert again == report and len(log.read_text().splitlines()) == 2  # read back, not rerun
