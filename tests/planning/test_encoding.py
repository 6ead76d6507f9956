"""The (state, goal) graph encoding on tiny hand-built scenes."""

import random

import pytest
import torch
from torch_geometric.data import Batch

from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import PREDICATES, Predicate, clear, in_grasp, inside, on
from hsgplan.domain.scene import FEATURES
from hsgplan.planning.regression.encoding import (
    DONT_CARE,
    FALSE,
    TRUE,
    Slots,
    decode,
    encode,
    encode_computed,
    encode_many,
    touching,
)
from hsgplan.planning.regression.features import edge_dim, node_dim
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.symbolic.generator import random_goal, random_state


def scene():
    return SymbolicSceneGraph.from_literals(
        ["cherries", "butter"], [on("butter", "cherries"), on("cherries", "shelf_a")], world=KITCHEN
    )


def test_shapes_and_one_slot_per_literal():
    s = scene()
    data = encode(
        s, parse_goal("In(cherries, shelf_a) & not Clear(butter)", world=KITCHEN).literals
    )
    n = 2 + len(KITCHEN.fixtures)
    assert data.x.shape == (n, node_dim("names"))
    assert data.edge_index.shape == (2, n * n)
    assert data.edge_attr.shape == (n * n, edge_dim("names"))
    assert data.valid.shape == data.goal.shape == (n * n, len(PREDICATES))
    slots = Slots(tuple(data.names))
    for lit in (on("butter", "cherries"), inside("cherries", "shelf_a"), clear("butter")):
        e, p = slots.slot(lit)
        assert slots.literal(e, p) == lit
        assert data.valid[e, p]
        src, dst = data.edge_index[:, e].tolist()
        assert (data.names[src], data.names[dst]) == (lit.args[0], lit.args[-1])


def test_state_goal_and_validity_features():
    s = scene()
    data = encode(
        s, parse_goal("In(cherries, shelf_a) & not Clear(butter)", world=KITCHEN).literals
    )
    slots = Slots(tuple(data.names))
    e, p = slots.slot(on("butter", "cherries"))
    assert data.edge_attr[e, p] == 1.0  # holds in the state
    e, p = slots.slot(inside("cherries", "shelf_a"))
    assert data.goal[e, p] == TRUE and data.edge_attr[e, p] == 0.0
    e, p = slots.slot(clear("butter"))
    assert data.goal[e, p] == FALSE
    assert (data.goal != DONT_CARE).sum() == 2
    # no literal about a fixture's own state, no On of an object with itself, In only to shelves
    e, p = slots.slot(on("cherries", "open_space"))
    assert data.valid[e, PREDICATES.index(Predicate.IN)] == False  # noqa: E712
    i = data.names.index("shelf_a")
    assert not data.valid[i * len(data.names) : (i + 1) * len(data.names)].any()


def test_decode_inverts_the_goal():
    goal = parse_goal(
        "On(butter, shelf_b) & InGrasp(cherries) & not On(butter, cherries)", world=KITCHEN
    )
    data = encode(scene(), goal.literals)
    assert set(decode(data, data.goal)) == set(goal.literals)


def test_duplicates_share_features_and_order_follows_nodes():
    s = SymbolicSceneGraph.initial(["cherries", "cherries_2"], world=KITCHEN)
    data = encode(s, [in_grasp("cherries_2")])
    assert torch.equal(data.x[0], data.x[1])
    slots = Slots(tuple(data.names))
    e, p = slots.slot(in_grasp("cherries_2"))
    assert e == 1 * len(data.names) + 1 and data.goal[e, p] == TRUE


@pytest.mark.parametrize("features", FEATURES)
def test_encode_many_equals_batching_single_encodings(features):
    rng = random.Random(0)
    goal = random_goal(6, rng, world=KITCHEN)
    s = random_state(goal.objects, rng, world=KITCHEN)
    lits = sorted(goal.literals)
    batched = Batch.from_data_list([encode(s, goal.literals, [lit], features) for lit in lits])
    many = encode_many(s, [goal.literals] * len(lits), [[lit] for lit in lits], features)
    for key in ("x", "edge_index", "edge_attr", "valid", "goal", "active"):
        assert torch.equal(getattr(batched, key), getattr(many, key)), key


def test_active_edges_are_self_loops_and_related_pairs():
    s = SymbolicSceneGraph.from_literals(
        ["cherries", "butter"],
        [on("butter", "cherries"), on("cherries", "open_space")],
        world=KITCHEN,
    )
    data = encode(s, [inside("cherries", "shelf_a")], [in_grasp("butter")])
    slots = Slots(tuple(data.names))
    active = {slots.literal(e, 0).args for e in data.active.nonzero().flatten().tolist()}
    pairs = {(a, b) for a, b in active if a != b}
    assert pairs == {("butter", "cherries"), ("cherries", "open_space"), ("cherries", "shelf_a")}
    assert all((n, n) in active for n in data.names)


@pytest.mark.parametrize("features", FEATURES)
def test_encode_computed_is_encode_many_cut_to_the_computed_edges(features):
    rng = random.Random(3)
    goal = random_goal(5, rng, world=KITCHEN)
    s = random_state(goal.objects, rng, world=KITCHEN)
    lits = sorted(goal.literals)
    contexts = [frozenset(goal.literals)] * (len(lits) - 1) + [frozenset([clear(lits[0].subject)])]
    readout = touching(s.nodes, [lit.args for lit in lits])
    batch = encode_computed(s, contexts, lits, readout, features)
    many = encode_many(s, contexts, [[lit] for lit in lits], features)
    kept = (many.active | torch.from_numpy(readout.reshape(-1))).nonzero().squeeze(1)
    assert torch.equal(batch.x, many.x)
    assert torch.equal(batch.edge_index, many.edge_index[:, kept])
    assert batch.edge_index.is_contiguous()  # else every index_select copies its index
    assert torch.equal(batch.edge_attr, many.edge_attr[kept])
    assert torch.equal(batch.weight, many.active[kept].float())
    assert (batch.valid == many.valid[kept].numpy()).all()
    e = many.valid.shape[0] // len(lits)
    assert (batch.graph * e + batch.edge == kept.numpy()).all()
    assert (batch.row[kept.numpy()] == range(len(kept))).all() and (batch.row >= 0).sum() == len(
        kept
    )
    # without a query or read-out edges: the active edges alone
    batch = encode_computed(
        s, [frozenset([lit]) for lit in lits], [None] * len(lits), features=features
    )
    many = encode_many(s, [[lit] for lit in lits], features=features)
    assert torch.equal(batch.edge_attr, many.edge_attr[many.active])
