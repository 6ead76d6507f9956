"""The motion level end to end on a tiny scale: collect, train both networks, evaluate."""

import json

import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.collect.motion import CollectConfig, collect
from hsgplan.data.motion_store import load_dataset
from hsgplan.domain.parameters import MotionPrimitive
from hsgplan.evaluation.motion_eval import evaluate_motion
from hsgplan.motion.train import MotionTrainConfig, split_tasks, train_motion

runner = CliRunner()


@pytest.fixture(scope="module")
def checkpoints(tmp_path_factory):
    root = tmp_path_factory.mktemp("motion")
    collect(CollectConfig(MotionPrimitive.PLACE, 6, workers=1, tasks_per_chunk=2), root / "data")
    # as shipped: the GNN and the fair MLP learn from every trial (bce), their epoch chosen on
    # held-out scenes; the paper's MLP from the successes (ce), its last epoch kept
    for model, folder, head, loss, held in (
        ("gnn", "gnn", "bins", "bce", 0.34),
        ("mlp", "mlp", "bins", "bce", 0.34),
        ("mlp", "mlp-paper", "mlp", "ce", 0.0),
    ):
        config = MotionTrainConfig(
            model=model, head=head, loss=loss, data=str(root / "data"), epochs=2, hidden=16,
            embed=8, validation=held,
        )  # fmt: skip
        train_motion(config, root / "ck" / f"place-{folder}")
    return root / "ck"


def test_held_out_scenes_are_whole_tasks(checkpoints):
    trials = load_dataset(checkpoints.parent / "data" / "place_trials.npz", MotionPrimitive.PLACE)
    held = split_tasks(trials, 0.34, 0)
    assert held.any() and not held.all()
    assert not set(trials.task[held]) & set(trials.task[~held])
    assert (split_tasks(trials, 0.34, 0) == held).all()  # the seed draws the same split
    assert not split_tasks(trials, 0.0, 0).any()


def test_a_control_of_equal_size_learns_from_the_first_trials_alone(checkpoints):
    from hsgplan.domain.errors import InvalidInputError
    from hsgplan.motion.train import _training_rows

    data = str(checkpoints.parent / "data")
    every = _training_rows(MotionTrainConfig(loss="bce", data=data))
    successes = _training_rows(MotionTrainConfig(loss="ce", data=data))
    assert len(every) > len(successes) >= 2  # failed trials among them
    control = _training_rows(MotionTrainConfig(loss="bce", data=data, trials=len(successes)))
    assert len(control) == len(successes)
    assert (control.task == every.task[: len(successes)]).all()
    assert (control.attempt == every.attempt[: len(successes)]).all()
    with pytest.raises(InvalidInputError, match=f"trials {len(every) + 1}: .* {len(every)} "):
        _training_rows(MotionTrainConfig(loss="bce", data=data, trials=len(every) + 1))


@pytest.mark.slow
def test_every_model_is_tried_once_in_the_same_scenes(checkpoints):
    report = evaluate_motion(["place"], 2, 0, checkpoints, workers=1)
    place = report["place"]
    assert set(place) == {"gnn", "mlp", "mlp_paper", "random"}  # no paper-head GNN here
    trials = {name: entry["trials"] for name, entry in place.items()}
    assert len(set(trials.values())) == 1 and 1 <= trials["gnn"] <= 2
    for entry in place.values():
        levels = entry["by_crowding"].values()
        assert sum(v["trials"] for v in levels) == entry["trials"]
        wins = sum(v["success_rate"] * v["trials"] for v in levels)
        assert abs(wins - entry["success_rate"] * entry["trials"]) < 1e-9
    # the same seed, the same result
    assert evaluate_motion(["place"], 2, 0, checkpoints, workers=1) == report


@pytest.mark.slow
def test_eval_motion_cli_prints_json(checkpoints):
    r = runner.invoke(
        app,
        ["eval", "motion", "--trials", "2", "--primitives", "place", "--motion-checkpoints",
         str(checkpoints), "--workers", "1", "--json"],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    place = json.loads(r.stdout)["place"]
    assert set(place) >= {"gnn", "mlp", "random"}
    gnn, mlp, paper = place["gnn"], place["mlp"], place["mlp_paper"]
    # the fair MLP learnt from the GNN's examples, its epoch chosen by the same rule
    assert gnn["training_examples"] == mlp["training_examples"] > 0
    assert gnn["validation_examples"] == mlp["validation_examples"] > 0
    assert {gnn["chosen_epoch"], mlp["chosen_epoch"]} <= {1, 2}
    assert paper["validation_examples"] == 0 and paper["chosen_epoch"] == 2
    assert "parameters" not in place["random"] and paper["parameters"] > 0


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


def test_a_network_of_geometry_features_is_measured_in_a_scene_of_new_objects(checkpoints):
    from pathlib import Path

    from hsgplan.domain.errors import InvalidInputError

    scene = Path(__file__).parents[2] / "scenes/new-objects/new-objects-000.toml"
    geometry = checkpoints.parent / "geometry"
    config = MotionTrainConfig(
        head="bins", loss="bce", data=str(checkpoints.parent / "data"), epochs=1, hidden=16,
        embed=8, features="geometry",
    )  # fmt: skip
    train_motion(config, geometry / "place-gnn")
    report = evaluate_motion(["place"], 1, 0, geometry, workers=1, scene=scene)
    assert set(report["place"]) == {"gnn", "random"}
    assert report["place"]["gnn"]["trials"] == report["place"]["random"]["trials"] == 1
    with pytest.raises(InvalidInputError, match="know the kitchen's objects"):
        evaluate_motion(["place"], 1, 0, checkpoints, workers=1, scene=scene)


@pytest.mark.slow
def test_trainings_are_tried_in_the_same_scenes_and_given_an_interval(checkpoints, tmp_path):
    import shutil

    from hsgplan.trainings import record

    root = tmp_path / "trainings"
    for s in (0, 1):
        shutil.copytree(checkpoints / "place-gnn", root / f"seed-{s}" / "place-gnn")
    record(root, [0, 1], "place-gnn")
    report = evaluate_motion(["place"], 2, 0, root, workers=1, run_dir=tmp_path / "run")
    gnn = report["place"]["gnn"]
    one = evaluate_motion(["place"], 2, 0, root / "seed-0", workers=1)["place"]["gnn"]
    assert gnn["trials"] == one["trials"]  # scenes, not trials: each scene once per training
    assert gnn["success_rate"] == one["success_rate"]  # two copies of one network
    assert gnn["success_ci"] == [one["success_rate"]] * 2
    assert {p.name for p in (tmp_path / "run").iterdir()} >= {"seed-0", "seed-1"}
    assert gnn["success_by_training"] == {"0": one["success_rate"], "1": one["success_rate"]}
    assert "success_by_training" not in one  # one training: nothing to set beside it
