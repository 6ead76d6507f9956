"""Mechanics of the learned task planner: examples, training, checkpoints, the symbolic loop."""

import json
from pathlib import Path

import pytest
import torch
from typer.testing import CliRunner

from hsgplan.checkpoint import write_manifest
from hsgplan.cli import app
from hsgplan.data.demos import load_demos
from hsgplan.data.world_trials import WorldTrial
from hsgplan.domain.actions import Pick, Place
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import clear, in_grasp, inside, on
from hsgplan.paths import home, shipped
from hsgplan.planning.heuristic import action_for, candidate_literals
from hsgplan.planning.regression.examples import (
    paper_reach_examples,
    regressed_subgoals,
    world_labels,
)
from hsgplan.planning.regression.gnn import load_network
from hsgplan.planning.regression.train import TaskTrainConfig, train_task
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

DEMOS = Path(__file__).resolve().parents[2] / "data" / "demos" / "v1"
TINY = {
    "demos": str(DEMOS),
    "epochs": 2,
    "hidden": 16,
    "rounds": 1,
    "batch_size": 256,
    "copies": 1,
    "reach": "alterations",
}


def test_a_stack_demonstration_regresses_base_first():
    demo = next(
        d for d in load_demos(DEMOS, world=KITCHEN) if d.task == "stack-butter-on-cherries-shelf_a"
    )
    chain = regressed_subgoals(demo)
    assert chain[-1] == {on("cherries", "shelf_a"), on("butter", "cherries")}
    # before the last place: butter in the hand, the base on the shelf and clear
    assert chain[-2] == {on("cherries", "shelf_a"), in_grasp("butter"), clear("cherries")}


def test_paper_reach_labels_come_from_demonstrated_changes_and_their_alterations():
    demo = next(
        d for d in load_demos(DEMOS, world=KITCHEN) if d.task == "stack-butter-on-cherries-shelf_a"
    )
    examples = paper_reach_examples([demo], singles=2)
    first = examples[0]  # the first step, every label at once: the pick of cherries
    from hsgplan.planning.regression.encoding import Slots

    slots = Slots(tuple(first.data.names))
    assert first.target[slots.slot(in_grasp("cherries"))] == 1
    assert first.mask[slots.slot(in_grasp("butter"))]  # another subject: an alteration
    assert first.target[slots.slot(in_grasp("butter"))] == 0
    for ex in examples:
        assert ex.mask.any() and ex.target[ex.mask].max() <= 1


def test_predicate_only_alterations_keep_the_edge_and_change_its_predicate():
    from hsgplan.planning.regression.encoding import Slots

    demo = next(d for d in load_demos(DEMOS, world=KITCHEN) if d.task == "inside-cherries-shelf_a")
    examples = paper_reach_examples([demo], singles=1, predicates_only=True)
    negatives, positives = set(), set()
    for ex in examples:
        slots = Slots(tuple(ex.data.names))
        for e, p in ex.mask.nonzero().tolist():
            (positives if ex.target[e, p] else negatives).add(slots.literal(e, p))
    assert {in_grasp("cherries"), inside("cherries", "shelf_a")} <= positives
    # In(cherries, shelf_a) as On: the one alteration that does not hold already (Clear,
    # InGrasp's other predicate, held before the pick); no other subject or target
    assert negatives == {on("cherries", "shelf_a")}


def test_world_labels_are_what_the_executed_action_made_hold():
    from hsgplan.data.world_trials import WorldTrial

    before = SymbolicSceneGraph.from_literals(
        ["cherries", "butter"],
        [on("butter", "cherries"), on("cherries", "open_space")],
        world=KITCHEN,
    )
    after = SymbolicSceneGraph.from_literals(
        ["cherries", "butter"], [in_grasp("butter"), on("cherries", "open_space")], world=KITCHEN
    )
    labels = world_labels(WorldTrial(before, Pick("butter"), "success", after))
    assert labels == {
        in_grasp("butter"): True,
        clear("cherries"): True,
        on("butter", "cherries").negated(): True,
    }
    failed = world_labels(WorldTrial(before, Pick("butter"), "no_path", before))
    assert set(failed) == set(labels) and not any(failed.values())
    toppled = world_labels(WorldTrial(before, Place("cherries", "shelf_a"), "knocked_over", None))
    assert toppled == {on("cherries", "shelf_a"): False}


def test_action_heuristic_reads_the_state_and_checks_no_precondition():
    s = SymbolicSceneGraph.from_literals(
        ["cherries", "butter"],
        [on("butter", "cherries"), on("cherries", "prepush_a")],
        world=KITCHEN,
    )
    assert str(action_for(clear("cherries"), s)) == "pick(butter)"
    assert str(action_for(in_grasp("butter"), s)) == "pick(butter)"
    # not clear yet: named all the same, the world (or f_reach) tells it fails
    assert str(action_for(inside("cherries", "shelf_a"), s)) == "push(cherries, shelf_a)"
    assert action_for(clear("butter"), s) is None  # nothing rests on butter
    asked = candidate_literals(s)
    assert all(not s.holds(lit) for lit in asked if lit.positive)
    assert on("butter", "cherries").negated() in asked and clear("butter") not in asked


def test_training_writes_checkpoint_folders_and_resumes(tmp_path):
    config = TaskTrainConfig.from_json(TINY | {"save_every": 1})
    seen = []

    def stop_midway(name, epoch, loss):
        seen.append((name, epoch))
        if name == "reach" and epoch == 1:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        train_task(config, tmp_path, stop_midway, world=KITCHEN)
    assert (tmp_path / "preimage" / "model.safetensors").exists()
    seen.clear()
    # saved before f_reach's own epoch count existed: trained with its default, resumed
    saved = json.loads((tmp_path / "train_config.json").read_text())
    del saved["reach_epochs"]
    (tmp_path / "train_config.json").write_text(json.dumps(saved))
    train_task(config, tmp_path, lambda n, e, loss: seen.append((n, e)), world=KITCHEN)
    assert ("preimage", 1) not in seen  # finished before: not trained again
    for name in ("preimage", "reach", "forward"):
        net = load_network(tmp_path / name)
        assert json.loads((tmp_path / name / "config.json").read_text())["hidden"] == 16
        assert net.config.hidden == 16
    with pytest.raises(InvalidInputError, match="another configuration"):
        train_task(TaskTrainConfig.from_json(TINY | {"seed": 9}), tmp_path, world=KITCHEN)


def test_broken_checkpoints_are_refused(tmp_path):
    with pytest.raises(InvalidInputError, match="no trained network"):
        load_network(tmp_path)
    (tmp_path / "config.json").write_text('{"node_dim": 3}')
    (tmp_path / "model.safetensors").write_bytes(b"not a tensor file")
    with pytest.raises(InvalidInputError, match="manifest.json is missing"):
        load_network(tmp_path)
    write_manifest(tmp_path)  # files that match a manifest but are no network
    with pytest.raises(InvalidInputError, match="not a usable checkpoint"):
        load_network(tmp_path)
    (tmp_path / "config.json").write_text('{"node_dim": 4}')  # changed after the manifest
    with pytest.raises(InvalidInputError, match="does not match its manifest"):
        load_network(tmp_path)


def test_eval_task_cli_with_fast_downward(tmp_path):
    r = CliRunner().invoke(
        app,
        [
            "eval",
            "task",
            "--planner",
            "fd",
            "--sizes",
            "2",
            "--goals",
            "2",
            "--json",
            "--workers",
            "1",
            "--out",
            str(tmp_path / "run"),
        ],
    )
    assert r.exit_code == 0, r.output
    entry = json.loads(r.stdout)["by_size"]["2"]
    assert entry["success_rate"] == 1.0 and entry["plan_length_ratio"] == 1.0
    assert entry["ms_per_decision"] > 0


@pytest.mark.slow
def test_eval_task_resumes_from_its_run_folder(tmp_path):
    from hsgplan.evaluation.task_eval import evaluate_task
    from hsgplan.runner.run_folder import RESULTS

    run = tmp_path / "run"
    first = evaluate_task("fd", tmp_path, [2], 2, 0, workers=1, run_dir=run)
    lines = (run / RESULTS).read_text().splitlines()
    assert len(lines) == 2
    (run / RESULTS).write_text(lines[0] + "\n" + lines[1][:10])  # cut short mid-write
    again = evaluate_task("fd", tmp_path, [2], 3, 0, workers=1, run_dir=run)
    rows = [json.loads(x) for x in (run / RESULTS).read_text().splitlines() if x.endswith("}")]
    assert len(again) == 3 and again[0] == first[0]  # read back, not run again
    assert (again[1].goal, again[1].steps) == (first[1].goal, first[1].steps)
    assert len(rows) == 3 and len({r["key"] for r in rows}) == 3
    with pytest.raises(InvalidInputError, match="another configuration"):
        evaluate_task("fd", tmp_path / "other", [2], 1, 0, run_dir=run)


def test_eval_task_without_a_checkpoint_is_one_line(tmp_path):
    r = CliRunner().invoke(
        app, ["eval", "task", "--checkpoint", str(tmp_path), "--goals", "1", "--out", str(tmp_path)]
    )
    assert r.exit_code == 2 and "no trained network" in r.stderr
    r = CliRunner().invoke(app, ["train", "task", "--config", str(tmp_path / "none.json")])
    assert r.exit_code == 2 and "does not exist" in r.stderr


def test_preimage_targets_of_a_stacks_last_step():
    from hsgplan.planning.regression.encoding import FALSE, TRUE, Slots, decode
    from hsgplan.planning.regression.examples import preimage_examples

    demo = next(
        d for d in load_demos(DEMOS, world=KITCHEN) if d.task == "stack-butter-on-cherries-shelf_a"
    )
    last = [
        e
        for e in preimage_examples([demo])
        if e.data.edge_attr[:, -4:].sum() == 1
        and decode(e.data, e.data.goal) == [on("cherries", "shelf_a"), on("butter", "cherries")]
    ]
    ex = last[-1]
    slots = Slots(tuple(ex.data.names))
    assert ex.target[slots.slot(on("cherries", "shelf_a"))] == TRUE  # the base comes first
    assert ex.target[slots.slot(in_grasp("butter"))] == TRUE
    assert ex.target[slots.slot(clear("cherries"))] == TRUE
    assert ex.target[slots.slot(in_grasp("cherries"))] == FALSE  # the hand holds only butter


@pytest.mark.slow
def test_eval_task_runs_a_trained_checkpoint_in_worker_processes(tmp_path):
    # The pool must not fork a process that has loaded torch: forked workers hung.
    train_task(TaskTrainConfig.from_json(TINY), tmp_path, world=KITCHEN)
    r = CliRunner().invoke(
        app,
        [
            "eval",
            "task",
            "--checkpoint",
            str(tmp_path),
            "--sizes",
            "2",
            "--goals",
            "2",
            "--workers",
            "2",
            "--json",
            "--out",
            str(tmp_path / "run"),
        ],
    )
    assert r.exit_code == 0, r.output
    entry = json.loads(r.stdout)["by_size"]["2"]
    assert entry["episodes"] == 2
    assert entry["success_rate"] * 2 == 2 - sum(entry["failures"].values())


def test_bad_training_settings_are_one_line_with_exit_code_2(tmp_path):
    for bad in ({"copies": -1}, {"epochs": 0}, {"reach_copies": 99}, {"hidden": "wide"}):
        path = tmp_path / "config.json"
        path.write_text(json.dumps(bad))
        r = CliRunner().invoke(
            app, ["train", "task", "--config", str(path), "--out", str(tmp_path)]
        )
        assert r.exit_code == 2, (bad, r.output)
        assert len(r.stderr.strip().splitlines()) == 1 and next(iter(bad)) in r.stderr


def test_a_demo_limit_trains_on_the_first_demonstrations_alone(tmp_path):
    first = tmp_path / "first-three"
    first.mkdir()
    (first / "meta.json").write_text((DEMOS / "meta.json").read_text())
    lines = (DEMOS / "demos.jsonl").read_text().splitlines()
    (first / "demos.jsonl").write_text("\n".join(lines[:3]) + "\n")
    tiny = TINY | {"epochs": 1, "copies": 0}
    train_task(
        TaskTrainConfig.from_json(tiny | {"demo_limit": 3}), tmp_path / "limited", world=KITCHEN
    )
    train_task(
        TaskTrainConfig.from_json(tiny | {"demos": str(first)}), tmp_path / "cut", world=KITCHEN
    )
    for name in ("preimage", "reach", "forward"):
        limited = json.loads((tmp_path / "limited" / name / "labels.json").read_text())
        assert limited == json.loads((tmp_path / "cut" / name / "labels.json").read_text())
    with pytest.raises(InvalidInputError, match="holds 18 demonstrations"):
        train_task(
            TaskTrainConfig.from_json(tiny | {"demo_limit": 19}), tmp_path / "more", world=KITCHEN
        )
    assert not (tmp_path / "more").exists()


def test_executed_primitives_are_learnt_in_the_worlds_they_were_staged_in(tmp_path):
    from hsgplan.evaluation.config import world_of_file
    from hsgplan.planning.regression.encoding import with_features
    from hsgplan.planning.regression.examples import world_reach_examples

    scenes = Path(__file__).resolve().parents[2] / "scenes"
    layout = world_of_file(str(scenes / "layouts" / "layout-003.toml"))
    before = SymbolicSceneGraph.from_literals(["butter"], [on("butter", "shelf_a")], world=layout)
    after = SymbolicSceneGraph.from_literals(["butter"], [in_grasp("butter")], world=layout)
    trial = WorldTrial(before, Pick("butter"), "success", after)
    examples = world_reach_examples([trial], [])
    # each described in the world it was staged in, not the demonstrations'
    assert examples and all(e.world is layout for e in examples)
    example = examples[0]
    in_layout = with_features(example.as_data(), layout, "geometry")
    in_kitchen = with_features(example.as_data(), KITCHEN, "geometry")
    assert not torch.equal(in_layout.x, in_kitchen.x)  # the shelves' sizes differ
    # names describe the kitchen's groceries alone: trials among other groceries are refused
    trials = tmp_path / "reach"
    trials.mkdir()
    new = scenes / "new-objects" / "new-objects-000.toml"
    (trials / "config.json").write_text(json.dumps({"kind": "reach", "seed": 0, "scene": str(new)}))
    config = TINY | {"reach": "world", "world_trials": str(trials), "epochs": 1}
    with pytest.raises(InvalidInputError, match="know the kitchen's names alone"):
        train_task(TaskTrainConfig.from_json(config), tmp_path / "m", world=KITCHEN)
    assert not (tmp_path / "m").exists()  # refused before anything was trained


SHIPPED_TASK = sorted(p.parent.name for p in (home() / "checkpoints").glob("task*/train_config.*"))


@pytest.mark.parametrize("folder", SHIPPED_TASK)
def test_every_shipped_task_configuration_names_data_the_repository_holds(folder):
    # a shipped configuration retrains its checkpoint from what is shipped, or from `runs/`,
    # which a documented command makes (docs/retraining.md)
    config = TaskTrainConfig.from_json(
        json.loads((home() / "checkpoints" / folder / "train_config.json").read_text())
    )
    named = [config.demos] + ([config.world_trials] if config.reach == "world" else [])
    named += [config.loop_trials] if config.loop_trials else []
    for path in named:
        assert path.startswith("runs/") or shipped(path).is_dir(), path


def test_a_reach_limit_draws_a_control_of_that_size_across_the_sources():
    from hsgplan.planning.regression.train import _drawn

    by_source = {"staged": list(range(10)), "visited": list(range(100, 130))}
    drawn = _drawn(by_source, 12, seed=0)
    assert sum(len(v) for v in drawn.values()) == 12 and drawn["visited"]
    assert all(set(drawn[k]) <= set(by_source[k]) and drawn[k] == sorted(drawn[k]) for k in drawn)
    assert drawn == _drawn(by_source, 12, seed=0) != _drawn(by_source, 12, seed=1)
    with pytest.raises(InvalidInputError, match="reach_limit 41: the executed primitives give 40"):
        _drawn(by_source, 41, 0)
    with pytest.raises(InvalidInputError, match="set reach 'world'"):
        TaskTrainConfig.from_json(TINY | {"reach_limit": 10})


def test_f_reach_learns_from_the_draw_beside_every_demonstrated_change(monkeypatch):
    from hsgplan.planning.regression import train

    # the executed primitives as stand-ins: twenty of the staged, thirty of the visited
    made = {"staged": list(range(20)), "visited": list(range(100, 130))}
    monkeypatch.setattr(train, "load_world_trials", lambda folder, worlds: folder.name)
    monkeypatch.setattr(train, "_trial_worlds", lambda *args: [])
    monkeypatch.setattr(
        train,
        "world_reach_examples",
        lambda trials, demos: made[trials] if trials else ["demo"] * 3,
    )
    reach = TINY | {"reach": "world", "world_trials": "staged", "loop_trials": "visited"}
    every = train._examples("reach", [], [], TaskTrainConfig.from_json(reach), KITCHEN, KITCHEN)
    config = TaskTrainConfig.from_json(reach | {"reach_limit": 12})
    drawn = train._examples("reach", [], [], config, KITCHEN, KITCHEN)
    assert drawn.keys() == every.keys()
    assert sum(len(drawn[k]) for k in drawn) == 12 + 3
    assert drawn["demonstrated changes"] == every["demonstrated changes"] == ["demo"] * 3


def test_networks_trained_apart_on_two_workers_are_those_trained_in_one_go(tmp_path):
    from hsgplan.cli.learn import NETWORK_ORDER
    from hsgplan.planning.regression.train import NETWORKS

    assert sorted(NETWORK_ORDER) == sorted(NETWORKS)
    config = tmp_path / "tiny.json"
    config.write_text(json.dumps(TINY | {"epochs": 1, "copies": 0}))
    args = ["train", "task", "--config", str(config), "--seeds", "2", "--out"]
    r = CliRunner().invoke(app, [*args, str(tmp_path / "apart"), "--workers", "2"])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(app, [*args, str(tmp_path / "together")])
    assert r.exit_code == 0, r.output
    for seed in (0, 1):
        for name in NETWORKS:
            apart, together = (
                (tmp_path / run / f"seed-{seed}" / name / "model.safetensors").read_bytes()
                for run in ("apart", "together")
            )
            assert apart == together, (seed, name)
        assert not list((tmp_path / "apart" / f"seed-{seed}").rglob(".lock"))  # all let go
