"""Table 2: both agents on the same goals, the summary's shape, the tables and the plot."""

import json

import pytest

from hsgplan.benchmarks.timing import PAPER_TABLE2, run_timing, tables, timing_summary
from hsgplan.evaluation.episode import EpisodeRecord, StepRecord


def _record(task: list[float], motion: float, success=True) -> EpisodeRecord:
    steps = tuple(
        StepRecord(k + 1, "", "pick(butter)", "pick(obj=butter)", "success", "", t, motion, 1.0)
        for k, t in enumerate(task)
    )
    return EpisodeRecord(1, "search", "On(butter, shelf_a)", 2, success, 1.0, None, steps, 1.0)


def test_times_per_episode_are_sums_over_steps_with_quartiles():
    s = timing_summary([_record([1.0, 0.0], 0.5), _record([3.0], 0.5), _record([2.0], 0.5, False)])
    assert s["task_s"] == 2.0 and s["task_q1"] == 1.5 and s["task_q3"] == 2.5
    # motion per episode: choosing parameters and executing them, every step
    assert s["motion_s"] == 1.5 and s["motion_q3"] == 2.25  # 3.0, 1.5, 1.5
    assert s["success_rate"] == pytest.approx(2 / 3) and s["episodes"] == 3


@pytest.mark.slow
def test_run_writes_both_agents_on_the_same_goals(tmp_path):
    report = run_timing([2], goals=1, seed=0, out=tmp_path)  # the strongest baseline unless told
    row = report["by_size"]["2"]
    assert set(row) == {"ours", "stream-goal"}
    for v in row.values():
        assert v["episodes"] == 1 and v["task_s"] >= 0 and v["motion_s"] > 0
    episodes = {
        agent: [
            json.loads(line)["result"]
            for line in (tmp_path / agent / "episodes.jsonl").read_text().splitlines()
        ]
        for agent in ("ours", "stream-goal")
    }
    assert [(r["goal"], r["seed"]) for r in episodes["ours"]] == [
        (r["goal"], r["seed"]) for r in episodes["stream-goal"]
    ]
    assert json.loads((tmp_path / "summary.json").read_text()) == report
    text = (tmp_path / "table2.md").read_text()
    assert f"{PAPER_TABLE2['pddlstream'][2][0]:g}" in text
    assert (tmp_path / "table2.png").stat().st_size > 5000
    assert tables(report)[0].rows[0][0] == "2"
    assert "; success under the paper protocol" in tables(report)[0].title
