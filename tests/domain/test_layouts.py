"""Random layouts: the same seed gives the same scenes, each within the documented ranges and
read back by the scene file's own checks; `hsgplan scenes` writes them once."""

import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.domain import layouts
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.scene import GRIPPER_MAX_OPENING, Kind
from hsgplan.domain.scene_file import read_world

runner = CliRunner()


@pytest.mark.parametrize("new_objects", [False, True])
def test_a_layout_is_drawn_within_its_ranges_and_again_the_same(new_objects):
    for index in range(5):
        w = layouts.random_layout(KITCHEN, 3, index, new_objects)
        assert w == layouts.random_layout(KITCHEN, 3, index, new_objects)
        assert w != KITCHEN and w.cameras == KITCHEN.cameras
        for s in w.shelf_list:
            lo, hi = layouts.SHELF_NEAR
            assert lo <= s.outer.x_min <= hi and s.prepush in w.regions
            assert layouts.SHELF_DEPTH[0] <= round(s.outer.width_x, 3) <= layouts.SHELF_DEPTH[1]
            assert layouts.SHELF_CLEARANCE[0] <= s.clearance <= layouts.SHELF_CLEARANCE[1]
        kinds = [t.kind for t in w.type_list]
        assert kinds == [t.kind for t in KITCHEN.type_list]
        for t, old in zip(w.type_list, KITCHEN.type_list, strict=True):
            assert min(t.footprint) <= GRIPPER_MAX_OPENING
            if t.kind is Kind.CAN:
                assert t.size[0] == t.size[1]
            if new_objects:
                assert t.name not in KITCHEN.object_types
            else:
                assert t.name == old.name
                assert all(
                    0.8 * a - 1e-3 <= b <= 1.2 * a + 1e-3
                    for a, b in zip(old.size, t.size, strict=True)
                )


def test_a_turn_draws_each_shelfs_yaw_within_it_and_no_turn_leaves_the_layout_as_it_was():
    yaws = []
    for index in range(8):
        w = layouts.random_layout(KITCHEN, 3, index, turn=30.0)
        assert w == layouts.random_layout(KITCHEN, 3, index, turn=30.0)
        yaws += [s.yaw_degrees for s in w.shelf_list]
        assert layouts.random_layout(KITCHEN, 3, index) == layouts.random_layout(
            KITCHEN, 3, index, turn=0.0
        )
    assert all(-30.0 <= y <= 30.0 for y in yaws) and len(set(yaws)) > 8
    assert any(y < -10 for y in yaws) and any(y > 10 for y in yaws)


def test_layouts_of_other_seeds_differ():
    assert layouts.random_layout(KITCHEN, 1, 0) != layouts.random_layout(KITCHEN, 2, 0)


def test_the_command_writes_scene_files_once_and_refuses_to_overwrite_others(tmp_path):
    out = tmp_path / "layouts"
    args = ["scenes", "--layouts", "3", "--seed", "4", "--out", str(out)]
    assert runner.invoke(app, args).exit_code == 0
    files = sorted(out.iterdir())
    assert [f.name for f in files] == [f"layout-{k:03d}.toml" for k in range(3)]
    assert read_world(files[1]) == layouts.random_layout(KITCHEN, 4, 1)
    assert files[0].read_text().startswith("# hsgplan scenes --layouts 3 --seed 4\n")
    stamps = [f.stat().st_mtime_ns for f in files]
    assert runner.invoke(app, args).exit_code == 0  # a rerun repeats nothing
    assert [f.stat().st_mtime_ns for f in files] == stamps
    other = runner.invoke(app, ["scenes", "--layouts", "2", "--seed", "5", "--out", str(out)])
    assert other.exit_code == 2
    assert other.output.strip().splitlines() == [
        f"error: '{files[0]}' holds another scene; choose another --out"
    ]
    assert [f.stat().st_mtime_ns for f in files] == stamps


def test_a_bad_base_scene_or_count_is_refused_in_one_line(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "x"\n')
    r = runner.invoke(app, ["scenes", "--layouts", "1", "--out", str(tmp_path / "o"),
                            "--scene", str(bad)])  # fmt: skip
    assert r.exit_code == 2 and len(r.output.strip().splitlines()) == 1
    assert "scene file" in r.output and "missing" in r.output
    r = runner.invoke(app, ["scenes", "--layouts", "-2", "--out", str(tmp_path / "o")])
    assert r.exit_code == 2 and not (tmp_path / "o").exists()


def test_every_layout_has_room_for_the_largest_goal_the_paper_measures():
    from hsgplan.symbolic.generator import random_goals

    for index in range(10):
        w = layouts.random_layout(KITCHEN, 5, index)
        assert w.goal_top_room >= layouts.GOAL_ROOM
        assert w.max_tower_levels >= layouts.TOWER_LEVELS
        assert len(random_goals(6, 3, 0, world=w)) == 3


def test_a_scene_too_small_for_a_goal_is_refused_in_one_line():
    import copy
    import tomllib

    from hsgplan.domain.errors import InvalidInputError
    from hsgplan.domain.scene_file import world_of
    from hsgplan.paths import KITCHEN_SCENE
    from hsgplan.symbolic.generator import random_goals

    data = tomllib.loads(KITCHEN_SCENE.read_text())
    data = copy.deepcopy(data)
    data["goals"] = {"shelf_tops": ["shelf_a"], "interior": "shelf_a"}
    small = world_of(data)
    with pytest.raises(InvalidInputError, match="no room for a goal of 12 objects"):
        random_goals(12, 1, 0, world=small)


def _three_shelves():
    """The kitchen with a third shelf beyond shelf_a, on the same side of the robot (the open
    space narrowed, so that both shelves on that side stand within the arm's reach)."""
    import tomllib

    from hsgplan.domain.scene_file import world_of
    from hsgplan.domain.scene_write import scene_data, to_toml

    data = tomllib.loads(to_toml(scene_data(KITCHEN)))
    data["table"]["y"] = [-1.2, 1.2]  # room beyond shelf_a for shelves of the layouts' widths
    data["regions"][0]["y"] = [-0.07, 0.07]
    third = dict(data["shelves"][0], name="shelf_c", x=[0.30, 0.52], y=[0.56, 0.80])
    third.pop("prepush", None)
    data["shelves"].append(third)
    return data, world_of


def test_shelves_sharing_a_side_keep_their_order_outwards_and_never_overlap():
    data, world_of = _three_shelves()
    base = world_of(data)
    for index in range(5):
        w = layouts.random_layout(base, 3, index)
        a, c = w.shelves["shelf_a"].outer, w.shelves["shelf_c"].outer
        assert a.y_max < c.y_min  # shelf_c stays beyond shelf_a, as in the base scene


def test_shelves_not_beside_the_open_space_move_about_their_own_place_and_keep_names():
    # the example of three shelves (one turned 30 degrees, one 90, behind the robot's side):
    # each drawn shelf stays within SHELF_SHIFT of its place, its yaw its own; a prepush region
    # the scene names is kept under its name
    import tomllib
    from pathlib import Path

    from hsgplan.domain.scene_file import world_of

    example = Path(__file__).parents[2] / "scenes/examples/three-shelves.toml"
    data = tomllib.loads(example.read_text())
    data["shelves"][0]["prepush"] = {"name": "front_a", "x": [0.24, 0.37], "y": [-0.51, -0.25]}
    base = world_of(data)
    assert not layouts.beside_open_space(base) and layouts.beside_open_space(KITCHEN)
    for index in range(4):
        w = layouts.random_layout(base, 3, index)
        assert w != base and w.shelves["shelf_a"].prepush == "front_a" and "front_a" in w.regions
        for s in w.shelf_list:
            old = base.shelves[s.name]
            assert s.yaw_degrees == old.yaw_degrees
            for axis in ("x", "y"):
                centre = (getattr(s.outer, f"{axis}_min") + getattr(s.outer, f"{axis}_max")) / 2
                before = (getattr(old.outer, f"{axis}_min") + getattr(old.outer, f"{axis}_max")) / 2
                assert abs(centre - before) <= layouts.SHELF_SHIFT + 1e-3
            lo, hi = layouts.SHELF_SCALE
            assert lo * old.clearance - 1e-3 <= s.clearance <= hi * old.clearance + 1e-3


def test_a_scene_no_draw_can_vary_is_refused_with_what_refused_most_draws():
    import tomllib

    from hsgplan.domain.errors import InvalidInputError
    from hsgplan.domain.scene_file import world_of
    from hsgplan.domain.scene_write import scene_data, to_toml

    data = tomllib.loads(to_toml(scene_data(KITCHEN)))
    # no tower of two such boxes (resized, 16 to 24 cm) stays in reach on any shelf top
    data["objects"][3]["size"] = [0.038, 0.085, 0.20]
    with pytest.raises(InvalidInputError) as e:
        layouts.random_layout(world_of(data), 3, 0)
    said = str(e.value)
    assert "\n" not in said and said.endswith("): its towers hold fewer than 2 objects")
    assert "most often (" in said
