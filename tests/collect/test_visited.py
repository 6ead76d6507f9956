"""f_reach's labels from the states the agent visits (`hsgplan collect visited`)."""

import json
import random
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.collect.reach import ACTIONS_PER_STATE, choose_actions, trials_from_here
from hsgplan.collect.visited import (
    VisitedItem,
    _goal,
    collect_visited,
    explore_episode,
    run_visited_item,
)
from hsgplan.data.world_trials import load_world_trials, trials_of
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import in_grasp, on
from hsgplan.domain.scene_file import read_world
from hsgplan.evaluation.seeds import GOAL_SEEDS, TUNING
from hsgplan.planning.regression.train import TaskTrainConfig, _examples
from hsgplan.scene_graph.symbol_mapping import map_symbols
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.scene import Scene
from hsgplan.sim.staging import stage
from tests.forbidden_calls import PACKAGE, RULES, rules_forbidden


def test_trials_from_a_scene_leave_it_as_it_was_the_grasp_included():
    state = SymbolicSceneGraph.from_literals(
        ["cherries", "butter"], [in_grasp("cherries"), on("butter", "open_space")], world=KITCHEN
    )
    with Scene(state.objects, world=KITCHEN) as scene:
        assert stage(scene, state, random.Random(0))
        before = {n: scene.pose(n) for n in scene.bodies}
        actions = choose_actions(state, random.Random(1))
        trials = trials_from_here(scene, state, actions)
        assert len(trials) == len(actions) and all(t.state == state for t in trials)
        assert any(t.succeeded for t in trials)  # something moved in a trial, and came back
        assert scene.held() == "cherries"
        for name, pose in before.items():
            assert np.allclose(scene.pose(name).position, pose.position, atol=1e-6), name
        assert map_symbols(scene.scene_graph()).state == state


def test_an_episode_row_holds_every_state_visited_and_is_read_as_trials():
    row = run_visited_item(VisitedItem(0, 2, 0))
    assert row["states"] and isinstance(row["success"], bool)
    trials = trials_of(row, KITCHEN)
    assert len(trials) == sum(len(s["trials"]) for s in row["states"])
    assert all(len(s["trials"]) <= ACTIONS_PER_STATE for s in row["states"])
    # the first state is the episode's start, every trial from it starts there
    first = trials_of(row["states"][0], KITCHEN)
    assert len({t.state for t in first}) == 1
    assert row == run_visited_item(VisitedItem(0, 2, 0))  # the same item, the same row


def test_the_goals_are_drawn_apart_from_every_evaluated_seed():
    item = VisitedItem(3, 4, 7)
    assert item.episode_seed >= GOAL_SEEDS.start and not set(TUNING) & set(GOAL_SEEDS)


@pytest.mark.slow
def test_collect_visited_end_to_end_a_rerun_repeats_nothing_and_training_reads_it(tmp_path):
    out = tmp_path / "visited"
    args = ["collect", "visited", "--episodes", "1", "--sizes", "2", "--workers", "1"]
    r = CliRunner().invoke(app, [*args, "--out", str(out)])
    assert r.exit_code == 0, r.output
    lines = (out / "episodes.jsonl").read_text().splitlines()
    assert [json.loads(x)["key"] for x in lines] == ["0/2/0"]
    trials = load_world_trials(out, KITCHEN)
    assert trials and f"{len(trials)} primitives executed" in r.stdout
    r = CliRunner().invoke(app, [*args, "--out", str(out)])
    assert r.exit_code == 0 and "; 0 run now" in r.stdout
    # another agent's episodes are never mixed into the collection
    other = ["--checkpoint", "checkpoints/task-paper", "--out", str(out)]
    r = CliRunner().invoke(app, [*args, *other])
    assert r.exit_code == 2 and "other settings, checkpoints, scene or goals" in r.stderr
    assert (out / "episodes.jsonl").read_text().splitlines() == lines
    # the staged states read from the same small folder: the shipped ones take half a minute
    config = TaskTrainConfig(world_trials=str(out), loop_trials=str(out))
    sources = _examples("reach", [], [], config, KITCHEN, KITCHEN)
    visited = sources["primitives executed from states the agent visited"]
    assert visited and "primitives executed in the simulated world" in sources


@pytest.mark.parametrize(("option", "value"), [("--episodes", "0"), ("--episodes", "-2")])
def test_bad_counts_are_refused_in_one_line(tmp_path, option, value):
    r = CliRunner().invoke(app, ["collect", "visited", option, value, "--out", str(tmp_path)])
    assert r.exit_code == 2 and len(r.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "config.json").exists()


def test_a_missing_checkpoint_is_refused_in_one_line_before_anything_is_written(tmp_path):
    args = ["collect", "visited", "--checkpoint", str(tmp_path / "none"), "--out", str(tmp_path)]
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 2 and len(r.stderr.strip().splitlines()) == 1
    assert "no trained network" in r.stderr and not (tmp_path / "config.json").exists()


def test_sizes_below_two_are_refused_in_one_line(tmp_path):
    r = CliRunner().invoke(app, ["collect", "visited", "--sizes", "1", "--out", str(tmp_path)])
    assert r.exit_code == 2 and "between 2 and" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and not (tmp_path / "config.json").exists()


def test_the_episode_and_its_trials_never_ask_the_hand_written_rules():
    # the goal and the start scene are drawn by the generator, as every evaluation's are, and
    # feasibility is left out as in the reach collector's test: building a state checks its
    # structure there, which asks nothing about actions
    rules = [r for r in RULES if r.name not in ("symbolic", "feasibility.py")]
    rules += [p for p in (PACKAGE / "symbolic").glob("*.py") if p.name != "generator.py"]
    item = VisitedItem(2, 3, 0)
    goal = _goal(item)
    calls: list[str] = []
    with rules_forbidden(calls, tuple(rules)):
        row = explore_episode(item, goal)
    assert calls == [] and trials_of(row, KITCHEN)


def test_training_on_a_missing_visited_collection_is_refused_before_anything_is_written(tmp_path):
    from hsgplan.domain.errors import InvalidInputError
    from hsgplan.planning.regression.train import train_task

    config = TaskTrainConfig(loop_trials=str(tmp_path / "none"), epochs=1)
    with pytest.raises(InvalidInputError, match="holds no collection"):
        train_task(config, tmp_path / "m", world=KITCHEN)
    assert not (tmp_path / "m").exists()


LAYOUT = Path(__file__).parents[2] / "scenes/layouts/layout-000.toml"
NEW_OBJECTS = Path(__file__).parents[2] / "scenes/new-objects/new-objects-000.toml"


def test_an_episode_runs_in_the_scene_files_world_and_its_trials_are_read_there():
    world = read_world(LAYOUT)
    item = VisitedItem(0, 2, 0, scene=str(LAYOUT))
    goal = _goal(item)
    row = explore_episode(item, goal)
    trials = trials_of(row, world)
    assert trials and all(t.state.world == world for t in trials)


def test_a_collection_in_a_scene_records_it_and_another_scene_is_refused(tmp_path):
    out = tmp_path / "visited"
    summary = collect_visited(out, 1, (2,), workers=1, scene=LAYOUT)
    assert summary.trials > 0
    assert json.loads((out / "config.json").read_text())["scene"] == str(LAYOUT)
    with pytest.raises(InvalidInputError, match="other settings, checkpoints, scene or goals"):
        collect_visited(out, 1, (2,), workers=1)


def test_a_scene_the_networks_cannot_read_is_refused_in_one_line_before_anything_is_written(
    tmp_path,
):
    # named by hand, the networks that know the kitchen's names are refused (given none, the
    # command runs the networks that read kind and size, as every command does)
    args = ["collect", "visited", "--scene", str(NEW_OBJECTS), "--out", str(tmp_path / "v")]
    r = CliRunner().invoke(app, [*args, "--checkpoint", "checkpoints/task"])
    assert r.exit_code == 2 and len(r.stderr.strip().splitlines()) == 1
    assert "know the kitchen's objects" in r.stderr and not (tmp_path / "v").exists()
