"""A goal whose start scene cannot be sampled is the world's limit, not the agent's failure: the
episode is recorded as such, the run goes on, and the tables count it apart from every rate."""

from __future__ import annotations

from hsgplan.agents.registry import make_agent
from hsgplan.domain.errors import UnsampledSceneError
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.evaluation.episode import EpisodeRecord, run_episode
from hsgplan.evaluation.failures import Failure
from hsgplan.evaluation.summary import summarize
from hsgplan.evaluation.table1 import markdown
from hsgplan.sim import env as env_module
from hsgplan.sim.env import KitchenStorageEnv

GOAL = "On(butter, shelf_a) & On(cherries, shelf_b)"


def _ok(seed: int) -> EpisodeRecord:
    return EpisodeRecord(seed, "oracle", GOAL, 2, True, 1.0, None, (), 1.0)


def test_an_unsampled_start_scene_is_recorded_as_such_and_nothing_is_tried(monkeypatch):
    def no_scene(objects, seed, p_elsewhere=0.3, visuals=True, world=None):
        raise UnsampledSceneError(f"no collision-free arrangement (seed {seed})")

    monkeypatch.setattr(env_module, "sample_scene", no_scene)
    record = run_episode(
        KitchenStorageEnv(world=KITCHEN), make_agent("oracle"), parse_goal(GOAL, world=KITCHEN), 12
    )
    assert record.failure == Failure.UNSAMPLED == "unsampled_scene"
    assert not record.success and record.steps == () and record.seed == 12
    assert EpisodeRecord.from_json(record.to_json()) == record  # logged and read back


def test_unsampled_episodes_are_left_out_of_every_rate_and_counted_apart():
    unsampled = EpisodeRecord(3, "oracle", GOAL, 2, False, 0.0, "unsampled_scene", (), 0.0)
    summary = summarize([_ok(1), _ok(2), unsampled])
    assert summary["unsampled_scenes"] == {"2": 1}
    size = summary["by_size"]["2"]
    assert size["success_rate"] == 1.0 and size["episodes"] == 2
    assert "unsampled_scene" not in size["failures"]
    assert summarize([_ok(1)])["unsampled_scenes"] == {}

    report = {
        "methods": {"oracle": {"agent": "oracle", "wall_seconds": 1.0, "sittings": []} | summary},
        "goals": 3,
        "goals_file": None,
        "repeats": 1,
        "seed": 0,
    }
    text = markdown(report)
    assert "1 episode(s) whose start scene could not be sampled are left out" in text
    failures = next(line for line in text.splitlines() if line.startswith("| method"))
    assert failures.endswith("| unsampled |")
    assert "| oracle | 2 | 2 | 0 | 0 | 0 | 0 | 0 | 0 | 1 |" in text  # 2 tried, 1 unsampled


def test_a_run_with_none_or_a_summary_older_than_the_count_shows_no_such_column():
    fresh = summarize([_ok(1)])
    for summary in (fresh, {"by_size": fresh["by_size"]}):
        methods = {"oracle": {"agent": "oracle", "wall_seconds": 1.0, "sittings": []} | summary}
        report = {"methods": methods, "goals": 1, "goals_file": None, "repeats": 1, "seed": 0}
        text = markdown(report)
        assert "unsampled" not in text and "could not be sampled" not in text
