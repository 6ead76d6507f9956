"""The data-loss cases a hostile user found, each reproduced and shown harmless: shipped and
foreign data are never overwritten, a resumed run never mixes checkpoints, a diverged training
saves nothing."""

import json
import shutil

import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.paths import TASK_CHECKPOINT, home

runner = CliRunner()


def run(*args):
    return runner.invoke(app, [str(a) for a in args])


def _refused(r, reason: str) -> None:
    assert r.exit_code == 2, r.output
    lines = [line for line in r.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:") and reason in lines[0], r.stderr


def _tree(folder):
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def test_eval_task_refuses_to_resume_under_a_replaced_checkpoint(tmp_path):
    checkpoint = tmp_path / "task"
    shutil.copytree(home() / TASK_CHECKPOINT, checkpoint)
    args = ["eval", "task", "--sizes", "2", "--goals", "1", "--workers", "1", "--json"]
    args += ["--checkpoint", checkpoint, "--out", tmp_path / "run"]
    first = run(*args)
    assert first.exit_code == 0, first.output
    log = (tmp_path / "run" / "episodes.jsonl").read_bytes()
    # the checkpoint replaced by another (the paper recipe's) at the same path
    shutil.rmtree(checkpoint)
    shutil.copytree(home() / "checkpoints" / "task-paper", checkpoint)
    _refused(run(*args), "another configuration or other checkpoints")
    assert (tmp_path / "run" / "episodes.jsonl").read_bytes() == log


@pytest.mark.parametrize(
    ("setting", "reason"),
    [
        ('{"lr": Infinity}', "Infinity is not a JSON number"),
        ('{"lr": NaN}', "NaN is not a JSON number"),
        ('{"lr": 1e400}', "need a finite number"),
        ('{"lr": "fast"}', "need a number"),
        ('{"lr": -1}', "must be greater than 0"),
        ('{"seed": 1180591620717411303424}', "must be at most 4294967295"),
        ('{"hidden": 1000000000000000}', "must be at most 4096"),
        ('{"copies": 1000000000}', "must be at most 1000"),
        ('{"epochs": 2.5}', "need an integer"),
        ("[1, 2]", "must hold one JSON object"),
        ('{"wings": 2}', "unknown training setting(s): wings"),
    ],
)
def test_bad_training_settings_are_refused_before_anything_is_written(tmp_path, setting, reason):
    config = tmp_path / "config.json"
    config.write_text(setting)
    commands = [["train", "task"]] + ([["train", "motion"]] if "copies" not in setting else [])
    for command in commands:
        _refused(run(*command, "--config", config, "--out", tmp_path / "out"), reason)
        assert not (tmp_path / "out").exists()


def test_training_configs_that_are_not_utf8_are_refused(tmp_path):
    config = tmp_path / "config.json"
    config.write_text('{"lr": 0.01}', encoding="utf-16")
    _refused(run("train", "task", "--config", config, "--out", tmp_path / "out"), "not UTF-8")


def test_a_diverging_training_saves_nothing():
    from hsgplan import training
    from hsgplan.domain.errors import InvalidInputError

    with pytest.raises(InvalidInputError, match="diverged at epoch 3"):
        training.check_loss(float("nan"), "preimage", 3)


def test_training_never_writes_into_a_foreign_folder(tmp_path):
    run_folder = tmp_path / "run"
    run_folder.mkdir()
    (run_folder / "episodes.jsonl").write_text('{"key": "a", "result": 1}\n')
    before = _tree(run_folder)
    _refused(run("train", "task", "--out", run_folder), "holds other files and no checkpoint")
    motion = tmp_path / "motion"
    shutil.copytree(home() / "checkpoints" / "motion" / "place-gnn", motion)
    # a finished motion checkpoint: retraining it as a task planner would replace it
    motion_before = _tree(motion)
    _refused(run("train", "task", "--out", motion), "trained with another configuration")
    task = tmp_path / "task"
    shutil.copytree(home() / TASK_CHECKPOINT, task)
    task_before = _tree(task)  # its networks live in subfolders
    _refused(run("train", "motion", "--out", task), "trained with another configuration")
    assert _tree(run_folder) == before and _tree(motion) == motion_before
    assert _tree(task) == task_before


def test_eval_never_writes_into_a_checkpoint_folder(tmp_path):
    checkpoint = tmp_path / "task"
    shutil.copytree(home() / TASK_CHECKPOINT, checkpoint)
    before = _tree(checkpoint)
    r = run(
        "eval", "world", "--agent", "oracle", "--sizes", "2", "--goals", "1", "--out", checkpoint
    )
    _refused(r, "holds other files and no eval-table run")
    r = run("eval", "task", "--planner", "fd", "--sizes", "2", "--goals", "1", "--out", checkpoint)
    _refused(r, "holds other files and no eval-task run")
    assert _tree(checkpoint) == before


def test_one_commands_run_folder_is_refused_by_another(tmp_path):
    folder = tmp_path / "run"
    folder.mkdir()
    (folder / "config.json").write_text(json.dumps({"kind": "eval-task", "planner": "fd"}))
    r = run("eval", "motion", "--trials", "1", "--out", folder)
    _refused(r, "is not an eval-motion run folder (it holds an eval-task run)")
    r = run("collect", "reach", "--states", "1", "--out", folder)
    _refused(r, "is not a reach run folder")


def test_collect_in_a_checkout_writes_under_runs_not_over_the_shipped_data(tmp_path, monkeypatch):
    shipped = tmp_path / "data" / "motion"
    shutil.copytree(home() / "data" / "motion", shipped)
    before = _tree(shipped)
    monkeypatch.chdir(tmp_path)
    # naming the shipped folder: refused, since its dataset was made with other settings
    r = run("collect", "place", "--samples", "60", "--workers", "1", "--out", "data/motion")
    _refused(r, "collected with other settings (samples 14573, seed 0)")
    r = run("collect", "place", "--samples", "0", "--workers", "1", "--out", "data/motion")
    _refused(r, "greater than or equal to 1")  # once it emptied the dataset
    # the default is a fresh folder under runs/
    r = run("collect", "place", "--samples", "1", "--workers", "1", "--tasks-per-chunk", "1")
    assert r.exit_code == 0, r.output
    assert (tmp_path / "runs" / "collect-motion" / "place.npz").exists()
    assert _tree(shipped) == before
