"""Work items survive a worker that dies: each is logged once, and one that kills its worker
every time ends the job in one line. The work functions live here so spawned workers import
them."""

import functools
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from hsgplan.runner.engines import RETRIES, WorkerLostError
from hsgplan.runner.items import run_items
from hsgplan.runner.run_folder import RESULTS


def square_or_die(marks: str, item: int) -> int:
    """Kills its own worker the first time it runs item 3 (a mark file remembers)."""
    mark = Path(marks) / f"died-{item}"
    if item == 3 and not mark.exists():
        mark.touch()
        os.kill(os.getpid(), signal.SIGKILL)
    return item * item


def always_die(item: int) -> int:
    if item == 1:
        os.kill(os.getpid(), signal.SIGKILL)
    return item


def sleep_and_tell(folder: str, item: int) -> int:
    """Writes its worker's pid, then works for a long while."""
    (Path(folder) / f"worker-{os.getpid()}").touch()
    time.sleep(60)
    return item


PARENT = """
import functools, sys
from hsgplan.runner.engines import LocalEngine
sys.path.insert(0, {tests!r})
from runner.test_engines import sleep_and_tell
pool = LocalEngine(2)
for item in range(4):
    pool.submit(functools.partial(sleep_and_tell, {folder!r}), item)
pool.next_done({{0}})
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux's parent-death signal")
def test_a_job_killed_with_sigkill_takes_its_workers_with_it(tmp_path):
    tests = str(Path(__file__).resolve().parents[1])
    code = PARENT.format(tests=tests, folder=str(tmp_path))
    parent = subprocess.Popen([sys.executable, "-c", code])
    try:
        deadline = time.monotonic() + 60
        while len(list(tmp_path.glob("worker-*"))) < 2:
            assert parent.poll() is None and time.monotonic() < deadline
            time.sleep(0.1)
    finally:
        parent.kill()
        parent.wait()
    workers = [int(p.name.removeprefix("worker-")) for p in tmp_path.glob("worker-*")]
    deadline = time.monotonic() + 20
    while any(_alive(pid) for pid in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not any(_alive(pid) for pid in workers)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    with open(f"/proc/{pid}/stat") as f:  # a zombie awaiting its reaper is no worker
        return f.read().split()[2] != "Z"


def test_an_item_whose_worker_is_killed_runs_again_and_is_logged_once(tmp_path):
    marks, run = tmp_path / "marks", tmp_path / "run"
    marks.mkdir()
    work = functools.partial(square_or_die, str(marks))
    items = list(range(8))
    got = run_items(work, items, key=str, run_dir=run, kind="test", workers=2)
    assert got == [i * i for i in items]
    assert (marks / "died-3").exists()  # the worker did die
    keys = [json.loads(line)["key"] for line in (run / RESULTS).read_text().splitlines()]
    assert sorted(keys) == sorted(str(i) for i in items)  # each exactly once


def test_an_item_that_kills_every_worker_ends_the_job_in_one_line(tmp_path):
    run = tmp_path / "run"
    with pytest.raises(WorkerLostError, match=f"died each of the {RETRIES + 1} times"):
        run_items(always_die, [0, 1, 2], key=str, run_dir=run, kind="test", workers=1)
    # what finished before is kept: run again, item 0 is not repeated
    keys = [json.loads(line)["key"] for line in (run / RESULTS).read_text().splitlines()]
    assert keys == ["0"]


def test_ray_runs_a_partial_and_survives_a_killed_worker(tmp_path):
    import ray  # noqa: F401  (installed by the test set-up: `make test` installs .[dev,ray])

    marks = tmp_path / "marks"
    marks.mkdir()
    work = functools.partial(square_or_die, str(marks))
    got = run_items(
        work, list(range(6)), key=str, run_dir=tmp_path / "run", kind="test", ray="local"
    )
    assert got == [i * i for i in range(6)]
    assert (marks / "died-3").exists()
    keys = [
        json.loads(line)["key"] for line in (tmp_path / "run" / RESULTS).read_text().splitlines()
    ]
    assert sorted(keys) == [str(i) for i in range(6)]


def test_a_cluster_is_sent_the_checkout_and_nothing_from_an_installed_package(
    monkeypatch, tmp_path
):
    from hsgplan.paths import HOME_VARIABLE
    from hsgplan.runner.engines import CLUSTER_EXCLUDES, cluster_env

    env = cluster_env()
    assert (Path(env["working_dir"]) / "checkpoints").is_dir()
    assert {".git", ".venv", "runs"} <= set(env["excludes"]) == set(CLUSTER_EXCLUDES)
    assert env["env_vars"]["OMP_NUM_THREADS"] == "1"
    monkeypatch.setenv(HOME_VARIABLE, str(tmp_path))  # a home holding no package
    assert "working_dir" not in cluster_env()


def test_eval_task_eval_motion_and_bench_timing_take_a_ray_address_checked_at_the_door(
    tmp_path,
):
    from typer.testing import CliRunner

    from hsgplan.cli import app

    timing = ["bench", "timing", "--sizes", "2", "--goals", "1", "--out", str(tmp_path / "t")]
    for command in (["eval", "task"], ["eval", "motion"], timing):
        result = CliRunner().invoke(app, [*command, "--ray", "127.0.0.1:1"])
        assert result.exit_code == 2 and "--ray '127.0.0.1:1'" in result.output
    assert not (tmp_path / "t").exists()  # refused before any run folder is made


def test_bench_timing_hands_its_ray_address_to_its_runs(monkeypatch, tmp_path):
    from hsgplan.benchmarks import timing

    class Handed(Exception):
        pass

    def run_evaluation(config, out, workers, on_episode, ray):
        raise Handed(ray)

    monkeypatch.setattr(timing, "run_evaluation", run_evaluation)
    with pytest.raises(Handed, match="local"):
        timing.run_timing([2], 1, 0, tmp_path / "t", ray="local")
