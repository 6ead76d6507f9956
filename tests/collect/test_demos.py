"""The shipped demonstrations, their format, and collection (resume included)."""

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.collect import demos as record_demos
from hsgplan.collect.demos import collect_demos
from hsgplan.data.demos import TASKS, demos_world, load_demos
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.scene_file import read_world
from hsgplan.symbolic.transition import apply

SHIPPED = Path(__file__).resolve().parents[2] / "data" / "demos" / "v1"
SCENES = Path(__file__).resolve().parents[2] / "scenes"


def test_the_paper_task_mix():
    kinds = [t.split("-")[0] for t, _ in TASKS]
    assert len(TASKS) == 18
    assert (kinds.count("place"), kinds.count("stack"), kinds.count("inside")) == (6, 9, 3)
    assert len({t for t, _ in TASKS}) == 18


def test_shipped_demos_replay_in_the_transition_model():
    demos = load_demos(SHIPPED, world=KITCHEN)
    assert [d.task for d in demos] == [t for t, _ in TASKS]
    for d in demos:
        states, actions = d.symbolic_states(), d.symbolic_actions()
        goal = d.goal_literals()
        assert actions, d.task
        assert not goal.satisfied_by(states[0]) and goal.satisfied_by(states[-1])
        for before, action, after in zip(states[:-1], actions, states[1:], strict=True):
            assert apply(before, action) == after, (d.task, str(action))


def test_demos_stay_out_of_the_evaluation_distribution():
    for d in load_demos(SHIPPED, world=KITCHEN):
        goal = d.goal_literals()
        stacked = any(lit.args[-1] in goal.objects for lit in goal.literals)
        assert goal.size == 1 or (goal.size == 2 and stacked)


def test_corrupted_or_missing_datasets_are_refused(tmp_path):
    with pytest.raises(InvalidInputError, match="does not exist"):
        load_demos(tmp_path / "nothing", world=KITCHEN)
    bad = tmp_path / "bad"
    bad.mkdir()
    (bad / "meta.json").write_text((SHIPPED / "meta.json").read_text())
    (bad / "demos.jsonl").write_text('{"task": "x", "goal"\n')
    with pytest.raises(InvalidInputError, match="demos.jsonl:1: not a demonstration"):
        load_demos(bad, world=KITCHEN)
    (bad / "meta.json").write_text("{not json")
    with pytest.raises(InvalidInputError, match="not valid JSON"):
        load_demos(bad, world=KITCHEN)


def test_collection_resumes_without_repeating(tmp_path, monkeypatch):
    monkeypatch.setattr(record_demos, "TASKS", TASKS[:2])
    first = collect_demos(tmp_path, seed=3)
    log = tmp_path / "demos.jsonl"
    lines = log.read_text().splitlines()
    assert len(first) == 2 and len(lines) == 2
    log.write_text(lines[0] + "\n" + lines[1][:30])  # interrupted while writing the second
    second = collect_demos(tmp_path, seed=3)
    assert second[0] == first[0] and second[1].task == first[1].task
    tasks = []
    for line in log.read_text().splitlines():
        try:
            tasks.append(json.loads(line)["task"])
        except json.JSONDecodeError:
            continue
    assert sorted(tasks) == sorted(t for t, _ in TASKS[:2])
    with pytest.raises(InvalidInputError, match="another seed"):
        collect_demos(tmp_path, seed=4)


def test_cli_refuses_a_dataset_made_with_another_seed(tmp_path):
    (tmp_path / "meta.json").write_text(
        json.dumps({"format": "hsgplan-demos", "version": 1, "seed": 7})
    )
    r = CliRunner().invoke(app, ["collect", "demos", "--seed", "0", "--out", str(tmp_path)])
    assert r.exit_code == 2 and "another seed" in r.stderr


FULL_SCENE = SHIPPED.parent / "full-scene"


def test_full_scene_demos_hold_every_type_and_replay_in_the_transition_model():
    demos = load_demos(FULL_SCENE, world=KITCHEN)
    assert [d.task for d in demos] == [t for t, _ in TASKS]
    assert json.loads((FULL_SCENE / "meta.json").read_text())["full_scene"] is True
    for d in demos:
        assert sorted(d.objects) == sorted(KITCHEN.object_types), d.task
        states, actions = d.symbolic_states(), d.symbolic_actions()
        assert d.goal_literals().satisfied_by(states[-1])
        for before, action, after in zip(states[:-1], actions, states[1:], strict=True):
            assert apply(before, action) == after, (d.task, str(action))


def test_the_learning_curve_set_starts_with_the_full_scene_set_and_replays():
    rounds = load_demos(FULL_SCENE.parent / "full-scene-rounds", world=KITCHEN)
    assert len(rounds) == 8 * len(TASKS)
    assert rounds[: len(TASKS)] == load_demos(FULL_SCENE, world=KITCHEN)
    assert len({d.seed for d in rounds}) == len(rounds)
    for d in rounds[len(TASKS) :]:
        states, actions = d.symbolic_states(), d.symbolic_actions()
        assert d.goal_literals().satisfied_by(states[-1]), d.task
        for before, action, after in zip(states[:-1], actions, states[1:], strict=True):
            assert apply(before, action) == after, (d.task, str(action))


def test_a_full_scene_collection_is_not_resumed_as_a_goal_objects_one(tmp_path, monkeypatch):
    monkeypatch.setattr(record_demos, "TASKS", TASKS[:1])
    (demo,) = collect_demos(tmp_path, seed=3, full_scene=True)
    assert len(demo.objects) == 6 and len(demo.goal_literals().objects) == 1
    with pytest.raises(InvalidInputError, match="every object type"):
        collect_demos(tmp_path, seed=3)


def _stub_recorder(seeds: list[int]):
    """A recorder that runs no simulation: one made-up transition per task, its seed noted."""

    def record(task, goal_text, seed, full_scene=False, world=KITCHEN):
        seeds.append(seed)
        return record_demos.Demo(
            task, goal_text, seed, ("butter",), ("a",), (("x",), ("y",)), world=KITCHEN
        )

    return record


def test_rounds_record_every_task_again_in_scenes_of_their_own(tmp_path, monkeypatch):
    monkeypatch.setattr(record_demos, "TASKS", TASKS[:2])
    seeds: list[int] = []
    monkeypatch.setattr(record_demos, "record_demo", _stub_recorder(seeds))
    (first_round := tmp_path / "one").mkdir()
    one = collect_demos(first_round, seed=3)
    three = collect_demos(tmp_path / "three", seed=3, rounds=3)
    names = [t for t, _ in TASKS[:2]]
    assert [d.task for d in three] == names + [f"{t}@2" for t in names] + [f"{t}@3" for t in names]
    assert three[:2] == one  # the first round is the paper's set, seeds and all
    assert len({d.seed for d in three}) == 6
    meta = json.loads((tmp_path / "three" / "meta.json").read_text())
    assert meta["rounds"] == 3
    seeds.clear()
    started: list[int] = []
    # a set grows by the missing rounds, and says how many it already holds
    grown = collect_demos(first_round, seed=3, rounds=2, on_start=started.append)
    assert grown == three[:4] and len(seeds) == 2 and started == [2]
    assert json.loads((first_round / "meta.json").read_text())["rounds"] == 2
    with pytest.raises(InvalidInputError, match="rounds 0"):
        collect_demos(tmp_path / "none", seed=3, rounds=0)


def test_cli_refuses_zero_rounds_in_one_line(tmp_path):
    r = CliRunner().invoke(app, ["collect", "demos", "--rounds", "0", "--out", str(tmp_path / "d")])
    assert r.exit_code == 2 and "rounds" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "d").exists()


def test_demos_recorded_in_a_layout_keep_it_and_are_not_resumed_in_the_kitchen(
    tmp_path, monkeypatch
):
    monkeypatch.setattr(record_demos, "TASKS", TASKS[:1])
    layout = SCENES / "layouts" / "layout-003.toml"
    (demo,) = collect_demos(tmp_path, seed=3, scene=layout)
    world = read_world(layout)
    assert demo.world == world != KITCHEN
    assert json.loads((tmp_path / "meta.json").read_text())["scene"] == str(layout)
    assert demos_world(tmp_path, KITCHEN) == world
    assert demo.goal_literals().satisfied_by(load_demos(tmp_path, world)[0].symbolic_states()[-1])
    with pytest.raises(InvalidInputError, match="recorded in"):
        collect_demos(tmp_path, seed=3)


def test_a_scene_without_the_tasks_groceries_is_refused_in_one_line(tmp_path):
    scene = SCENES / "new-objects" / "new-objects-000.toml"
    out = tmp_path / "demos"
    r = CliRunner().invoke(app, ["collect", "demos", "--scene", str(scene), "--out", str(out)])
    assert r.exit_code == 2 and len(r.stderr.strip().splitlines()) == 1
    assert "the demonstration tasks name the kitchen's groceries" in r.stderr
    assert not out.exists()
