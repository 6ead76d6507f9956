"""Grounding f_g on hand-built scenes."""

from dataclasses import replace

import pytest
import torch

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import clear, inside, on
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.scene_graph.grounding import (
    EDGE_DIM,
    GEOMETRY_NODE_DIM,
    GEOMETRY_SUBGOAL_DIM,
    KINDS,
    NODE_DIM,
    REGION_CLASSES,
    ROLES,
    SCALE,
    SUBGOAL_DIM,
    TARGET_ROLES,
    TYPES,
    ground,
)

K = len(TYPES) + len(REGION_CLASSES)  # where the geometric features start


def _top(shelf: str, dx: float = 0.0, dy: float = 0.0, height: float = 0.058):
    r = KITCHEN.surface_rect(shelf)
    cx, cy = r.center
    return Pose.from_xyz_yaw(cx + dx, cy + dy, r.z + height / 2)


def _place_scene() -> GeometricSceneGraph:
    return GeometricSceneGraph.from_poses(
        {
            "cherries": _top("shelf_a"),  # on the target's centre
            "butter": Pose.from_xyz_yaw(0.45, 0.0, 0.012),  # on the open space
            "tomato_soup": Pose.from_xyz_yaw(0.4, 0.0, 0.4),  # in the gripper
        },
        held="tomato_soup",
        world=KITCHEN,
    )


def test_place_grounding_shapes_and_attributes():
    g = ground(_place_scene(), on("tomato_soup", "shelf_a"))
    names = _place_scene().objects
    assert g.x.shape == (3, NODE_DIM) and g.u.shape == (1, SUBGOAL_DIM)
    assert g.edge_index.shape == (2, 6) and g.edge_attr.shape == (6, EDGE_DIM)
    i = {n: names.index(n) for n in names}
    # type and region one-hots
    assert g.x[i["cherries"], TYPES.index("cherries")] == 1
    assert g.x[i["cherries"], len(TYPES) + REGION_CLASSES.index("top:shelf_a")] == 1
    assert g.x[i["butter"], len(TYPES) + REGION_CLASSES.index("open_space")] == 1
    assert g.x[i["tomato_soup"], len(TYPES) + REGION_CLASSES.index("held")] == 1
    # only the held object is the mover
    assert g.mover.tolist() == [n == "tomato_soup" for n in names]
    assert g.x[:, K].tolist() == g.mover.float().tolist()
    # the object at the target's centre: zero offset (A), the middle of the surface (B)
    row = g.x[i["cherries"]]
    assert torch.allclose(row[K + 6 : K + 8], torch.zeros(2), atol=1e-5)
    assert torch.allclose(row[K + 9 : K + 11], torch.tensor([0.5, 0.5]), atol=1e-5)
    assert row[K + 11] == pytest.approx(SCALE * 0.029, abs=1e-4)
    # the subgoal names the target and the moved object's type
    assert g.u[0, KITCHEN.entity_types.index("shelf_a")] == 1
    assert g.u[0, len(KITCHEN.entity_types) + TYPES.index("tomato_soup")] == 1
    assert g.u.sum() == 2


def test_edges_carry_offsets_in_both_directions():
    g = ground(_place_scene(), on("tomato_soup", "shelf_a"))
    for e in range(g.edge_index.shape[1]):
        a, b = g.edge_index[:, e].tolist()
        back = ((g.edge_index[0] == b) & (g.edge_index[1] == a)).nonzero().item()
        assert torch.allclose(g.edge_attr[e, :3], -g.edge_attr[back, :3])
        assert g.edge_attr[e, 3] == pytest.approx(g.edge_attr[e, :2].norm().item(), abs=1e-5)


def test_push_grounding_is_relative_to_the_object_and_the_shelf():
    front = KITCHEN.shelves["shelf_a"].interior
    scene = GeometricSceneGraph.from_poses(
        {
            "cherries": Pose.from_xyz_yaw(0.30, 0.38, 0.029),  # on prepush_a
            "alphabet_soup": Pose.from_xyz_yaw(front.x_min + 0.06, 0.30, 0.042),  # inside
        },
        world=KITCHEN,
    )
    g = ground(scene, inside("cherries", "shelf_a"))
    c, a = scene.objects.index("cherries"), scene.objects.index("alphabet_soup")
    assert torch.allclose(g.x[c, K + 6 : K + 9], torch.zeros(3), atol=1e-5)
    assert g.x[a, len(TYPES) + REGION_CLASSES.index("in:shelf_a")] == 1
    assert g.x[c, len(TYPES) + REGION_CLASSES.index("prepush_a")] == 1
    mid = (front.y_min + front.y_max) / 2
    expect = torch.tensor([SCALE * (0.30 - front.x_min), SCALE * (0.38 - mid)])
    assert torch.allclose(g.x[c, K + 9 : K + 11], expect, atol=1e-4)


def test_subgoals_without_motion_parameters_are_refused():
    with pytest.raises(InvalidInputError, match="On\\(o, surface\\)"):
        ground(_place_scene(), clear("butter"))
    with pytest.raises(InvalidInputError, match="not in the scene"):
        ground(_place_scene(), on("popcorn", "shelf_a"))
    with pytest.raises(InvalidInputError):
        ground(_place_scene(), on("tomato_soup", "butter"))  # stacking: geometry, not bins


def _renamed(sg: GeometricSceneGraph, names: dict[str, str]) -> GeometricSceneGraph:
    """The same poses in a world whose object types are renamed."""
    types = tuple(replace(t, name=names.get(t.name, t.name)) for t in sg.world.type_list)
    world = replace(sg.world, type_list=types)
    poses = {names.get(n, n): sg.pose(n) for n in sg.objects}
    held = names.get(sg.held, sg.held) if sg.held else None
    return GeometricSceneGraph.from_poses(poses, held=held, world=world)


def test_geometry_grounding_reads_what_the_scene_says_not_names():
    sg = _place_scene()
    g = ground(sg, on("tomato_soup", "shelf_a"), "geometry")
    assert g.x.shape == (3, GEOMETRY_NODE_DIM) and g.u.shape == (1, GEOMETRY_SUBGOAL_DIM)
    i = {n: sg.objects.index(n) for n in sg.objects}
    kinds, roles = len(KINDS), len(ROLES)
    # a can on the target's top; a box on a region; a can in the hand
    assert g.x[i["cherries"], :kinds].tolist() == [1, 0]
    assert g.x[i["cherries"], kinds + ROLES.index("top")] == 1
    assert g.x[i["cherries"], kinds + roles] == 1  # the target's own surface
    assert g.x[i["butter"], :kinds].tolist() == [0, 1]
    assert g.x[i["butter"], kinds + ROLES.index("region")] == 1
    assert g.x[i["butter"], kinds + roles] == 0
    assert g.x[i["tomato_soup"], kinds + ROLES.index("held")] == 1
    # the rest is the names' features, from the mover flag on
    names = ground(sg, on("tomato_soup", "shelf_a"))
    assert torch.equal(g.x[:, kinds + roles + 2 :], names.x[:, K:])
    # the subgoal: a shelf top, its sides and height, a can of the soup's size
    top = KITCHEN.surface_rect("shelf_a")
    u = g.u[0].tolist()
    assert u[: len(TARGET_ROLES)] == [0, 0, 1, 0]
    assert u[4:7] == pytest.approx([SCALE * top.width_x, SCALE * top.width_y, SCALE * top.z])
    assert u[7:9] == [1, 0] and u[9:] == pytest.approx([0.70, 0.70, 0.83])
    # renamed object types: the same features, where the names' one-hots cannot be made
    renamed = _renamed(sg, {"cherries": "plums", "tomato_soup": "bisque"})
    again = ground(renamed, on("bisque", "shelf_a"), "geometry")
    assert torch.equal(again.x, g.x) and torch.equal(again.u, g.u)
    with pytest.raises(ValueError):
        ground(renamed, on("bisque", "shelf_a"))


def test_geometry_grounding_of_a_push_marks_the_target_interior_and_its_prepush_region():
    prepush = KITCHEN.surface_rect("prepush_a")
    sg = GeometricSceneGraph.from_poses(
        {
            "cherries": Pose.from_xyz_yaw(*prepush.center, 0.029),
            "alphabet_soup": Pose.from_xyz_yaw(
                KITCHEN.shelves["shelf_a"].interior.center[0],
                KITCHEN.shelves["shelf_a"].interior.center[1],
                0.042,
            ),
            "butter": _top("shelf_a", height=0.024),
        },
        world=KITCHEN,
    )
    g = ground(sg, inside("cherries", "shelf_a"), "geometry")
    i = {n: sg.objects.index(n) for n in sg.objects}
    at = len(KINDS)
    row = {n: g.x[i[n], at : at + len(ROLES) + 2].tolist() for n in i}
    assert row["cherries"] == [0, 1, 0, 0, 0, 0, 1]  # on the target shelf's prepush region
    assert row["alphabet_soup"] == [0, 0, 0, 1, 0, 1, 0]  # inside the target shelf
    assert row["butter"] == [0, 0, 1, 0, 0, 0, 0]  # on its top: not where the push goes
    assert g.u[0, : len(TARGET_ROLES)].tolist() == [0, 0, 0, 1]
    with pytest.raises(InvalidInputError, match="features 'colour'"):
        ground(sg, inside("cherries", "shelf_a"), "colour")
