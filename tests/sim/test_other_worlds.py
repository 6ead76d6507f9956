"""The simulated world is built from the World it is given: its shelves stand where the scene
says, its objects have the scene's sizes, f_m reads the scene's surfaces, and an episode runs in
its goal's world."""

import json
import shutil
from dataclasses import replace

import numpy as np
import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.layouts import random_layout
from hsgplan.domain.predicates import on
from hsgplan.domain.scene_write import scene_data, to_toml
from hsgplan.paths import KITCHEN_SCENE
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.scene_graph.symbol_mapping import DEFAULT_TOLERANCES, map_symbols
from hsgplan.sim.env import KitchenStorageEnv, ResetOptions
from hsgplan.sim.scene import Scene

LAYOUT = random_layout(KITCHEN, 3, 0)
NEW = random_layout(KITCHEN, 3, 0, new_objects=True)


def test_a_scene_stands_its_shelves_and_sizes_its_objects_as_its_world_says():
    box = next(t for t in NEW.type_list if t.kind == "box")
    with Scene((box.name,), world=NEW, visuals=False) as scene:
        for shelf in NEW.shelf_list:
            top_board = scene.arena.shelves[shelf.name][-1]
            lo, hi = scene.bc.getAABB(top_board)
            assert lo[0] == pytest.approx(shelf.top.x_min, abs=2e-3)
            assert hi[1] == pytest.approx(shelf.top.y_max, abs=2e-3)
            assert hi[2] == pytest.approx(shelf.top.z, abs=2e-3)
        scene.set_pose(box.name, Pose.from_xyz_yaw(0.5, 0.0, 0.3, 0.0))
        lo, hi = scene.bc.getAABB(scene.bodies[box.name])
        assert np.subtract(hi, lo) == pytest.approx(box.size, abs=2e-3)
        assert scene.scene_graph().world is NEW


def test_f_m_reads_the_surfaces_of_the_graphs_world():
    shelf = LAYOUT.shelves["shelf_a"]
    butter = LAYOUT.object_types["butter"]
    x, y = shelf.top.center
    pose = Pose.from_xyz_yaw(x, y, shelf.top.z + butter.height / 2, 0.0)
    laid_out = map_symbols(GeometricSceneGraph.from_poses({"butter": pose}, world=LAYOUT))
    assert laid_out.state.holds(on("butter", "shelf_a")) and not laid_out.anomalies
    kitchen_top = KITCHEN.shelves["shelf_a"].top
    # the kitchen's mapping tells the two tops apart only beyond its contact tolerance
    if (
        not kitchen_top.contains(x, y)
        or abs(kitchen_top.z - shelf.top.z) > DEFAULT_TOLERANCES.contact_z
    ):
        in_kitchen = map_symbols(GeometricSceneGraph.from_poses({"butter": pose}, world=KITCHEN))
        assert not in_kitchen.state.holds(on("butter", "shelf_a"))


def test_an_episode_runs_in_its_goals_world_and_the_spaces_are_the_worlds():
    can = next(t.name for t in NEW.type_list if t.kind == "can")
    goal = parse_goal(f"On({can}, shelf_a)", world=NEW)
    env = KitchenStorageEnv(visuals=False, world=NEW)
    try:
        obs, info = env.reset(seed=4, options=ResetOptions(goal))
        assert env.scene.world is NEW and info["observation"].symbols.state.world is NEW
        assert env.observation_space.contains(obs)
        assert obs["types"][0] == list(NEW.object_types).index(can) + 1
        with pytest.raises(ValueError, match="another world"):
            env.reset(
                seed=4, options=ResetOptions(parse_goal("On(cherries, shelf_a)", world=KITCHEN))
            )
    finally:
        env.close()


runner = CliRunner()


def test_an_agent_with_learned_parts_is_refused_a_world_of_other_names(tmp_path):
    # networks named by hand that know the kitchen's names, or an MLP (which reads names
    # alone): refused in one line before anything is written
    scene = tmp_path / "new.toml"
    scene.write_text(to_toml(scene_data(NEW)))
    evaluation = ["eval", "world", "--sizes", "2", "--goals", "1", "--workers", "1"]
    for args in (
        [
            "demo",
            "--agent",
            "learned",
            "--out",
            str(tmp_path / "d"),
            "--checkpoint",
            "checkpoints/task",
        ],
        [*evaluation, "--out", str(tmp_path / "e"), "--motion", "mlp"],
    ):
        r = runner.invoke(app, [*args, "--scene", str(scene)])
        assert r.exit_code == 2 and len(r.output.strip().splitlines()) == 1, r.output
        assert "know the kitchen's objects" in r.output
    assert not (tmp_path / "d").exists() and not (tmp_path / "e").exists()


def test_a_scene_of_other_names_runs_the_networks_that_read_kind_and_size_by_default(tmp_path):
    from hsgplan.agents.registry import default_checkpoints
    from hsgplan.paths import (
        MOTION_CHECKPOINTS,
        MOTION_GEOMETRY_CHECKPOINTS,
        TASK_CHECKPOINT,
        TASK_GEOMETRY_CHECKPOINT,
        shipped,
    )

    kitchen = default_checkpoints("regression+gnn", [KITCHEN])
    assert kitchen == (TASK_CHECKPOINT, MOTION_CHECKPOINTS, None)
    *folders, said = default_checkpoints("regression+gnn", [KITCHEN, NEW])
    assert folders == [TASK_GEOMETRY_CHECKPOINT, MOTION_GEOMETRY_CHECKPOINTS]
    assert "networks that read kind and size" in said
    mine = tmp_path / "mine"
    shutil.copytree(shipped(TASK_GEOMETRY_CHECKPOINT), mine)
    *folders, _ = default_checkpoints("regression+gnn", [NEW], checkpoint=mine)
    assert folders == [mine, MOTION_GEOMETRY_CHECKPOINTS]  # a folder named is kept
    assert default_checkpoints("regression+mlp", [NEW])[2] is None  # no geometry MLP ships
    names = default_checkpoints("regression+gnn", [NEW], checkpoint=shipped(TASK_CHECKPOINT))
    assert names[2] is None  # a names planner named by hand: left to be refused
    assert default_checkpoints("oracle", [NEW])[2] is None  # nothing learned to swap
    # only a learned part's folder: Fast Downward reads no task networks
    assert default_checkpoints("fd+gnn", [NEW])[:2] == (
        TASK_CHECKPOINT,
        MOTION_GEOMETRY_CHECKPOINTS,
    )

    scene, out = tmp_path / "new.toml", tmp_path / "e"
    scene.write_text(to_toml(scene_data(NEW)))
    args = ["eval", "world", "--sizes", "2", "--goals", "1", "--workers", "1", "--out", str(out)]
    r = runner.invoke(app, [*args, "--scene", str(scene), "--tables", "success"])
    assert r.exit_code == 0, r.output
    assert "networks that read kind and size" in r.output
    config = json.loads((out / "config.json").read_text())
    assert config["checkpoint"] == str(TASK_GEOMETRY_CHECKPOINT)


def test_every_command_that_names_no_networks_runs_a_scene_of_other_names(tmp_path):
    # the symbolic loop and the motion evaluation swap in the networks that read kind and size
    # as eval world does, and say so; the kitchen keeps the shipped ones
    from hsgplan.paths import TASK_GEOMETRY_CHECKPOINT

    scene = tmp_path / "new.toml"
    scene.write_text(to_toml(scene_data(NEW)))
    task = ["eval", "task", "--sizes", "2", "--goals", "1", "--workers", "1"]
    r = runner.invoke(app, [*task, "--scene", str(scene), "--out", str(tmp_path / "t")])
    assert r.exit_code == 0, r.output
    assert "networks that read kind and size" in r.output
    config = json.loads((tmp_path / "t" / "config.json").read_text())
    assert config["checkpoint"] == str(TASK_GEOMETRY_CHECKPOINT)
    r = runner.invoke(app, [*task, "--out", str(tmp_path / "k")])
    assert r.exit_code == 0 and "read kind and size" not in r.output, r.output
    motion = ["eval", "motion", "--trials", "1", "--primitives", "place", "--workers", "1"]
    r = runner.invoke(app, [*motion, "--scene", str(scene), "--json"])
    assert r.exit_code == 0, r.output
    assert "networks that read kind and size" in r.output


def test_the_stream_baselines_place_size_and_push_by_their_scenes_world():
    from hsgplan.agents.streams import push_shelf, stack_pose, surface_pose

    shelf = next(s for s in LAYOUT.shelf_list if s.interior is not None)
    can = LAYOUT.object_type("tomato_soup")
    assert can.size != KITCHEN.object_type("tomato_soup").size  # resized in this layout
    on_top = surface_pose("tomato_soup", shelf.name, (4, 4), LAYOUT)
    assert on_top.bottom == pytest.approx(shelf.top.z)
    assert on_top.top - on_top.bottom == pytest.approx(can.height)
    assert shelf.top.contains(on_top.x, on_top.y)
    butter = stack_pose("butter", on_top)
    assert butter is not None and butter.bottom == pytest.approx(on_top.top)
    assert butter.top - butter.bottom == pytest.approx(LAYOUT.object_type("butter").height)
    before = surface_pose("tomato_soup", shelf.prepush, (4, 4), LAYOUT)
    assert LAYOUT.regions[shelf.prepush].contains(before.x, before.y)
    assert push_shelf(before) == shelf.name


def test_f_p_is_refused_objects_it_never_saw_and_other_cameras_but_not_a_new_layout(tmp_path):
    from hsgplan.evaluation.config import EvalConfig

    new = tmp_path / "new.toml"
    new.write_text(to_toml(scene_data(NEW)))
    elsewhere = tmp_path / "cameras.toml"
    moved = replace(LAYOUT.cameras[0], eye=(1.5, 0.0, 1.0))
    elsewhere.write_text(to_toml(scene_data(replace(LAYOUT, cameras=(moved, *LAYOUT.cameras[1:])))))
    evaluation = ["eval", "world", "--agent", "oracle", "--sizes", "2", "--goals", "1"]
    for scene, why in ((new, "has not learned the look of"), (elsewhere, "its cameras")):
        for args in (
            ["demo", "--agent", "oracle", "--perception", "rgb", "--out", str(tmp_path / "d")],
            [*evaluation, "--perception", "gt,rgb", "--out", str(tmp_path / "e")],
        ):
            r = runner.invoke(app, [*args, "--scene", str(scene)])
            assert r.exit_code == 2 and len(r.output.strip().splitlines()) == 1, r.output
            assert "f_p cannot see scene" in r.output and why in r.output, r.output
    assert not (tmp_path / "d").exists() and not (tmp_path / "e").exists()
    # moved shelves and resized groceries of the looks it learned: it sees them by their sizes
    layout = tmp_path / "layout.toml"
    layout.write_text(to_toml(scene_data(LAYOUT)))
    seen = EvalConfig("oracle", (2,), 1, 0, perception="rgb", scene=str(layout))
    assert list(seen.worlds().values()) == [LAYOUT]
    kitchen = EvalConfig("oracle", (2,), 1, 0, perception="rgb", scene=str(KITCHEN_SCENE))
    assert list(kitchen.worlds().values()) == [KITCHEN]


@pytest.mark.slow
def test_the_oracle_solves_a_goal_of_new_objects_in_the_world(tmp_path):
    scene = tmp_path / "new.toml"
    scene.write_text(to_toml(scene_data(NEW)))
    out = tmp_path / "run"
    args = ["eval", "world", "--agent", "oracle", "--sizes", "2", "--goals", "1", "--workers", "1"]
    r = runner.invoke(app, [*args, "--scene", str(scene), "--out", str(out), "--json"])
    assert r.exit_code == 0, r.output
    row = json.loads((out / "oracle" / "episodes.jsonl").read_text().splitlines()[0])["result"]
    assert set(parse_goal(row["goal"], world=NEW).objects) <= set(NEW.object_types)
    assert json.loads((out / "oracle" / "config.json").read_text())["scene"] == str(scene)


def test_an_evaluation_over_a_folder_runs_each_scene_on_the_same_goal_seeds(tmp_path):
    from hsgplan.evaluation.config import EvalConfig
    from hsgplan.evaluation.protocol import episode_specs, run_config

    for k in range(2):
        (tmp_path / f"layout-{k}.toml").write_text(
            to_toml(scene_data(random_layout(KITCHEN, 8, k)))
        )
    config = EvalConfig("regression+gnn", (2, 3), 2, 0, scene=str(tmp_path))
    specs = episode_specs(config)
    assert len(specs) == 2 * 2 * 2 and len({s.key for s in specs}) == len(specs)
    by_scene = {}
    for s in specs:
        by_scene.setdefault(s.scene, []).append((s.size, s.index, s.seed))
    assert sorted(by_scene) == [str(tmp_path / "layout-0.toml"), str(tmp_path / "layout-1.toml")]
    assert by_scene[str(tmp_path / "layout-0.toml")] == by_scene[str(tmp_path / "layout-1.toml")]
    before = run_config(config)["fingerprint"]
    (tmp_path / "layout-1.toml").write_text(to_toml(scene_data(random_layout(KITCHEN, 8, 5))))
    assert run_config(config)["fingerprint"] != before  # another scene: another run
    kitchen = run_config(EvalConfig("regression+gnn", (2,), 1, 0))
    assert "scene" not in kitchen  # as runs in the kitchen were always claimed


def test_the_benchmarks_run_in_a_scene_file_and_refuse_one_their_models_cannot_read(tmp_path):
    layout, new = tmp_path / "layout.toml", tmp_path / "new.toml"
    layout.write_text(to_toml(scene_data(LAYOUT)))
    new.write_text(to_toml(scene_data(NEW)))
    args = ["bench", "symbolic", "--sizes", "2", "--goals", "1", "--markdown"]
    r = runner.invoke(app, [*args, "--scene", str(layout)])
    assert r.exit_code == 0 and f"in {layout})" in r.output, r.output
    task = ["bench", "task", "--sizes", "2", "--goals", "1"]
    r = runner.invoke(app, [*task, "--scene", str(new)])  # the networks that read kind and size
    assert r.exit_code == 0 and "read kind and size" in r.output, r.output
    for args, why in (
        ([*task, "--checkpoint", "checkpoints/task"], "know the kitchen's objects"),
        (["bench", "observe", "--scenes", "1"], "f_p cannot see scene"),
    ):
        r = runner.invoke(app, [*args, "--scene", str(new)])
        assert r.exit_code == 2 and len(r.output.strip().splitlines()) == 1, r.output
        assert why in r.output, r.output
