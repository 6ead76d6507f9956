"""Shelves at any yaw: a turned rectangle's frame, a scene file's `yaw`, and the bins, cells and
features that follow a turned shelf; an unturned world computes exactly as it always did."""

import copy
import math
import tomllib

import pytest
from hypothesis import given
from hypothesis import strategies as st

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.parameters import place_xy, place_yaw, push_values
from hsgplan.domain.scene import Rect
from hsgplan.domain.scene_file import read_world, world_of
from hsgplan.domain.scene_write import scene_data, to_toml
from hsgplan.domain.world import PLACE_BINS, PLACE_LONG_AXIS_YAW
from hsgplan.paths import KITCHEN_SCENE, SCENES, home

KITCHEN = tomllib.loads(KITCHEN_SCENE.read_text())
THREE = home() / SCENES / "examples" / "three-shelves.toml"


def turned(yaw_degrees: float, shelf: int = 0) -> dict:
    data = copy.deepcopy(KITCHEN)
    data["regions"][0]["y"] = [-0.20, 0.02]  # room for the region before the turned shelf
    data["shelves"][shelf]["yaw"] = yaw_degrees
    del data["shelves"][shelf]["prepush"]  # derived in front of the turned shelf
    return data


@given(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5), st.floats(-math.pi, math.pi), st.booleans())
def test_a_turned_rectangle_takes_points_to_the_world_and_back(x, y, yaw, own_pivot):
    r = Rect(0.1, 0.3, -0.2, 0.1, 0.0, yaw, (0.05, 0.02) if own_pivot else None)
    back = r.to_local(*r.to_world(x, y))
    assert back == pytest.approx((x, y), abs=1e-12)
    assert r.contains(*r.to_world(0.2, 0.0)) and not r.contains(*r.to_world(0.35, 0.0))
    for corner in r.corners():
        assert r.contains(*corner, margin=1e-9)


def test_an_unturned_rectangle_gives_back_the_very_numbers_it_is_given():
    r = Rect(0.1, 0.3, -0.2, 0.1)
    assert r.to_world(0.123456789, -0.1) == (0.123456789, -0.1)
    assert r.to_local(0.3, 0.7) == (0.3, 0.7) and r.direction(-0.0) == -0.0
    assert r.center == ((0.1 + 0.3) / 2, (-0.2 + 0.1) / 2)


def test_turned_rectangles_overlap_only_where_they_truly_do():
    square = Rect(0.0, 1.0, 0.0, 1.0)
    # a diamond beyond the square's corner: their axis-aligned boxes overlap, they do not
    diamond = Rect(1.1, 1.9, 1.1, 1.9, 0.0, math.radians(45))
    assert not square.overlaps(diamond) and not diamond.overlaps(square)
    near = Rect(0.6, 1.4, 0.6, 1.4, 0.0, math.radians(45))
    assert square.overlaps(near) and near.overlaps(square)
    assert not square.overlaps(Rect(1.0, 2.0, 0.0, 1.0))  # sharing an edge is no overlap


def test_a_turned_shelf_faces_its_yaw_and_its_prepush_region_stands_before_it():
    w = world_of(turned(90.0))
    shelf = w.shelves["shelf_a"]
    assert shelf.yaw_degrees == 90.0 and shelf.outer.yaw == pytest.approx(math.pi / 2)
    (cx, cy), (px, py) = shelf.outer.center, w.regions[shelf.prepush].center
    facing = math.atan2(py - cy, px - cx)  # from the shelf to the region in front of it
    assert facing == pytest.approx(math.radians(90 + 180) - 2 * math.pi)
    assert shelf.outer.center == pytest.approx((0.49, 0.38))  # turned about its own centre
    assert world_of(tomllib.loads(to_toml(scene_data(w)))) == w


def test_a_yaw_out_of_range_is_refused_in_one_line():
    with pytest.raises(InvalidInputError) as e:
        world_of(turned(200.0))
    assert "shelves[1].yaw 200.0: must be at most 180" in str(e.value)
    assert "\n" not in str(e.value)


def test_place_bins_and_cells_turn_with_the_shelf_top():
    w = read_world(THREE)
    for name in ("shelf_b", "shelf_c", "prepush_b"):
        rect = w.surface_rect(name)
        assert rect.yaw != 0.0
        bins = [place_xy("butter", name, i, j, w) for i in range(PLACE_BINS) for j in (0, 9)]
        assert all(rect.contains(x, y) for x, y in bins)
        assert all(rect.contains(x, y) for x, y in w.spot_cells(name))
        assert place_yaw(name, w) == pytest.approx(PLACE_LONG_AXIS_YAW + rect.yaw)
    # a push's bins run about the shelf's own inward x
    angle, _ = push_values(10, 0, w.shelves["shelf_c"].interior.yaw)
    assert angle == pytest.approx(push_values(10, 0)[0] + math.pi / 2)


def test_a_push_subgoal_reads_the_same_into_a_turned_shelf_as_into_an_unturned_one():
    # one can on the prepush region, at the same spot of the region's own frame and turned as
    # the shelf is: the features a network reads of it are those of the unturned kitchen's
    import torch

    from hsgplan.domain.predicates import inside, on
    from hsgplan.scene_graph.geometric import GeometricSceneGraph
    from hsgplan.scene_graph.geometry import Pose
    from hsgplan.scene_graph.grounding import ground

    plain, turn = world_of(turned(0.0)), world_of(turned(30.0))
    rect = turn.regions["prepush_a"]
    local = (0.31, 0.33)
    z = plain.object_type("cherries").height / 2
    graphs = [
        GeometricSceneGraph.from_poses(
            {"cherries": Pose.from_xyz_yaw(*at, z, 0.2 + yaw)}, None, world=w
        )
        for w, at, yaw in ((plain, local, 0.0), (turn, rect.to_world(*local), rect.yaw))
    ]
    for features in ("names", "geometry"):
        a, b = (ground(g, inside("cherries", "shelf_a"), features) for g in graphs)
        assert torch.allclose(a.x, b.x, atol=1e-5), (a.x, b.x)
        assert torch.allclose(a.query, b.query, atol=1e-5)
    assert on("cherries", "prepush_a")  # the literal the staged can stands under


def test_the_samplers_draw_in_the_cells_a_scene_of_long_boxes_counts():
    # a 13 cm box widens the cells along y: the stream baselines' first place bins (one per
    # cell) and the scene sampler's spots follow the world's cells, not fixed 11 cm ones
    import random

    import numpy as np

    from hsgplan.agents.streams import bin_order
    from hsgplan.scene_graph.geometry import Pose
    from hsgplan.sim.sampler import free_spot
    from hsgplan.sim.scene import Scene

    data = copy.deepcopy(KITCHEN)
    data["objects"][4]["size"] = [0.053, 0.13, 0.024]
    w = world_of(data)
    cells = w.spot_cells("open_space")
    assert len(cells) == 8 and w.cell[1] > 0.11  # 4 x 2, where 11 cm cells make 4 x 3
    first = bin_order("cherries", "open_space", np.random.default_rng(0), w)[: len(cells)]
    nearest = [min(cells, key=lambda c: math.dist(place_xy("cherries", "open_space", *b, w), c))
               for b in first]  # fmt: skip
    assert sorted(nearest) == sorted(cells)  # one first bin in each of the 8 cells
    names = ["cherries", *(f"cherries_{k}" for k in range(2, 10))]
    with Scene(names, seed=0, poses={n: Pose.from_xyz_yaw(5.0 + k, 5.0, 0.1, 0.0)
                                     for k, n in enumerate(names)}, world=w) as scene:  # fmt: skip
        placed: list[str] = []
        for name in names[:8]:
            assert free_spot(scene, name, "open_space", placed, random.Random(1)) is not None
            placed.append(name)
        # every cell taken: a ninth has no spot (11 cm cells would have held four more)
        assert free_spot(scene, names[8], "open_space", placed, random.Random(1)) is None
