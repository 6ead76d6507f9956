"""A Ray node lost in the middle of a run (its raylet killed) costs its items a retry on
another node, never the run: every item is logged once. The work function lives here so that
Ray's workers import it."""

import json
import os
import signal
from pathlib import Path

import pytest

from hsgplan.runner.items import run_items
from hsgplan.runner.run_folder import RESULTS


def square_or_lose_my_node(marks: str, item: int) -> int:
    """The first time it runs item 3, kills the raylet that started its worker: the node goes
    with every worker on it."""
    mark = Path(marks) / f"lost-{item}"
    if item == 3 and not mark.exists():
        mark.write_text(Path(f"/proc/{os.getppid()}/cmdline").read_text())
        os.kill(os.getppid(), signal.SIGKILL)
        os._exit(1)  # as the node's workers do when their raylet is gone
    return item * item


@pytest.mark.slow
def test_a_node_lost_mid_run_costs_its_items_a_retry_and_every_item_is_logged_once(tmp_path):
    import functools

    import ray
    from ray.cluster_utils import Cluster

    cluster = Cluster(initialize_head=True, head_node_args={"num_cpus": 0})
    for _ in range(2):  # the work runs on these two; the head, which the driver joins, stays
        cluster.add_node(num_cpus=1)
    cluster.wait_for_nodes()
    marks, run = tmp_path / "marks", tmp_path / "run"
    marks.mkdir()
    try:
        work = functools.partial(square_or_lose_my_node, str(marks))
        got = run_items(
            work, list(range(6)), key=str, run_dir=run, kind="test", ray=cluster.address
        )
    finally:
        ray.shutdown()
        cluster.shutdown()
    assert got == [i * i for i in range(6)]
    assert "raylet" in (marks / "lost-3").read_text()  # a node was lost: its raylet killed
    keys = [json.loads(line)["key"] for line in (run / RESULTS).read_text().splitlines()]
    assert sorted(keys) == [str(i) for i in range(6)]
