"""Shipped checkpoints and data are found from any folder; the environment variable wins."""

import subprocess
import sys
from pathlib import Path

from hsgplan import paths

REPO = Path(__file__).resolve().parents[1]


def test_the_home_is_the_checkout_wherever_the_process_stands(tmp_path, monkeypatch):
    monkeypatch.delenv(paths.HOME_VARIABLE, raising=False)
    monkeypatch.chdir(tmp_path)
    assert paths.home() == REPO
    assert paths.shipped(paths.TASK_CHECKPOINT) == REPO / "checkpoints" / "task"


def test_a_path_present_here_or_absolute_is_taken_as_given(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "checkpoints" / "task").mkdir(parents=True)
    assert paths.shipped("checkpoints/task") == Path("checkpoints/task")
    assert paths.shipped(tmp_path / "elsewhere") == tmp_path / "elsewhere"


def test_the_environment_variable_names_the_home(tmp_path, monkeypatch):
    monkeypatch.setenv(paths.HOME_VARIABLE, str(tmp_path))
    monkeypatch.chdir(tmp_path.parent)
    assert paths.home() == tmp_path
    assert paths.shipped("data/demos/v1") == tmp_path / "data" / "demos" / "v1"


def test_eval_task_runs_from_another_folder_on_the_shipped_checkpoint(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "hsgplan.cli", "eval", "task", "--sizes", "2", "--goals", "1",
         "--planner", "regression", "--workers", "1", "--json"],
        cwd=tmp_path, capture_output=True, text=True,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert '"episodes": 1' in result.stdout
    assert (tmp_path / "runs").is_dir()  # run folders go where the user is
