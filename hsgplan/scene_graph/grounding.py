"""Grounding f_g: the geometric scene graph re-expressed around the subgoal ĝ, as tensors.

For place (`On(o, surface)`) each node is described relative to the target surface, for push
(`In(o, shelf)`) relative to the pushed object and to the shelf, as the paper does. Every node
carries, in this order (`NODE_DIM` numbers):

- object type, one-hot over the kitchen's object types (6);
- current region, one-hot over `REGION_CLASSES` (8): the surface it ultimately stands on (a
  tower's base decides), inside a shelf, or in the gripper;
- whether it is the object the primitive moves (1);
- its size as it rests (3) and its yaw as (cos 2ψ, sin 2ψ) (2): boxes look the same turned
  half way round;
- reference A (3): place: position minus the target surface's centre (z above the surface);
  push: position minus the pushed object's;
- reference B (3): place: position in the target surface's own coordinates, 0..1 across its
  length and width where the place bins are (added: a bin's cell can then be read off
  directly), and height above it; push: position minus the middle of the shelf's open front.

Edges join every ordered pair of distinct objects (the geometric graph is fully connected);
each carries the other object's offset (3) and horizontal distance (1). The subgoal is one
vector `u` (`SUBGOAL_DIM`): the target entity, one-hot over the kitchen's entity types, and the
moved object's type, one-hot over its object types. Lengths are in decimetres (`SCALE`), so that
every feature is of order one.

These are the "names" features, the paper's: their one-hots are over the kitchen's names, so a
network trained on them reads only scenes of those names. The "geometry" features say what
the scene file says instead of a name, and read any scene: a node's kind (can or box, 2) for
its type; for its region, the region's role (open region, prepush region, shelf top, shelf
interior, held: 5) and whether that region is the target's own or the target shelf's prepush
region (2); the rest as above. Their subgoal vector (`GEOMETRY_SUBGOAL_DIM`) is the target's
role (4), its rectangle's two sides and height (3), and the moved object's kind (2) and size
(3). Every rectangle, size and place bin is the graph's world's.
"""

from __future__ import annotations

import math

import torch
from torch_geometric.data import Data

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.parameters import place_xy, push_carry, push_values
from hsgplan.domain.predicates import Literal, Predicate
from hsgplan.domain.scene import Kind, World, check_features
from hsgplan.domain.world import PLACE_BINS, PUSH_ANGLE_BINS, PUSH_DIST_BINS
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.names import ENTITY_NAMES, REGION_NAMES, SHELF_NAMES, TYPE_NAMES
from hsgplan.scene_graph.symbol_mapping import map_symbols
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

TYPES = TYPE_NAMES
REGION_CLASSES: tuple[str, ...] = (
    *REGION_NAMES,
    *(f"top:{s}" for s in SHELF_NAMES),
    *(f"in:{s}" for s in SHELF_NAMES),
    "held",
)
NODE_DIM = len(TYPES) + len(REGION_CLASSES) + 1 + 3 + 2 + 3 + 3
EDGE_DIM = 4
SUBGOAL_DIM = len(ENTITY_NAMES) + len(TYPES)
KINDS = tuple(Kind)
ROLES = ("region", "prepush", "top", "in", "held")
TARGET_ROLES = ROLES[:4]
GEOMETRY_NODE_DIM = len(KINDS) + len(ROLES) + 2 + 1 + 3 + 2 + 3 + 3
GEOMETRY_SUBGOAL_DIM = len(TARGET_ROLES) + 3 + len(KINDS) + 3
SCALE = 10.0  # metres to decimetres
QUERY_DIM = 5


def dims(features: str) -> tuple[int, int]:
    """(node, subgoal) feature widths of an encoding; InvalidInputError for an unknown one."""
    check_features(features)
    if features == "names":
        return NODE_DIM, SUBGOAL_DIM
    return GEOMETRY_NODE_DIM, GEOMETRY_SUBGOAL_DIM


def _role(world: World, entity: str) -> str:
    """The role of a region class's entity (a region, or a shelf's top or interior)."""
    if entity in world.regions:
        return "prepush" if any(s.prepush == entity for s in world.shelf_list) else "region"
    return "top"


def _described(world: World, region: str, target: str, place: bool) -> list[float]:
    """The geometry features of a node's region (`region` a `_region_class`)."""
    role, _, entity = region.partition(":")
    if region == "held":
        entity = ""
    elif not entity:
        role, entity = _role(world, region), region
    of_target = entity == target and (role != "in" if place else role == "in")
    prepush = world.shelves[target].prepush if target in world.shelves else None
    return [float(role == r) for r in ROLES] + [float(of_target), float(entity == prepush)]


def _region_class(state: SymbolicSceneGraph, obj: str) -> str:
    loc = state.location(obj)
    while loc.predicate is Predicate.ON and loc.args[1] in state.objects:
        loc = state.location(loc.args[1])
    if loc.predicate is Predicate.IN_GRASP:
        return "held"
    if loc.predicate is Predicate.IN:
        return f"in:{loc.args[1]}"
    surface = loc.args[1]
    return surface if surface in state.world.regions else f"top:{surface}"


def check_subgoal(subgoal: Literal, sg: GeometricSceneGraph) -> None:
    """Refuse a subgoal that no motion parameters serve, in one line."""
    obj, world = subgoal.args[0], sg.world
    if obj not in sg.objects:
        raise InvalidInputError(f"'{subgoal}' names '{obj}', which is not in the scene")
    if subgoal.predicate is Predicate.ON and subgoal.args[1] in world.surface_capacity:
        return
    if subgoal.predicate is Predicate.IN and subgoal.args[1] in world.interior_capacity:
        return
    raise InvalidInputError(
        f"'{subgoal}': motion parameters are chosen for On(o, surface) and In(o, shelf) only"
    )


def ground(sg: GeometricSceneGraph, subgoal: Literal, features: str = "names") -> Data:
    """ŝ_g for a subgoal: `Data(x [N, node_dim], edge_index [2, N(N-1)], edge_attr
    [N(N-1), EDGE_DIM], u [1, subgoal_dim], mover [N] bool)` with the widths `dims(features)`;
    nodes in `sg`'s order."""
    node_dim, subgoal_dim = dims(features)
    check_subgoal(subgoal, sg)
    obj, target = subgoal.args
    world = sg.world
    state = map_symbols(sg).state
    place = subgoal.predicate is Predicate.ON
    # Positions and yaws are read in the target's frame (it turns with its shelf), so that a
    # turned shelf reads as an unturned one.
    if place:
        rect = world.surface_rect(target)
        ref_a = ((rect.x_min + rect.x_max) / 2, (rect.y_min + rect.y_max) / 2, rect.z)
    else:
        rect = world.shelves[target].interior
        ref_a = (*rect.to_local(*sg.pose(obj).position[:2]), sg.pose(obj).position[2])
        front = (rect.x_min, (rect.y_min + rect.y_max) / 2)
    rows = []
    for node in sg.nodes:
        x, y, z = node.pose.position
        x, y = rect.to_local(x, y)
        t = node.type
        region = _region_class(state, node.name)
        if features == "names":
            feat = [0.0] * (len(TYPES) + len(REGION_CLASSES))
            feat[TYPES.index(t.name)] = 1.0
            feat[len(TYPES) + REGION_CLASSES.index(region)] = 1.0
        else:
            feat = [float(t.kind is k) for k in KINDS] + _described(world, region, target, place)
        k = len(feat)
        feat += [0.0] * (node_dim - k)
        yaw = node.pose.yaw - rect.yaw
        size = [SCALE * s for s in t.size]
        feat[k : k + 6] = [float(node.name == obj), *size, math.cos(2 * yaw), math.sin(2 * yaw)]
        feat[k + 6 : k + 9] = [
            SCALE * (x - ref_a[0]),
            SCALE * (y - ref_a[1]),
            SCALE * (z - ref_a[2]),
        ]
        if place:
            u = (x - rect.x_min) / rect.width_x
            v = (y - rect.y_min) / rect.width_y
            feat[k + 9 : k + 12] = [u, v, SCALE * (z - rect.z)]
        else:
            feat[k + 9 : k + 12] = [SCALE * (x - front[0]), SCALE * (y - front[1]), SCALE * z]
        rows.append(feat)
    n = len(sg.nodes)
    pos = torch.tensor([node.pose.position for node in sg.nodes], dtype=torch.float)
    src, dst = torch.meshgrid(torch.arange(n), torch.arange(n), indexing="ij")
    keep = src != dst
    edge_index = torch.stack([src[keep], dst[keep]])
    if rect.yaw:  # into the target's frame, as the nodes' positions
        c, s = math.cos(rect.yaw), math.sin(rect.yaw)
        turn = torch.tensor([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]], dtype=torch.float)
        pos = pos @ turn
    offset = SCALE * (pos[edge_index[1]] - pos[edge_index[0]])
    edge_attr = torch.cat([offset, offset[:, :2].norm(dim=1, keepdim=True)], dim=1)
    u = torch.tensor([_subgoal(world, obj, target, place, features)])
    assert u.shape[1] == subgoal_dim
    mover = torch.tensor([node.name == obj for node in sg.nodes])
    return Data(
        x=torch.tensor(rows, dtype=torch.float),
        edge_index=edge_index,
        edge_attr=edge_attr,
        u=u,
        mover=mover,
        query=bin_queries(sg, subgoal),
        num_nodes=n,
    )


def _subgoal(world: World, obj: str, target: str, place: bool, features: str) -> list[float]:
    moved = world.object_type(obj)
    if features == "names":
        u = [0.0] * SUBGOAL_DIM
        u[ENTITY_NAMES.index(target)] = 1.0
        u[len(ENTITY_NAMES) + TYPES.index(moved.name)] = 1.0
        return u
    role = _role(world, target) if place else "in"
    rect = world.surface_rect(target) if place else world.shelves[target].interior
    side = [SCALE * rect.width_x, SCALE * rect.width_y, SCALE * rect.z]
    kind = [float(moved.kind is k) for k in KINDS]
    return [float(role == r) for r in TARGET_ROLES] + side + kind + [SCALE * s for s in moved.size]


def bin_queries(sg: GeometricSceneGraph, subgoal: Literal) -> torch.Tensor:
    """Where each bin pair would put the moved object, in the frame of reference A (as the
    nodes' reference-A features), and the bin indices scaled to 0..1: [bins, QUERY_DIM].

    Place: the bin's centre on the target surface. Push: where the object would end, pushed
    the bin's distance (less the lead) along the bin's angle. Used by the bin-query head.
    """
    obj, target = subgoal.args
    rows = []
    if subgoal.predicate is Predicate.ON:
        rect = sg.world.surface_rect(target)  # in its frame, as the nodes' features
        cx, cy = (rect.x_min + rect.x_max) / 2, (rect.y_min + rect.y_max) / 2
        for i in range(PLACE_BINS):
            for j in range(PLACE_BINS):
                x, y = rect.to_local(*place_xy(obj, target, i, j, sg.world))
                rows.append(
                    [
                        SCALE * (x - cx),
                        SCALE * (y - cy),
                        0.0,
                        i / (PLACE_BINS - 1),
                        j / (PLACE_BINS - 1),
                    ]
                )
    else:
        for i in range(PUSH_ANGLE_BINS):
            for j in range(PUSH_DIST_BINS):
                angle, dist = push_values(i, j)
                d = SCALE * push_carry(dist)
                rows.append(
                    [
                        d * math.cos(angle),
                        d * math.sin(angle),
                        0.0,
                        i / (PUSH_ANGLE_BINS - 1),
                        j / (PUSH_DIST_BINS - 1),
                    ]
                )
    return torch.tensor(rows, dtype=torch.float)
