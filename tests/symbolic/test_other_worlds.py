"""The symbolic domain counts by the world it is given: names, capacities, what fits and what
carries come from the scene, not from the kitchen."""

import copy
import json
import random
import tomllib

import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.domain.actions import Pick, Place, Push
from hsgplan.domain.errors import InfeasibleError, InvalidInputError, UnknownNameError
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.layouts import random_layout
from hsgplan.domain.predicates import on
from hsgplan.domain.scene_file import world_of
from hsgplan.domain.scene_write import scene_data, to_toml
from hsgplan.paths import KITCHEN_SCENE
from hsgplan.planning.fast_downward import FastDownwardPlanner
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.symbolic.generator import random_goals, random_state
from hsgplan.symbolic.transition import applicable_actions, apply, why_not

DATA = tomllib.loads(KITCHEN_SCENE.read_text())
FIVE_ON_A = "On(cherries, shelf_a) & On(alphabet_soup, shelf_a) & On(tomato_soup, shelf_a) & " \
    "On(popcorn, shelf_a) & On(butter, shelf_a)"  # fmt: skip


def _world(change):
    data = copy.deepcopy(DATA)
    change(data)
    return world_of(data)


def _deep_shelf_a(data):
    # two cells deep, three wide, every cell within the hand's reach: six places
    data["shelves"][0] |= {"x": [0.36, 0.58], "y": [0.21, 0.54]}
    data["shelves"][0]["prepush"]["x"] = [0.24, 0.35]


def test_a_wider_shelf_top_holds_more_in_goals_and_in_the_transition_model():
    wide = _world(_deep_shelf_a)
    assert wide.surface_capacity["shelf_a"] == 6 and KITCHEN.surface_capacity["shelf_a"] == 4
    with pytest.raises(InfeasibleError, match="holds at most 4"):
        parse_goal(FIVE_ON_A, world=KITCHEN)
    goal = parse_goal(FIVE_ON_A, world=wide)
    four = [on(o, "shelf_a") for o in ("cherries", "alphabet_soup", "tomato_soup", "popcorn")]
    objects = (*goal.objects, "cream_cheese")
    literals = [*four, on("butter", "open_space"), on("cream_cheese", "open_space")]
    for world, applicable in ((KITCHEN, False), (wide, True)):
        state = SymbolicSceneGraph.from_literals(objects, literals, world=world)
        held = apply(state, Pick("butter"))
        assert held.world is world
        assert (why_not(held, Place("butter", "shelf_a")) is None) is applicable
    plan = FastDownwardPlanner().plan(SymbolicSceneGraph.initial(objects, world=wide), goal)
    state = SymbolicSceneGraph.initial(objects, world=wide)
    for action in plan.actions:
        state = apply(state, action)
    assert goal.satisfied_by(state)


def test_objects_of_a_new_scene_are_named_drawn_and_planned_for():
    new = random_layout(KITCHEN, 0, 0, new_objects=True)
    can = next(t.name for t in new.type_list if t.kind == "can")
    with pytest.raises(UnknownNameError):
        parse_goal(f"On({can}, shelf_a)", world=KITCHEN)
    assert parse_goal(f"On({can}, shelf_a)", world=new).objects == (can,)
    goals = random_goals(4, 5, seed=1, world=new)
    assert all(set(g.objects) <= set(new.object_types) for g in goals)
    for k, goal in enumerate(goals):
        state = random_state(goal.objects, random.Random(k), world=new)
        assert state.nodes[: len(goal.objects)] == goal.objects
        for action in FastDownwardPlanner().plan(state, goal).actions:
            state = apply(state, action)
        assert goal.satisfied_by(state)


def test_a_closed_shelf_takes_nothing_inside():
    def close_b(data):
        del data["shelves"][1]["prepush"]
        data["shelves"][1]["interior"] = False

    closed = _world(close_b)
    with pytest.raises(InfeasibleError, match="shelf_b has no interior"):
        parse_goal("In(cherries, shelf_b)", world=closed)
    state = SymbolicSceneGraph.initial(("cherries",), world=closed)
    assert not any(isinstance(a, Push) for a in applicable_actions(state))
    assert "prepush_b" not in state.nodes and "prepush_a" in state.nodes


runner = CliRunner()


def test_eval_task_runs_in_a_scene_file_and_refuses_what_its_planner_cannot_read(tmp_path):
    scene = tmp_path / "new.toml"
    scene.write_text(to_toml(scene_data(random_layout(KITCHEN, 0, 0, new_objects=True))))
    args = ["eval", "task", "--sizes", "2", "--goals", "2", "--workers", "1", "--json"]
    out = tmp_path / "run"
    r = runner.invoke(app, [*args, "--planner", "fd", "--scene", str(scene), "--out", str(out)])
    assert r.exit_code == 0, r.output
    report = json.loads(r.stdout)
    assert report["scene"] == str(scene) and report["by_size"]["2"]["success_rate"] == 1.0
    assert json.loads((out / "config.json").read_text())["scene"] == str(scene)
    other = tmp_path / "layout.toml"
    other.write_text(to_toml(scene_data(random_layout(KITCHEN, 0, 1))))
    r = runner.invoke(app, [*args, "--planner", "fd", "--scene", str(other), "--out", str(out)])
    assert r.exit_code == 2  # another world's episodes never mix with these
    # the names planner, named by hand, cannot read the new groceries (given none, eval task
    # runs the networks that read kind and size)
    names = ["--planner", "regression", "--checkpoint", "checkpoints/task"]
    r = runner.invoke(app, [*args, *names, "--scene", str(scene)])
    assert r.exit_code == 2 and len(r.output.strip().splitlines()) == 1
    assert "know the kitchen's objects" in r.output


def test_eval_task_runs_every_scene_of_a_folder_on_the_same_goal_seeds(tmp_path):
    from hsgplan.evaluation.task_eval import evaluate_task

    folder = tmp_path / "layouts"
    folder.mkdir()
    for k in range(2):
        (folder / f"layout-{k}.toml").write_text(to_toml(scene_data(random_layout(KITCHEN, 9, k))))
    episodes = evaluate_task("fd", KITCHEN_SCENE, [3], 2, 0, workers=1, scene=folder)
    assert sorted(e.scene for e in episodes) == sorted([str(p) for p in folder.iterdir()] * 2)
    by_scene = {}
    for e in episodes:
        by_scene.setdefault(e.scene, []).append(e.seed)
    assert len(set(map(tuple, map(sorted, by_scene.values())))) == 1  # the same goal seeds
    (tmp_path / "empty").mkdir()
    with pytest.raises(InvalidInputError, match="holds no scene file"):
        evaluate_task("fd", KITCHEN_SCENE, [3], 2, 0, workers=1, scene=tmp_path / "empty")


def test_goals_and_plan_take_a_scene_file(tmp_path):
    scene = tmp_path / "new.toml"
    new = random_layout(KITCHEN, 0, 0, new_objects=True)
    scene.write_text(to_toml(scene_data(new)))
    r = runner.invoke(app, ["goals", "--objects", "3", "--goals", "4", "--scene", str(scene)])
    assert r.exit_code == 0, r.output
    lines = r.stdout.splitlines()
    assert lines[0].endswith(f"--scene {scene}") and len(lines) == 5
    goals = [parse_goal(line, world=new) for line in lines[1:]]
    assert all(set(g.objects) <= set(new.object_types) for g in goals)
    r = runner.invoke(app, ["plan", "--goal", str(goals[0]), "--scene", str(scene), "--json"])
    assert r.exit_code == 0, r.output
    steps = json.loads(r.stdout)
    assert all(lit in steps[-1]["state"] for lit in map(str, goals[0].literals))
    r = runner.invoke(app, ["plan", "--goal", str(goals[0])])  # not the kitchen's names
    assert r.exit_code == 2 and "unknown" in r.output
