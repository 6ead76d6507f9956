"""Train, tune and test apart: declared ranges, goals cut by their hash, and the check that
finds a test episode drawn by a collection or a tuning run."""

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.evaluation.config import EvalConfig
from hsgplan.evaluation.protocol import episode_specs
from hsgplan.evaluation.seeds import GOAL_SEEDS, marked
from hsgplan.evaluation.split_check import TEST_REPEATS, check, drawn_by_test, goal_space
from hsgplan.evaluation.splits import (
    BUCKETS,
    SHARED_SIZES,
    SPLITS,
    TEST,
    TRAIN,
    TUNE,
    bucket,
    canonical,
    split_goals,
    split_of_goal,
)

runner = CliRunner()


def test_the_splits_draw_from_ranges_and_shares_of_their_own():
    splits = list(SPLITS.values())
    for i, a in enumerate(splits):
        for b in splits[i + 1 :]:
            assert not set(a.goal_share) & set(b.goal_share)
            for ra, rb in ((a.seeds, b.seeds), (a.layouts, b.layouts)):
                assert ra.stop <= rb.start or rb.stop <= ra.start, (a.name, b.name)
    assert sorted(b for s in splits for b in s.goal_share) == list(range(BUCKETS))
    assert TRAIN.seeds == GOAL_SEEDS  # the visited collection's goals are the train split's


def test_a_goal_is_canonical_whichever_look_alike_it_names_first():
    a = parse_goal("On(cherries, shelf_a) & On(cherries_2, butter)", world=KITCHEN)
    b = parse_goal("On(cherries_2, shelf_a) & On(cherries, butter)", world=KITCHEN)
    assert a != b and canonical(a) == canonical(b) and bucket(a) == bucket(b)


@pytest.mark.parametrize("split", [TRAIN, TUNE, TEST])
def test_a_split_draws_only_goals_of_its_share(split):
    goals = split_goals(split, 4, 30, split.seeds.start, world=KITCHEN)
    assert len(goals) == 30 and all(split_of_goal(g) == split.name for g in goals)
    # the first goals are the same however many are drawn: a run may grow
    assert split_goals(split, 4, 10, split.seeds.start, world=KITCHEN) == goals[:10]


def test_two_objects_are_shared_because_their_goal_space_is_too_small_to_cut():
    assert {2} == SHARED_SIZES
    assert goal_space(2) < 100  # 93: a fifth of it would be a test of some twenty goals
    goal = split_goals(TEST, 2, 1, TEST.seeds.start, stacking=False, world=KITCHEN)[0]
    assert split_of_goal(goal) is None


def test_a_test_split_run_draws_its_goals_and_seeds_from_the_test_split():
    config = EvalConfig("learned", (3,), 5, TEST.seeds.start, split="test", protocol="paper")
    specs = episode_specs(config)
    drawn = {(d.goal, d.seed) for d in drawn_by_test([3])}
    assert {(canonical(parse_goal(s.goal, world=KITCHEN)), s.seed) for s in specs} <= drawn
    with pytest.raises(InvalidInputError, match="not a test seed"):
        EvalConfig("learned", (3,), 5, 0, split="test")


def test_titles_tell_the_test_split_from_choosing_and_exploration():
    assert marked("Table", TEST.seeds.start, split="test") == "Table"
    assert "tuning" in marked("Table", 900, split="tune")
    assert "exploration" in marked("Table", 0)


def _visited(folder: Path, rows: list[tuple[str, int]]) -> Path:
    folder.mkdir(parents=True)
    config = {"kind": "reach", "unit": "visited episode", "seed": 0, "goals": "train"}
    (folder / "config.json").write_text(json.dumps(config))
    lines = [
        json.dumps({"key": f"0/0/{i}", "result": {"states": [], "goal": g, "seed": s}})
        for i, (g, s) in enumerate(rows)
    ]
    (folder / "episodes.jsonl").write_text("\n".join(lines) + "\n")
    return folder


def _drawn(split, n: int, count: int) -> list[tuple[str, int]]:
    goals = split_goals(split, n, count, GOAL_SEEDS.start, stacking=n > 2, world=KITCHEN)
    return [(str(g), GOAL_SEEDS.start + i) for i, g in enumerate(goals)]


def test_the_check_passes_a_collection_of_train_goals(tmp_path):
    _visited(tmp_path / "data" / "visited", _drawn(TRAIN, 3, 200) + _drawn(TRAIN, 2, 50))
    reports, found = check([tmp_path / "data"], [2, 3])
    assert found.folders == {"visited collections": 1}
    assert all(r.sealed for r in reports)
    two = next(r for r in reports if r.size == 2)
    assert two.shared_training and two.space == goal_space(2)  # shared, said, not a leak


def test_the_check_fails_a_collection_drawn_from_the_whole_goal_space(tmp_path):
    # the mutation it guards against: a collection that draws its goals without the cut
    _visited(tmp_path / "visited", _drawn(None, 3, 200))
    reports, _ = check([tmp_path], [3])
    assert not reports[0].sealed and reports[0].shared_training


def test_the_check_fails_a_test_episode_a_collection_ran(tmp_path):
    test = drawn_by_test([2])[TEST_REPEATS]  # at 2 objects goals are shared, episodes are not
    goal = str(parse_goal(test.goal, world=KITCHEN))
    _visited(tmp_path / "visited", [(goal, test.seed)])
    reports, _ = check([tmp_path], [2])
    assert not reports[0].sealed and len(reports[0].shared_pairs) == 1


def test_the_check_reads_tuning_runs_and_leaves_out_exploration(tmp_path):
    goal = str(split_goals(TEST, 3, 1, TEST.seeds.start, world=KITCHEN)[0])
    for name, settings in (("tune", {"split": "tune", "seed": 900}), ("explore", {"seed": 0})):
        run = tmp_path / name
        run.mkdir()
        (run / "config.json").write_text(json.dumps({"kind": "eval"} | settings))
        row = {"key": "k", "result": {"goal": goal, "seed": 1}}
        (run / "episodes.jsonl").write_text(json.dumps(row) + "\n")
    reports, found = check([tmp_path], [3])
    assert found.folders == {"tuning runs": 1}
    assert reports[0].shared_tuning == {canonical(parse_goal(goal, world=KITCHEN))}


def test_the_command_exits_1_on_a_leak_and_0_when_sealed(tmp_path):
    _visited(tmp_path / "ok" / "v", _drawn(TRAIN, 3, 50))
    _visited(tmp_path / "leak" / "v", _drawn(None, 3, 200))
    sealed = runner.invoke(app, ["splits", "check", str(tmp_path / "ok"), "--sizes", "3"])
    assert sealed.exit_code == 0 and "sealed" in sealed.stdout
    leak = runner.invoke(app, ["splits", "check", str(tmp_path / "leak"), "--sizes", "3"])
    assert leak.exit_code == 1 and "LEAKS" in leak.stdout
    missing = runner.invoke(app, ["splits", "check", str(tmp_path / "nowhere")])
    assert missing.exit_code == 2
    assert runner.invoke(app, ["splits", "show"]).exit_code == 0


def test_a_collection_refuses_a_seed_beyond_the_train_split(tmp_path):
    from hsgplan.collect.visited import collect_visited

    with pytest.raises(InvalidInputError, match="train split"):
        collect_visited(tmp_path / "v", 1, (2,), seed=TRAIN.seeds.stop - GOAL_SEEDS.start)
    assert not (tmp_path / "v").exists()


def _layouts(folder: Path, seed: int) -> Path:
    folder.mkdir(parents=True)
    (folder / "layout-000.toml").write_text(f"# hsgplan scenes --layouts 1 --seed {seed}\n")
    return folder


def test_the_check_fails_a_collection_round_test_layouts_and_a_test_run_in_others(tmp_path):
    train = _layouts(tmp_path / "train-layouts", TRAIN.layouts.start + 2)
    test = _layouts(tmp_path / "test-layouts", TEST.layouts.start)
    for name, scene, settings in (
        ("reach-train", train, {"kind": "reach", "unit": "state"}),
        ("test-run", test, {"kind": "eval", "split": "test", "seed": TEST.seeds.start}),
    ):
        (tmp_path / "runs" / name).mkdir(parents=True)
        config = settings | {"scene": str(scene)}
        (tmp_path / "runs" / name / "config.json").write_text(json.dumps(config))
    _, found = check([tmp_path / "runs"], [3])
    assert found.leaks() == []
    (tmp_path / "runs" / "reach-test").mkdir()
    config = {"kind": "reach", "unit": "state", "scene": str(test)}
    (tmp_path / "runs" / "reach-test" / "config.json").write_text(json.dumps(config))
    run = tmp_path / "runs" / "test-run" / "config.json"
    run.write_text(json.dumps({"kind": "eval", "split": "test", "scene": str(train)}))
    _, found = check([tmp_path / "runs"], [3])
    assert len(found.leaks()) == 2
    r = runner.invoke(app, ["splits", "check", str(tmp_path / "runs"), "--sizes", "3"])
    assert r.exit_code == 1 and "ran in test-split layouts" in r.stdout


def test_the_canonical_text_is_the_least_reading_of_every_drawn_goal():
    # the seal rests on each goal's bucket: the text must be what the readings themselves give
    from hsgplan.domain.kitchen import KITCHEN
    from hsgplan.evaluation.splits import canonical
    from hsgplan.symbolic.generator import random_goals

    def by_readings(goal):
        return min(" & ".join(sorted(str(lit) for lit in r.literals)) for r in goal.readings())

    for n in (2, 5, 8, 12):
        for goal in random_goals(n, 5, 11, stacking=n > 2, world=KITCHEN):
            assert canonical(goal) == by_readings(goal)
