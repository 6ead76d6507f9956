"""A symbolic state and a (sub)goal as one graph, the input of the task planner's networks.

Nodes are the state's objects and fixtures; edges are every ordered pair of nodes, self loops
included, so that each possible literal has exactly one slot: `On(o, x)` and `In(o, shelf)`
on the edge o -> x, `InGrasp(o)` and `Clear(o)` on o's self loop. A goal gives each slot one
of three values, as Regression Planning Networks encode goals: don't care, true or false.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import torch
from torch_geometric.data import Data

from hsgplan.domain.objects import ENTITY_TYPES, EntityKind, kind_of, type_of
from hsgplan.domain.predicates import PREDICATES, Literal, Predicate
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

DONT_CARE, TRUE, FALSE = 0, 1, 2
KINDS = tuple(EntityKind)
NODE_DIM = len(ENTITY_TYPES) + len(KINDS)
# state multi-hot, goal one-hot over {don't care, true, false} per predicate, valid slots, and
# the query: the one literal of the goal being regressed
EDGE_DIM = len(PREDICATES) + 3 * len(PREDICATES) + 2 * len(PREDICATES)


def _valid(pred: Predicate, src: str, dst: str) -> bool:
    """Whether a literal of this predicate can exist on the edge src -> dst."""
    if kind_of(src) is not EntityKind.OBJECT:
        return False
    if pred.arity == 1:
        return src == dst
    if src == dst:
        return False
    return pred is Predicate.ON or kind_of(dst) is EntityKind.SHELF


@dataclass(frozen=True)
class Slots:
    """Where each literal sits in the edge list of a graph over `nodes`."""

    nodes: tuple[str, ...]

    @property
    def edges(self) -> list[tuple[int, int]]:
        n = len(self.nodes)
        return [(i, j) for i in range(n) for j in range(n)]

    def slot(self, lit: Literal) -> tuple[int, int]:
        """(edge index, predicate index) of a literal's atom."""
        index = {name: i for i, name in enumerate(self.nodes)}
        src, dst = lit.args[0], lit.args[-1]
        return index[src] * len(self.nodes) + index[dst], PREDICATES.index(lit.predicate)

    def literal(self, edge: int, pred: int) -> Literal:
        src, dst = divmod(edge, len(self.nodes))
        p = PREDICATES[pred]
        args = (self.nodes[src],) if p.arity == 1 else (self.nodes[src], self.nodes[dst])
        return Literal(p, args)

    def valid_mask(self) -> torch.Tensor:
        """[E, P] bool: which slots can hold a literal at all."""
        return torch.tensor(
            [[_valid(p, self.nodes[i], self.nodes[j]) for p in PREDICATES] for i, j in self.edges]
        )

    def goal_values(self, goal: Iterable[Literal]) -> torch.Tensor:
        """[E, P] long: DONT_CARE, TRUE or FALSE for each slot."""
        values = torch.full((len(self.nodes) ** 2, len(PREDICATES)), DONT_CARE, dtype=torch.long)
        for lit in goal:
            e, p = self.slot(lit)
            values[e, p] = TRUE if lit.positive else FALSE
        return values


def encode(
    state: SymbolicSceneGraph, goal: Iterable[Literal], query: Iterable[Literal] = ()
) -> Data:
    """The state, a goal (literals over the state's nodes) and a query within it, as a graph.

    Shapes:
        x: [N, NODE_DIM] node type one-hot over `ENTITY_TYPES`, then kind one-hot.
        edge_index: [2, N * N] every ordered pair, self loops included.
        edge_attr: [N * N, EDGE_DIM] the state's literals (multi-hot over `PREDICATES`), the
            goal's value per predicate (one-hot over don't care / true / false), valid slots,
            the query's slots.
        valid: [N * N, P] bool, the slots a literal can occupy.
        goal: [N * N, P] long, the goal's values.
        names: list of N node names.
    """
    slots = Slots(state.nodes)
    n = len(slots.nodes)
    x = torch.zeros(n, NODE_DIM)
    for i, name in enumerate(slots.nodes):
        x[i, ENTITY_TYPES.index(type_of(name))] = 1.0
        x[i, len(ENTITY_TYPES) + KINDS.index(kind_of(name))] = 1.0
    holds = torch.zeros(n * n, len(PREDICATES))
    for lit in state.literals:
        e, p = slots.slot(lit)
        holds[e, p] = 1.0
    values = slots.goal_values(goal)
    valid = slots.valid_mask()
    goal_onehot = torch.nn.functional.one_hot(values, 3).float().reshape(n * n, -1)
    asked = torch.zeros(n * n, len(PREDICATES))
    for lit in query:
        e, p = slots.slot(lit)
        asked[e, p] = 1.0
    edge_attr = torch.cat([holds, goal_onehot, valid.float(), asked], dim=1)
    edge_index = torch.tensor(slots.edges, dtype=torch.long).t().contiguous()
    return Data(
        x=x,
        edge_index=edge_index,
        edge_attr=edge_attr,
        valid=valid,
        goal=values,
        names=list(slots.nodes),
    )


def decode(data: Data, values: torch.Tensor) -> list[Literal]:
    """The literals a [E, P] tensor of DONT_CARE / TRUE / FALSE values states (valid slots)."""
    slots = Slots(tuple(data.names))
    out = []
    for e, p in (values != DONT_CARE).logical_and(data.valid).nonzero().tolist():
        lit = slots.literal(e, p)
        out.append(lit if values[e, p] == TRUE else lit.negated())
    return out
