"""Collecting primitives executed in the simulated world (`hsgplan collect reach`)."""

import json
import random
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

import hsgplan
from hsgplan.cli import app
from hsgplan.collect.reach import (
    ACTIONS_PER_STATE,
    MAX_OBJECTS,
    MIN_OBJECTS,
    ReachItem,
    choose_actions,
    draw_reach_state,
    record_reach_state,
    run_reach_item,
    run_trials,
)
from hsgplan.data.world_trials import load_world_trials, trials_of
from hsgplan.domain.actions import Pick, Place, Push
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import in_grasp, on
from hsgplan.domain.scene_file import read_world
from hsgplan.planning.heuristic import action_for, candidate_literals
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.scene import Scene

BOUNDED = [s for s in KITCHEN.surface_capacity if s != "open_space"]  # shelf tops, prepush regions
NEW_OBJECTS = Path(__file__).parents[2] / "scenes/new-objects/new-objects-000.toml"
LAYOUT = Path(__file__).parents[2] / "scenes/layouts/layout-000.toml"


def _situations(s: SymbolicSceneGraph) -> set[str]:
    found = set()
    if s.held() is not None:
        found.add("held")
    if any(len(s.resting_on(x)) >= KITCHEN.surface_capacity[x] for x in BOUNDED):
        found.add("full surface")
    if any(len(s.inside(x)) >= KITCHEN.interior_capacity[x] for x in KITCHEN.shelves):
        found.add("full interior")
    if any(s.resting_on(o) for o in s.objects):
        found.add("covered")
    return found


def test_drawn_states_are_reproducible_within_limits_and_often_hard():
    states = [draw_reach_state(3, i, KITCHEN) for i in range(200)]
    assert states == [draw_reach_state(3, i, KITCHEN) for i in range(200)]
    assert states != [draw_reach_state(4, i, KITCHEN) for i in range(200)]
    for s in states:  # the world's limits (capacities, towers, fit) accept every one
        assert (
            SymbolicSceneGraph.from_literals(s.objects, s.literals, limits=True, world=KITCHEN) == s
        )
    assert {len(s.objects) for s in states} == set(range(MIN_OBJECTS, MAX_OBJECTS + 1))
    situations = [_situations(s) for s in states]
    counts = {
        k: sum(k in found for found in situations)
        for k in ("held", "full surface", "full interior", "covered")
    }
    assert 70 <= counts["held"] <= 130, counts
    assert min(counts["full surface"], counts["covered"]) >= 40, counts
    assert counts["full interior"] >= 20, counts
    for s in states:  # what is held rests on nothing and carries nothing
        assert s.held() is None or not s.resting_on(s.held())


def test_actions_are_the_heuristics_distinct_and_of_every_kind():
    kinds = set()
    for i in range(30):
        state = draw_reach_state(0, i, KITCHEN)
        named = {action_for(lit, state) for lit in candidate_literals(state)}
        chosen = choose_actions(state, random.Random(i))
        assert chosen == choose_actions(state, random.Random(i))
        assert len(set(chosen)) == len(chosen) == min(ACTIONS_PER_STATE, len(named))
        assert set(chosen) <= named
        kinds |= {type(a) for a in chosen}
    assert kinds == {Pick, Place, Push}


def test_the_world_refuses_a_pick_while_the_hand_holds_another_object():
    state = SymbolicSceneGraph.from_literals(
        ("cherries", "butter"), [in_grasp("butter"), on("cherries", "open_space")], world=KITCHEN
    )
    # the place first: the pick after it starts from the staged hand again, not the empty one
    actions = [Place("butter", "open_space"), Pick("cherries"), Push("cherries", "shelf_a")]
    with Scene((), world=KITCHEN) as scene:
        row = run_trials(scene, state, actions, random.Random(0))
    placed, pick, push = trials_of(row, world=KITCHEN)
    assert placed.status == "success" and placed.after.holds(on("butter", "open_space"))
    assert pick.status == push.status == "invalid" and pick.after == push.after == state


def test_a_state_is_recorded_the_same_whatever_its_process_ran_before():
    with Scene((), world=KITCHEN) as scene:
        first = record_reach_state(scene, 0, 5)
    with Scene((), world=KITCHEN) as scene:
        record_reach_state(scene, 0, 7)
        again = record_reach_state(scene, 0, 5)
    assert first == again and first["trials"]


def test_the_collector_never_asks_the_transition_model(monkeypatch):
    def forbidden(*args, **kwargs):
        raise AssertionError("the transition model was asked")

    for name in ("why_not", "apply", "applicable_actions"):
        monkeypatch.setattr(f"hsgplan.symbolic.transition.{name}", forbidden)
    # and any call into the rules' files however reached (feasibility is left out: building a
    # state checks its structure there, which asks nothing about actions)
    package = Path(hsgplan.__file__).resolve().parent
    rules = (package / "symbolic", package / "planning" / "fast_downward.py")
    calls = []

    def profile(frame, event, arg):
        path = Path(frame.f_code.co_filename)
        if event == "call" and any(r == path or r in path.parents for r in rules):
            calls.append(frame.f_code.co_name)

    # in this process, where the patch holds (the collector's workers are fresh processes)
    sys.setprofile(profile)
    try:
        rows = [run_reach_item(ReachItem(1, i)) for i in range(2)]
    finally:
        sys.setprofile(None)
    assert calls == [] and sum(len(trials_of(r, world=KITCHEN)) for r in rows) > 0


@pytest.mark.slow
def test_collect_reach_end_to_end_and_a_rerun_repeats_nothing(tmp_path):
    out = tmp_path / "reach"
    args = ["collect", "reach", "--states", "2", "--workers", "1", "--out", str(out)]
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0, r.output
    assert "; 2 run now" in r.stdout
    lines = (out / "episodes.jsonl").read_text().splitlines()
    assert sorted(json.loads(x)["key"] for x in lines) == ["0/0", "0/1"]
    trials = load_world_trials(out, world=KITCHEN)
    assert 0 < len(trials) <= 2 * ACTIONS_PER_STATE
    assert f"{len(trials)} primitives executed" in r.stdout
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0 and "; 0 run now" in r.stdout
    assert (out / "episodes.jsonl").read_text().splitlines() == lines
    r = CliRunner().invoke(app, [*args[:2], "--states", "3", *args[4:]])
    assert r.exit_code == 0 and "; 1 run now" in r.stdout
    assert (out / "episodes.jsonl").read_text().splitlines()[:2] == lines


@pytest.mark.parametrize(
    ("option", "value"), [("--states", "0"), ("--states", "-3"), ("--workers", "0")]
)
def test_bad_counts_are_refused_in_one_line(tmp_path, option, value):
    r = CliRunner().invoke(app, ["collect", "reach", option, value, "--out", str(tmp_path)])
    assert r.exit_code == 2 and "greater than or equal to 1" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and not (tmp_path / "config.json").exists()


def test_a_folder_collected_with_other_settings_is_refused(tmp_path):
    (tmp_path / "config.json").write_text('{"kind": "reach", "seed": 0}\n')
    r = CliRunner().invoke(app, ["collect", "reach", "--states", "1", "--out", str(tmp_path)])
    assert r.exit_code == 2 and "other settings" in r.stderr


def test_states_are_drawn_staged_and_recorded_in_the_scenes_world():
    world = read_world(NEW_OBJECTS)
    states = [draw_reach_state(0, i, world) for i in range(40)]
    names = set(world.object_types)
    assert all({world.type_of(o) for o in s.objects} <= names for s in states)
    assert {x for s in states for lit in s.literals for x in lit.args} - set(world.surfaces) - {
        o for s in states for o in s.objects
    } == set()  # every place a literal names is the scene's own
    with Scene((), world=world) as scene:
        row = record_reach_state(scene, 0, 3)
    assert row["trials"] and trials_of(row, world=world)


@pytest.mark.slow
def test_a_collection_round_a_folder_of_scenes_records_it_and_is_read_in_each(tmp_path):
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    (scenes / "a.toml").write_text(LAYOUT.read_text())
    (scenes / "b.toml").write_text(NEW_OBJECTS.read_text())
    out = tmp_path / "reach"
    args = ["collect", "reach", "--states", "2", "--workers", "1", "--out", str(out)]
    r = CliRunner().invoke(app, [*args, "--scene", str(scenes)])
    assert r.exit_code == 0, r.output
    assert json.loads((out / "config.json").read_text())["scene"] == str(scenes)
    lines = (out / "episodes.jsonl").read_text().splitlines()
    rows = {json.loads(x)["key"]: json.loads(x)["result"] for x in lines}
    # state k in the k-th file: the layout holds the kitchen's groceries, the other new ones
    assert set(rows["0/0"]["objects"]) <= set(KITCHEN.object_types)
    assert not set(rows["0/1"]["objects"]) & set(KITCHEN.object_types)
    worlds = [read_world(LAYOUT), read_world(NEW_OBJECTS)]
    assert len(load_world_trials(out, worlds)) == sum(len(r["trials"]) for r in rows.values())
    # the same folder in another world is another collection
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 2 and "other settings" in r.stderr
    # networks that know the kitchen's names cannot read the new groceries; geometry can
    r = CliRunner().invoke(app, ["eval", "reach", "--data", str(out)])
    assert r.exit_code == 2 and len(r.stderr.strip().splitlines()) == 1
    assert "names others" in r.stderr
    geometry = Path(__file__).parents[2] / "checkpoints/task-geometry"
    r = CliRunner().invoke(
        app, ["eval", "reach", "--data", str(out), "--checkpoint", str(geometry)]
    )
    assert r.exit_code == 0, r.output
    assert "(staged in 2 worlds)" in " ".join(r.stdout.split())


def test_a_collection_whose_scene_is_gone_is_refused_in_one_line(tmp_path):
    (tmp_path / "config.json").write_text('{"kind": "reach", "scene": "nowhere/scenes"}\n')
    (tmp_path / "episodes.jsonl").write_text("")
    r = CliRunner().invoke(app, ["eval", "reach", "--data", str(tmp_path)])
    assert r.exit_code == 2 and len(r.stderr.strip().splitlines()) == 1
    assert "nowhere/scenes" in r.stderr and "not found" in r.stderr
