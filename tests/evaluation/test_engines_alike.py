"""An evaluation runs alike on the local pool and on Ray, and a worker killed in the middle of
an episode costs that episode a retry: every episode is logged once and the summary is an
undisturbed run's."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from hsgplan.evaluation.config import EvalConfig
from hsgplan.evaluation.protocol import run_evaluation
from hsgplan.evaluation.summary import summarize
from hsgplan.runner.run_folder import RESULTS

CONFIG = EvalConfig(agent="regression+gnn", sizes=(2,), goals=2, seed=3)
TIMES = {"seconds", "task_seconds", "motion_seconds", "execution_seconds"}


def _untimed(value):
    """A record or summary with every wall-clock time left out (they differ run to run)."""
    if isinstance(value, dict):
        return {k: _untimed(v) for k, v in value.items() if k not in TIMES and "seconds" not in k}
    if isinstance(value, list):
        return [_untimed(v) for v in value]
    return value


def _rows(run: Path) -> dict[str, dict]:
    rows = [json.loads(line) for line in (run / RESULTS).read_text().splitlines()]
    assert len(rows) == len({r["key"] for r in rows})  # each episode logged once
    return {r["key"]: _untimed(r["result"]) for r in rows}


@pytest.mark.slow
def test_ray_gives_the_local_pools_episodes_and_summary(tmp_path):
    import ray  # noqa: F401  (installed by the test set-up: `make test` installs .[dev,ray])

    local = run_evaluation(CONFIG, tmp_path / "local", workers=2)
    on_ray = run_evaluation(CONFIG, tmp_path / "ray", workers=2, ray="local")
    assert _rows(tmp_path / "ray") == _rows(tmp_path / "local")
    assert len(on_ray) == len(local) == 2
    assert _untimed(summarize(on_ray)) == _untimed(summarize(local))


def _workers_of(pid: int) -> list[int]:
    """The processes `pid` started (the pool's workers and its resource tracker)."""
    children = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:  # gone meanwhile
            continue
        if int(fields[1]) == pid:
            children.append(int(stat.parent.name))
    return children


@pytest.mark.slow
def test_a_worker_killed_mid_run_costs_its_episode_a_retry(tmp_path):
    undisturbed = run_evaluation(CONFIG, tmp_path / "calm", workers=1)
    out = tmp_path / "killed"
    command = [sys.executable, "-m", "hsgplan.cli", "eval", "world", "--planner", "regression"]
    command += ["--motion", "gnn", "--sizes", "2", "--goals", "2", "--seed", "3"]
    command += ["--workers", "1", "--out", str(out)]
    proc = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    log = out / "gnn" / RESULTS
    deadline = time.time() + 120
    while time.time() < deadline and not (log.exists() and log.read_text().count("\n") >= 1):
        time.sleep(0.05)
    killed = 0
    for pid in _workers_of(proc.pid):  # the worker, busy with the next episode
        if "spawn_main" in Path(f"/proc/{pid}/cmdline").read_text(errors="replace"):
            os.kill(pid, signal.SIGKILL)
            killed += 1
    _, err = proc.communicate(timeout=300)
    assert killed == 1 and proc.returncode == 0, err
    assert _rows(log.parent) == _rows(tmp_path / "calm")
    summary = json.loads((out / "summary.json").read_text())["methods"]["gnn"]
    assert _untimed(summary["by_size"]) == _untimed(summarize(undisturbed)["by_size"])
