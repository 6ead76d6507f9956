"""Grounding f_g on hand-built scenes."""

import pytest
import torch

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.objects import ENTITY_TYPES
from hsgplan.domain.predicates import clear, inside, on
from hsgplan.domain.world import SHELVES, surface_rect
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.scene_graph.grounding import (
    EDGE_DIM,
    NODE_DIM,
    REGION_CLASSES,
    SCALE,
    SUBGOAL_DIM,
    TYPES,
    ground,
)

K = len(TYPES) + len(REGION_CLASSES)  # where the geometric features start


def _top(shelf: str, dx: float = 0.0, dy: float = 0.0, height: float = 0.058):
    r = surface_rect(shelf)
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
    assert g.u[0, ENTITY_TYPES.index("shelf_a")] == 1
    assert g.u[0, len(ENTITY_TYPES) + TYPES.index("tomato_soup")] == 1
    assert g.u.sum() == 2


def test_edges_carry_offsets_in_both_directions():
    g = ground(_place_scene(), on("tomato_soup", "shelf_a"))
    for e in range(g.edge_index.shape[1]):
        a, b = g.edge_index[:, e].tolist()
        back = ((g.edge_index[0] == b) & (g.edge_index[1] == a)).nonzero().item()
        assert torch.allclose(g.edge_attr[e, :3], -g.edge_attr[back, :3])
        assert g.edge_attr[e, 3] == pytest.approx(g.edge_attr[e, :2].norm().item(), abs=1e-5)


def test_push_grounding_is_relative_to_the_object_and_the_shelf():
    front = SHELVES["shelf_a"].interior
    scene = GeometricSceneGraph.from_poses(
        {
            "cherries": Pose.from_xyz_yaw(0.30, 0.38, 0.029),  # on prepush_a
            "alphabet_soup": Pose.from_xyz_yaw(front.x_min + 0.06, 0.30, 0.042),  # inside
        }
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
