"""Scene files: the kitchen's reads as the world the product was built in, a world written out
reads back equal, and every bad field is refused in one line that names it."""

import copy
import math
import tomllib

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.scene import Kind, Rect, shelf_boards
from hsgplan.domain.scene_file import read_world, world_of
from hsgplan.domain.scene_write import scene_data, to_toml
from hsgplan.paths import KITCHEN_SCENE

KITCHEN = tomllib.loads(KITCHEN_SCENE.read_text())


def test_the_kitchen_is_the_world_every_table_was_measured_in():
    w = read_world(KITCHEN_SCENE)
    assert list(w.object_types) == [
        "cherries", "alphabet_soup", "tomato_soup", "popcorn", "cream_cheese", "butter",
    ]  # fmt: skip
    assert w.object_types["popcorn"].size == (0.038, 0.085, 0.126)
    assert w.object_types["butter"].kind is Kind.BOX and w.object_types["butter"].mass == 0.15
    assert w.object_types["cherries"].color == (0.80, 0.10, 0.15, 1.0)
    assert w.table == Rect(-0.30, 1.00, -0.80, 0.80, 0.0)
    assert list(w.regions) == ["open_space", "prepush_a", "prepush_b"]
    assert w.regions["prepush_b"] == Rect(0.24, 0.37, -0.52, -0.24, 0.0)
    a = w.shelves["shelf_a"]
    assert a.outer == Rect(0.38, 0.60, 0.22, 0.54) and a.interior == Rect(0.38, 0.58, 0.24, 0.52)
    assert a.top.z == pytest.approx(0.14) and a.prepush == "prepush_a"
    assert w.surface_capacity == {
        "open_space": 12, "prepush_a": 2, "prepush_b": 2, "shelf_a": 4, "shelf_b": 4,
    }  # fmt: skip
    assert w.interior_capacity == {"shelf_a": 3, "shelf_b": 3}
    assert w.max_tower_levels == 2
    assert w.goal_surfaces == ("shelf_a", "shelf_b") and w.goal_interior == "shelf_a"
    assert len(w.cameras) == 5 and w.cameras[0].eye == (1.15, 0.0, 1.0)


def test_a_world_written_out_reads_back_equal():
    w = read_world(KITCHEN_SCENE)
    again = world_of(tomllib.loads(to_toml(scene_data(w))))
    assert again == w and hash(again) == hash(w)


def test_a_shelf_given_no_prepush_region_gets_one_in_front_of_it():
    data = copy.deepcopy(KITCHEN)
    del data["shelves"][1]["prepush"]
    w = world_of(data)
    r = w.regions["prepush_b"]
    assert r.x_max < w.shelves["shelf_b"].outer.x_min
    assert (r.y_min, r.y_max) == pytest.approx((-0.52, -0.24))


def test_a_closed_shelf_has_a_front_board_and_no_interior():
    data = copy.deepcopy(KITCHEN)
    del data["shelves"][1]["prepush"]
    data["shelves"][1]["interior"] = False
    w = world_of(data)
    closed = w.shelves["shelf_b"]
    assert closed.interior is None and closed.prepush is None
    assert "prepush_b" not in w.regions and "shelf_b" not in w.interior_capacity
    assert len(shelf_boards(closed)) == len(shelf_boards(w.shelves["shelf_a"])) + 1
    assert not w.fits_inside("cherries", "shelf_b") and w.fits_inside("cherries", "shelf_a")


def _set(path, value):
    def change(data):
        *head, last = path
        for key in head:
            data = data[key]
        if value is _DELETE:
            del data[last]
        else:
            data[last] = value

    return change


_DELETE = object()

BAD = [
    (_set(["shelves", 0, "clearance"], -0.1), "shelves[1].clearance -0.1: must be at least 0.05"),
    (_set(["shelves", 0, "x"], [0.6, 0.38]), "shelves[1].x [0.6, 0.38]: need [low, high]"),
    (_set(["objects", 2, "kind"], "jar"), "objects[3].kind 'jar': need 'can' or 'box'"),
    (_set(["objects", 0, "size"], [0.07, 0.06, 0.05]), "a can's first two sizes"),
    (_set(["objects", 3, "size"], [0.09, 0.12, 0.05]), "wider than the gripper opens"),
    (_set(["objects", 1, "colour"], [1.2, 0, 0]), "objects[2].colour[1] 1.2"),
    (_set(["objects", 1, "name"], "Soup 2"), "objects[2].name 'Soup 2'"),
    (_set(["objects", 1, "name"], "cherries"), "the name 'cherries' is given twice"),
    (_set(["objects", 0, "mass"], "heavy"), "objects[1].mass 'heavy': need a number"),
    (_set(["objects", 0, "colour"], _DELETE), "objects[1]: missing colour"),
    (_set(["objects", 0, "shape"], "round"), "objects[1]: unknown field(s) 'shape'"),
    (_set(["regions", 0, "name"], "middle"), "need one named 'open_space'"),
    (_set(["shelves", 1, "y"], [0.30, 0.60]), "shelf_a and shelf_b overlap"),
    (_set(["shelves", 0, "x"], [0.38, 1.20]), "shelf_a is not wholly on the table"),
    (_set(["shelves", 0, "interior"], "yes"), "shelves[1].interior 'yes': true or false"),
    (_set(["shelves", 0, "interior"], False), "shelves[1].prepush: a shelf with no interior"),
    (_set(["goals", "interior"], "pantry"), "goals.interior 'pantry'"),
    (_set(["goals", "shelf_tops"], []), "goals: need a shelf top or a region for goals to fill"),
    (_set(["goals", "regions"], ["prepush_a"]), "goals.regions ['prepush_a']: need a list"),
    (_set(["shelves"], []), "goals.shelf_tops ['shelf_a', 'shelf_b']: need a list of the"),
    (_set(["shelves"], [{"name": "s"}] * 600), "shelves: need between 0 and 577"),
    (_set(["cameras", 0, "width"], 0), "cameras[1] width and height [0, 240]"),
    (_set(["cameras", 0, "target"], [1.15, 0.0, 1.0]), "cameras[1]: the eye is where it looks"),
    (_set(["table"], "big"), "table: need a table of fields"),
    (_set(["name"], 7), "name 7: need a name"),
    (_set(["shelves", 0, "name"], "cherries_2"), "reads as an instance of the object type"),
]


@pytest.mark.parametrize(("change", "message"), BAD, ids=[m for _, m in BAD])
def test_a_bad_field_is_refused_in_one_line_that_names_it(tmp_path, change, message):
    data = copy.deepcopy(KITCHEN)
    change(data)
    path = tmp_path / "scene.toml"
    path.write_text(to_toml(data))
    with pytest.raises(InvalidInputError) as e:
        read_world(path)
    lines = str(e.value).splitlines()  # a renamed shelf also leaves the goals naming the old one
    assert any(message in line for line in lines)
    assert all(line.startswith(f"scene file '{path}': ") for line in lines)


def test_every_bad_field_is_named_one_line_each_not_the_first_alone(tmp_path):
    data = copy.deepcopy(KITCHEN)
    data["objects"][0]["mass"] = 9.0
    data["shelves"][1]["clearance"] = 2.0
    data["cameras"][2]["fov"] = 0.0
    path = tmp_path / "scene.toml"
    path.write_text(to_toml(data))
    with pytest.raises(InvalidInputError) as e:
        read_world(path)
    lines = [line.removeprefix(f"scene file '{path}': ") for line in str(e.value).splitlines()]
    assert [line.split(":")[0] for line in lines] == [
        "shelves[2].clearance 2.0", "objects[1].mass 9.0", "cameras[3].fov 0.0",
    ]  # fmt: skip


def test_a_file_that_is_not_toml_or_not_there_is_refused_in_one_line(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("name = [\n")
    with pytest.raises(InvalidInputError, match="is not valid TOML"):
        read_world(bad)
    with pytest.raises(InvalidInputError, match="does not exist"):
        read_world(tmp_path / "missing.toml")


_values = st.recursive(
    st.none() | st.booleans() | st.integers(-5, 5) | st.floats(-2, 2) | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner),
    max_leaves=6,
)
_places = [["name"], ["table"], ["table", "x"], ["regions", 0, "x"], ["shelves", 0, "y"],
           ["shelves", 1, "prepush"], ["shelves", 0, "wall"], ["objects", 4, "size"],
           ["objects", 5, "colour"], ["goals"], ["cameras", 2, "fov"], ["cameras", 0]]  # fmt: skip


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(place=st.sampled_from(_places), value=_values)
def test_any_value_anywhere_is_read_or_refused_a_line_a_reason(place, value):
    # one line for each thing refused (a table moved off every fixture refuses each of them)
    data = copy.deepcopy(KITCHEN)
    _set(place, value)(data)
    try:
        world_of(data)
    except InvalidInputError as e:
        lines = str(e).split("\n")
        assert all(line.startswith("scene: ") and len(line) > 7 for line in lines)
        assert len(set(lines)) == len(lines)


def test_a_scene_the_robot_cannot_work_in_is_refused_with_every_reason():
    # a shelf moved onto the robot's base, a region beyond the arm's reach, a shelf so tall that
    # nothing on its top stays within reach, a box too long for every surface (the open space
    # made small) and too tall for every shelf, whose length leaves two regions narrower than a
    # cell, and a vase that stands on the floor but would rise past the reach on a shelf's top
    data = copy.deepcopy(KITCHEN)
    data["regions"][0]["x"], data["regions"][0]["y"] = [0.26, 0.4], [-0.1, 0.1]
    data["shelves"][0]["x"], data["shelves"][0]["y"] = [-0.1, 0.12], [-0.3, 0.02]
    del data["shelves"][0]["prepush"]
    data["shelves"][1]["clearance"] = 0.36
    data["regions"].append({"name": "far_side", "x": [0.64, 0.99], "y": [-0.79, -0.40]})
    data["objects"] += [
        {"name": "crate", "kind": "box", "size": [0.07, 0.30, 0.28], "colour": [0.5, 0.5, 0.5]},
        {"name": "vase", "kind": "box", "size": [0.05, 0.06, 0.30], "colour": [0.2, 0.5, 0.5]},
    ]
    with pytest.raises(InvalidInputError) as refused:
        world_of(data, "scene file 'mine.toml'")
    lines = str(refused.value).splitlines()
    assert all(line.startswith("scene file 'mine.toml': ") for line in lines)
    said = [
        "shelf 'shelf_a' stands on the robot's base",
        "region 'prepush_a' stands on the robot's base",  # the prepush region derived before it
        "region 'open_space' holds no object: it is smaller than a cell of 11.0 x 30.6 cm",
        "region 'prepush_a' holds no object",
        "region 'prepush_b' holds no object",
        "region 'far_side': every place on it lies beyond the arm's reach (0.72 m",
        "shelf 'shelf_b': its top at 0.380 m leaves no object within reach",
        "object 'crate' (7.0 x 30.0 x 28.0 cm) fits on no surface within reach",
        "object 'vase' (0.300 m high) would rise to 0.440 m on the top of shelf 'shelf_a'",
    ]
    assert len(lines) == len(said), lines
    assert all(w in line for w, line in zip(said, lines, strict=True)), lines
    assert world_of(KITCHEN) is not None  # the kitchen itself has nothing of the kind


def test_a_scene_counts_its_surfaces_in_cells_its_largest_footprint_fits():
    # the kitchen's objects fit the measured 11 cm cells; a 13 cm box widens the cells along
    # its long side (y), and the open space (40 cm across) holds two rows of them, not three
    kitchen = world_of(KITCHEN)
    assert kitchen.cell == (0.11, 0.11)
    data = copy.deepcopy(KITCHEN)
    data["objects"][4]["size"] = [0.053, 0.13, 0.024]
    data["objects"][0]["size"] = [0.079, 0.079, 0.058]  # as wide as the gripper opens, with
    wide = world_of(data)  # the fingers' room, fits 11 cm across
    assert wide.cell == pytest.approx((0.11, 0.136))
    assert kitchen.surface_capacity["open_space"] == 4 * 3
    assert wide.surface_capacity["open_space"] == 4 * 2
    for name in wide.surfaces:  # every cell holds the longest box with its gap
        rect, cells = wide.surface_rect(name), wide.spot_cells(name)
        assert len(cells) == wide.surface_capacity[name]
        rows = len({round(y, 9) for _, y in cells})
        assert rows == 0 or rect.width_y / rows >= 0.136


def test_a_scene_holds_as_many_fixtures_as_stand_apart_on_its_table():
    # ten regions besides the open space, each a cell behind or beside the robot's base: no
    # cap but the table's (a 1.3 x 1.6 m table holds at most 577 of the least fixture)
    data = copy.deepcopy(KITCHEN)
    ys = [[a, round(a + 0.13, 2)] for a in (-0.66, -0.52, -0.38, -0.24, 0.11, 0.25, 0.39, 0.53)]
    trays = [([-0.30, -0.17], y) for y in ys] + [([0.09, 0.22], y) for y in (ys[3], ys[4])]
    data["regions"] += [{"name": f"tray{k}", "x": x, "y": y} for k, (x, y) in enumerate(trays)]
    w = world_of(data)
    assert len(w.regions) == 3 + 10 and all(w.surface_capacity[f"tray{k}"] for k in range(10))


def test_a_surface_holds_only_the_cells_the_arm_reaches():
    # shelf A drawn half beyond the reach: its top still makes four cells, but only those
    # within REACH_MAX_XY are counted, started in and placed on; the kitchen's are all reached
    from hsgplan.domain.scene import REACH_MAX_XY

    data = copy.deepcopy(KITCHEN)
    data["shelves"][0] |= {"y": [0.40, 0.72]}
    data["shelves"][0]["prepush"] |= {"y": [0.42, 0.70]}
    far = world_of(data)
    assert len(far.grid_cells("shelf_a")) == 4
    assert 1 <= far.surface_capacity["shelf_a"] < 4
    assert all(math.hypot(x, y) <= REACH_MAX_XY for x, y in far.spot_cells("shelf_a"))
    assert far.surface_capacity["shelf_b"] == 4
    kitchen = world_of(KITCHEN)
    assert all(len(kitchen.grid_cells(n)) == kitchen.surface_capacity[n] for n in kitchen.surfaces)


def test_the_robots_base_is_its_urdfs_base_link():
    import pybullet as p

    from hsgplan.domain.scene import ROBOT_BASE
    from hsgplan.sim.robot import panda_urdf

    client = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(panda_urdf(False), useFixedBase=True, physicsClientId=client)
        (x0, y0, _), (x1, y1, _) = p.getAABB(body, -1, physicsClientId=client)
    finally:
        p.disconnect(client)
    # the constant holds the box to the centimetre, never inside it
    assert ROBOT_BASE.x_min <= x0 < ROBOT_BASE.x_min + 0.01
    assert ROBOT_BASE.x_max - 0.01 < x1 <= ROBOT_BASE.x_max
    assert ROBOT_BASE.y_min <= y0 < ROBOT_BASE.y_min + 0.01
    assert ROBOT_BASE.y_max - 0.01 < y1 <= ROBOT_BASE.y_max


def test_scenes_check_says_which_object_limits_a_tower_and_what_fits_where(tmp_path):
    from typer.testing import CliRunner

    from hsgplan.cli import app

    data = copy.deepcopy(KITCHEN)
    data["objects"][3]["size"] = [0.038, 0.085, 0.15]  # a popcorn box too tall for two levels
    path = tmp_path / "tall.toml"
    path.write_text(to_toml(data))
    r = CliRunner().invoke(app, ["scenes", "check", str(path), "--markdown"])
    assert r.exit_code == 0, r.output
    assert "| shelf_a | shelf top | 0.140 | 4 | 4 | yes |" in r.output
    assert "| popcorn | 3.8 x 8.5 x 15.0 | no | — |" in r.output
    tower = " ".join(r.output.split())
    assert "a tower holds at most 1 object: 1 of the tallest, popcorn (0.150 m)" in tower
    kitchen = CliRunner().invoke(app, ["scenes", "check", str(KITCHEN_SCENE), "--markdown"])
    said = " ".join(kitchen.output.split())
    assert "at most 2 objects" in said
    assert "a cell of 11.0 x 11.0 cm (across: the least measured; along: the least" in said
    data["objects"][4]["size"] = [0.053, 0.13, 0.024]  # a longer cream cheese sets the cells
    path.write_text(to_toml(data))
    long = CliRunner().invoke(app, ["scenes", "check", str(path), "--markdown"])
    said = " ".join(long.output.split())
    assert (
        "a cell of 11.0 x 13.6 cm (across: the least measured; along: set by cream_cheese" in said
    )
