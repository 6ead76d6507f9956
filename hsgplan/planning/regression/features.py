"""What the task planner's networks know of each node and of each pair of fixtures.

Two encodings, chosen when a network is trained and saved in its configuration:

- "names" (the paper's): a node is its entity type, one-hot over the kitchen's names, and its
  kind. A network trained so reads only scenes whose names are the kitchen's.
- "geometry": a node is what the scene file says of it, not what it is called. An object is its
  kind (can or box) and size; a shelf is whether it has an interior, its clearance and how many
  objects its top and its interior hold; a region is whether it is a prepush region and how many
  objects it holds. One edge column marks a shelf and its prepush region (both directions), the
  one relation between fixtures that names carried. Such a network reads any scene.
"""

from __future__ import annotations

from functools import cache

import torch

from hsgplan.domain.predicates import PREDICATES, Predicate
from hsgplan.domain.scene import EntityKind, Kind, World, check_features
from hsgplan.scene_graph.names import ENTITY_NAMES, unnamed

KINDS = tuple(EntityKind)
OBJECT_KINDS = tuple(Kind)
SCALE = 10.0  # metres to decimetres, so that sizes are of order one
ROOM_SCALE = 10.0  # objects a surface holds, scaled to order one
# literal slots (state, goal's three values, valid, query per predicate); geometry adds one
SLOT_DIM = 6 * len(PREDICATES)
GEOMETRY_NODE_DIM = len(KINDS) + len(OBJECT_KINDS) + 3 + 1 + 2 + 2


def node_dim(features: str) -> int:
    """Width of a node's features."""
    check_features(features)
    if features == "names":
        return len(ENTITY_NAMES) + len(KINDS)
    return GEOMETRY_NODE_DIM


def edge_dim(features: str) -> int:
    """Width of an edge's features: the literal slots, and the fixture column for geometry."""
    check_features(features)
    return SLOT_DIM + (features == "geometry")


def reads(features: str, world: World) -> bool:
    """Whether a network of these features can read a scene of this world."""
    return features == "geometry" or not unnamed(world)


def _valid(world: World, pred: Predicate, src: str, dst: str) -> bool:
    """Whether a literal of this predicate can exist on the edge src -> dst."""
    if world.kind_of(src) is not EntityKind.OBJECT:
        return False
    if pred.arity == 1:
        return src == dst
    if src == dst:
        return False
    return pred is Predicate.ON or world.kind_of(dst) is EntityKind.SHELF


@cache
def valid_mask(nodes: tuple[str, ...], world: World) -> torch.Tensor:
    """[N * N, P] bool: which slots of a graph over `nodes` can hold a literal at all (shared:
    clone before writing)."""
    n = len(nodes)
    return torch.tensor(
        [
            [_valid(world, p, nodes[i], nodes[j]) for p in PREDICATES]
            for i in range(n)
            for j in range(n)
        ]
    )


def _geometry(name: str, world: World) -> list[float]:
    kind = world.kind_of(name)
    row = [0.0] * GEOMETRY_NODE_DIM
    row[KINDS.index(kind)] = 1.0
    k = len(KINDS)
    if kind is EntityKind.OBJECT:
        t = world.object_type(name)
        row[k + OBJECT_KINDS.index(t.kind)] = 1.0
        row[k + 2 : k + 5] = [SCALE * s for s in t.size]
        return row
    k += len(OBJECT_KINDS) + 3
    top = world.surface_capacity[name] / ROOM_SCALE
    if kind is EntityKind.REGION:
        prepush = any(s.prepush == name for s in world.shelves.values())
        row[k] = float(prepush)
        row[k + 3] = top
        return row
    shelf = world.shelves[name]
    row[k + 1] = float(shelf.interior is not None)
    row[k + 2] = SCALE * shelf.clearance if shelf.interior is not None else 0.0
    row[k + 3] = top
    row[k + 4] = world.interior_capacity.get(name, 0) / ROOM_SCALE
    return row


@cache
def node_features(nodes: tuple[str, ...], world: World, features: str) -> torch.Tensor:
    """[N, node_dim(features)] (shared: do not write)."""
    check_features(features)
    if features == "geometry":
        return torch.tensor([_geometry(name, world) for name in nodes])
    names = ENTITY_NAMES
    x = torch.zeros(len(nodes), node_dim(features))
    for i, name in enumerate(nodes):
        x[i, names.index(world.type_of(name))] = 1.0
        x[i, len(names) + KINDS.index(world.kind_of(name))] = 1.0
    return x


@cache
def fixture_edges(nodes: tuple[str, ...], world: World) -> torch.Tensor:
    """[N * N, 1]: 1 on the edges between a shelf and its prepush region, both ways."""
    pairs = {(s.name, s.prepush) for s in world.shelves.values() if s.prepush}
    pairs |= {(b, a) for a, b in pairs}
    return torch.tensor([[float((a, b) in pairs)] for a in nodes for b in nodes])
