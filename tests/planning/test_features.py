"""What the task planner's networks know of a node, by name or by geometry, on tiny scenes."""

from dataclasses import replace
from pathlib import Path

import pytest
import torch

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import inside, on
from hsgplan.domain.scene_file import read_world
from hsgplan.planning.regression.encoding import encode, encode_computed, with_features
from hsgplan.planning.regression.features import (
    GEOMETRY_NODE_DIM,
    edge_dim,
    fixture_edges,
    node_dim,
    node_features,
    reads,
)
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

NEW = read_world(Path(__file__).parents[2] / "scenes/new-objects/new-objects-000.toml")


def _renamed(world, names: dict[str, str]):
    """The same world, its object types renamed."""
    types = tuple(replace(t, name=names.get(t.name, t.name)) for t in world.type_list)
    return replace(world, type_list=types)


def test_geometry_describes_what_the_scene_says_not_what_it_is_called():
    renamed = _renamed(KITCHEN, {"cherries": "plums", "butter": "margarine"})
    before = node_features(("cherries", "butter", "shelf_a", "prepush_b"), KITCHEN, "geometry")
    after = node_features(("plums", "margarine", "shelf_a", "prepush_b"), renamed, "geometry")
    assert torch.equal(before, after)
    assert before.shape == (4, GEOMETRY_NODE_DIM) == (4, node_dim("geometry"))
    cherries, butter, shelf, prepush = before.tolist()
    assert cherries[:5] == [1, 0, 0, 1, 0]  # an object, a can
    assert butter[:5] == [1, 0, 0, 0, 1]  # an object, a box
    assert butter[5:8] == pytest.approx([0.53, 1.03, 0.24])  # its size in decimetres
    assert shelf[:3] == [0, 1, 0] and shelf[9] == 1.0 and shelf[10] == pytest.approx(1.2)
    assert prepush[:3] == [0, 0, 1] and prepush[8] == 1.0


def test_names_tell_look_alikes_apart_and_geometry_only_by_size():
    names = node_features(("cream_cheese", "butter"), KITCHEN, "names")
    geometry = node_features(("cream_cheese", "butter"), KITCHEN, "geometry")
    assert not torch.equal(names[0], names[1])
    assert geometry[0, :5].tolist() == geometry[1, :5].tolist()
    assert geometry[0, 6] != geometry[1, 6]  # 10.4 cm against 10.3 cm long


def test_a_shelf_and_its_prepush_region_are_joined_both_ways_and_nothing_else():
    nodes = ("cherries", "shelf_a", "shelf_b", "prepush_a", "prepush_b", "open_space")
    marked = fixture_edges(nodes, KITCHEN).view(len(nodes), len(nodes))
    pairs = {(nodes[i], nodes[j]) for i, j in marked.nonzero().tolist()}
    assert pairs == {
        ("shelf_a", "prepush_a"),
        ("prepush_a", "shelf_a"),
        ("shelf_b", "prepush_b"),
        ("prepush_b", "shelf_b"),
    }
    # and messages travel on them, though no literal relates the two
    state = SymbolicSceneGraph.initial(["cherries"], world=KITCHEN)
    assert pairs <= _active_pairs(encode(state, [], features="geometry"))
    assert not pairs & _active_pairs(encode(state, []))


def _active_pairs(data) -> set[tuple[str, str]]:
    n = len(data.names)
    return {(data.names[i // n], data.names[i % n]) for i in data.active.nonzero()[:, 0].tolist()}


def test_geometry_encodes_a_scene_of_new_names_and_names_refuse_to():
    state = SymbolicSceneGraph.initial(["peaches", "tea"], world=NEW)
    data = encode(state, [inside("peaches", "shelf_a")], features="geometry")
    assert data.x.shape[1] == node_dim("geometry")
    assert data.edge_attr.shape[1] == edge_dim("geometry") == edge_dim("names") + 1
    assert reads("geometry", NEW) and not reads("names", NEW) and reads("names", KITCHEN)
    with pytest.raises(ValueError):
        encode(state, [], features="names")
    with pytest.raises(InvalidInputError, match="features 'colour'"):
        node_dim("colour")


def test_training_examples_encoded_by_name_convert_to_geometry():
    state = SymbolicSceneGraph.from_literals(
        ["cherries", "butter"], [on("butter", "cherries"), on("cherries", "shelf_b")], world=KITCHEN
    )
    goal, query = [inside("cherries", "shelf_a")], [on("butter", "open_space")]
    converted = with_features(encode(state, goal, query), KITCHEN, "geometry")
    direct = encode(state, goal, query, features="geometry")
    for key in ("x", "edge_index", "edge_attr", "valid", "goal", "active"):
        assert torch.equal(getattr(converted, key), getattr(direct, key)), key


def test_equal_states_of_two_worlds_are_not_confused_by_the_caches():
    resized = replace(
        KITCHEN,
        type_list=tuple(replace(t, size=tuple(1.1 * s for s in t.size)) for t in KITCHEN.type_list),
    )
    one = SymbolicSceneGraph.initial(["cherries"], world=KITCHEN)
    other = SymbolicSceneGraph.initial(["cherries"], world=resized)
    assert one == other  # states do not compare their worlds
    a = encode_computed(one, [frozenset()], [None], features="geometry")
    b = encode_computed(other, [frozenset()], [None], features="geometry")
    assert not torch.equal(a.x, b.x)
