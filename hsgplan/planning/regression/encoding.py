"""A symbolic state and a (sub)goal as one graph, the input of the task planner's networks.

Nodes are the state's objects and fixtures; edges are every ordered pair of nodes, self loops
included, so that each possible literal has exactly one slot: `On(o, x)` and `In(o, shelf)`
on the edge o -> x, `InGrasp(o)` and `Clear(o)` on o's self loop. A goal gives each slot one
of three values, as Regression Planning Networks encode goals: don't care, true or false.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from functools import cache, cached_property, lru_cache

import numpy as np
import torch
from torch_geometric.data import Data

from hsgplan.domain.predicates import PREDICATES, Literal
from hsgplan.domain.scene import World
from hsgplan.planning.regression.features import (
    edge_dim,
    fixture_edges,
    node_features,
    valid_mask,
)
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

DONT_CARE, TRUE, FALSE = 0, 1, 2

_PRED_INDEX = {p: i for i, p in enumerate(PREDICATES)}


@cache
def _edge_index(n: int) -> torch.Tensor:
    """The complete edge index over n nodes, self loops included (shared: do not write)."""
    return torch.tensor([(i, j) for i in range(n) for j in range(n)], dtype=torch.long).t()


@dataclass(frozen=True)
class Slots:
    """Where each literal sits in the edge list of a graph over `nodes`."""

    nodes: tuple[str, ...]

    @property
    def edges(self) -> list[tuple[int, int]]:
        n = len(self.nodes)
        return [(i, j) for i in range(n) for j in range(n)]

    @cached_property
    def _index(self) -> dict[str, int]:
        return {name: i for i, name in enumerate(self.nodes)}

    def slot(self, lit: Literal) -> tuple[int, int]:
        """(edge index, predicate index) of a literal's atom."""
        src, dst = lit.args[0], lit.args[-1]
        return self._index[src] * len(self.nodes) + self._index[dst], _PRED_INDEX[lit.predicate]

    def literal(self, edge: int, pred: int) -> Literal:
        return _literal(self.nodes, edge, pred)

    def valued(self, edge: int, pred: int, value: int) -> Literal:
        """The literal a TRUE or FALSE value in a slot states (shared, cached: a planner call
        decodes many, and making a `Literal` is slow)."""
        return _valued(self.nodes, edge, pred, value)

    @staticmethod
    def of(nodes: tuple[str, ...]) -> Slots:
        """The (shared, cached) slots of a node list."""
        return _slots(nodes)

    def goal_values(self, goal: Iterable[Literal]) -> torch.Tensor:
        """[E, P] long: DONT_CARE, TRUE or FALSE for each slot."""
        values = torch.full((len(self.nodes) ** 2, len(PREDICATES)), DONT_CARE, dtype=torch.long)
        for lit in goal:
            e, p = self.slot(lit)
            values[e, p] = TRUE if lit.positive else FALSE
        return values


@cache
def _slots(nodes: tuple[str, ...]) -> Slots:
    return Slots(nodes)


@lru_cache(maxsize=65536)
def _literal(nodes: tuple[str, ...], edge: int, pred: int) -> Literal:
    src, dst = divmod(edge, len(nodes))
    p = PREDICATES[pred]
    return Literal(p, (nodes[src],) if p.arity == 1 else (nodes[src], nodes[dst]))


@lru_cache(maxsize=65536)
def _valued(nodes: tuple[str, ...], edge: int, pred: int, value: int) -> Literal:
    lit = _literal(nodes, edge, pred)
    return lit if value == TRUE else lit.negated()


def encode(
    state: SymbolicSceneGraph,
    goal: Iterable[Literal],
    query: Iterable[Literal] = (),
    features: str = "names",
) -> Data:
    """The state, a goal (literals over the state's nodes) and a query within it, as a graph,
    its nodes described by `features` (`domain.scene.FEATURES`).

    Shapes:
        x: [N, node_dim(features)] (`features.node_features`).
        edge_index: [2, N * N] every ordered pair, self loops included.
        edge_attr: [N * N, edge_dim(features)] the state's literals (multi-hot over
            `PREDICATES`), the goal's value per predicate (one-hot over don't care / true /
            false), valid slots, the query's slots; for "geometry", then the fixture column
            (`features.fixture_edges`).
        valid: [N * N, P] bool, the slots a literal can occupy.
        goal: [N * N, P] long, the goal's values.
        active: [N * N] bool, the edges messages travel on: self loops, the pairs a state,
            goal or query literal relates, and for "geometry" a shelf and its prepush region
            (else a prepush region could not learn which shelf it serves). Other pairs are read
            out but pass nothing on, so that objects nothing relates do not change what the
            network says elsewhere (scenes grow from two objects in training to twelve).
        names: list of N node names.
    """
    slots = Slots(state.nodes)
    n = len(slots.nodes)
    x, edge_index = node_features(slots.nodes, state.world, features), _edge_index(n)
    holds = torch.zeros(n * n, len(PREDICATES))
    for lit in state.literals:
        e, p = slots.slot(lit)
        holds[e, p] = 1.0
    values = slots.goal_values(goal)
    valid = valid_mask(slots.nodes, state.world).clone()
    goal_onehot = torch.nn.functional.one_hot(values, 3).float().reshape(n * n, -1)
    asked = torch.zeros(n * n, len(PREDICATES))
    for lit in query:
        e, p = slots.slot(lit)
        asked[e, p] = 1.0
    parts = [holds, goal_onehot, valid.float(), asked]
    always = edge_index[0] == edge_index[1]
    if features == "geometry":
        parts.append(fixture_edges(slots.nodes, state.world))
        always = always | (parts[-1][:, 0] > 0)
    edge_attr = torch.cat(parts, dim=1)
    active = always | (holds.sum(1) > 0) | (values != DONT_CARE).any(1) | (asked.sum(1) > 0)
    return Data(
        x=x,
        edge_index=edge_index,
        edge_attr=edge_attr,
        valid=valid,
        goal=values,
        active=active,
        names=list(slots.nodes),
    )


def with_features(data: Data, world: World, features: str) -> Data:
    """A graph `encode` made with the "names" features, described by `features` instead (the
    training examples are encoded once, by name, and trained under either)."""
    if features == "names":
        return data
    nodes = tuple(data.names)
    out = data.clone()
    out.x = node_features(nodes, world, features)
    joined = fixture_edges(nodes, world)
    out.edge_attr = torch.cat([data.edge_attr, joined], dim=1)
    out.active = data.active | (joined[:, 0] > 0)
    return out


def decode(data: Data, values: torch.Tensor) -> list[Literal]:
    """The literals a [E, P] tensor of DONT_CARE / TRUE / FALSE values states (valid slots)."""
    return decode_values(data.names, values, data.valid)


def decode_values(names, values: torch.Tensor, valid: torch.Tensor) -> list[Literal]:
    """`decode` for one graph's [E, P] values and valid mask, over the node list `names`."""
    slots = Slots(tuple(names))
    out = []
    for e, p in (values != DONT_CARE).logical_and(valid).nonzero().tolist():
        lit = slots.literal(e, p)
        out.append(lit if values[e, p] == TRUE else lit.negated())
    return out


@lru_cache(maxsize=4)
def _encode_state(state: SymbolicSceneGraph, world: World, features: str) -> Data:
    # `world` keys the cache: states of two worlds with the same literals compare equal
    return encode(state, (), features=features)


def encode_many(
    state: SymbolicSceneGraph,
    goals: list[Iterable[Literal]],
    queries: list[Iterable[Literal]] | None = None,
    features: str = "names",
) -> Data:
    """Several (goal, query) graphs over one state, batched into one disjoint graph: graph k
    owns nodes [k N, (k + 1) N) and edges [k N^2, (k + 1) N^2). Equal to batching `encode`'s
    graphs, without building each one (the planner asks many questions per decision).

    Shapes: as `encode`, with K = len(goals) graphs: x [K N, node_dim], edge_index
    [2, K N^2], edge_attr [K N^2, edge_dim], valid / goal [K N^2, P], active [K N^2].
    """
    queries = queries if queries is not None else [()] * len(goals)
    one = _encode_state(state, state.world, features)
    slots = Slots.of(state.nodes)
    k, n, e = len(goals), len(slots.nodes), len(slots.nodes) ** 2
    values = torch.zeros(k, e, len(PREDICATES), dtype=torch.long)
    asked = torch.zeros(k, e, len(PREDICATES))
    for target, lists, is_goal in ((values, goals, True), (asked, queries, False)):
        index, fill = [], []
        for i, lits in enumerate(lists):
            for lit in lits:
                index.append((i, *slots.slot(lit)))
                fill.append((TRUE if lit.positive else FALSE) if is_goal else 1)
        if index:
            target[tuple(torch.tensor(index).t())] = torch.tensor(fill, dtype=target.dtype)
    holds = one.edge_attr[:, : len(PREDICATES)].expand(k, e, -1)
    valid = one.valid.expand(k, e, -1)
    goal_onehot = torch.nn.functional.one_hot(values, 3).float().reshape(k, e, -1)
    parts = [holds, goal_onehot, valid.float(), asked]
    if features == "geometry":
        parts.append(one.edge_attr[:, _FIXTURE_COL:].expand(k, e, -1))
    edge_attr = torch.cat(parts, dim=2)
    active = one.active.expand(k, e) | (values != DONT_CARE).any(2) | (asked.sum(2) > 0)
    offsets = (torch.arange(k) * n).repeat_interleave(e)
    return Data(
        x=one.x.repeat(k, 1),
        edge_index=one.edge_index.repeat(1, k) + offsets,
        edge_attr=edge_attr.reshape(k * e, -1),
        valid=valid.reshape(k * e, -1),
        goal=values.reshape(k * e, -1),
        active=active.reshape(k * e),
        names=list(slots.nodes),
    )


# --- the planner's batches: only the edges a network computes, built with numpy ----------------
#
# `encode_many` builds every edge of every graph, and the network then drops all but the active
# and read-out ones; at planning time (many calls, a few small graphs each) building the rest was
# most of a call's cost. `encode_computed` builds the kept edges alone, with the very values and
# in the very order the network would have kept, so its outputs are the same numbers.

_GOAL_COL = len(PREDICATES)  # edge_attr columns: holds, goal one-hot (3 per predicate), valid,
_VALID_COL = 4 * len(PREDICATES)  # query
_QUERY_COL = 5 * len(PREDICATES)
_FIXTURE_COL = 6 * len(PREDICATES)  # "geometry" only


@dataclass(frozen=True)
class _Template:
    """What every graph over one node list shares, as numpy arrays."""

    x: np.ndarray  # [N, node_dim] float32
    attr: np.ndarray  # [E, edge_dim] float32: no literal holds, don't care everywhere, no query
    self_loop: np.ndarray  # [E] bool
    edge_index: np.ndarray  # [2, E] int64


@cache
def _template(nodes: tuple[str, ...], world: World, features: str) -> _Template:
    n, e = len(nodes), len(nodes) ** 2
    attr = np.zeros((e, edge_dim(features)), dtype=np.float32)
    attr[:, _GOAL_COL:_VALID_COL:3] = 1.0  # DONT_CARE's one-hot
    attr[:, _VALID_COL:_QUERY_COL] = valid_mask(nodes, world).numpy()
    if features == "geometry":
        attr[:, _FIXTURE_COL:] = fixture_edges(nodes, world).numpy()
    edge_index = _edge_index(n).numpy()
    x = node_features(nodes, world, features).numpy()
    return _Template(x, attr, edge_index[0] == edge_index[1], edge_index)


@cache
def _touching(nodes: tuple[str, ...]) -> np.ndarray:
    """[N, E] bool: the edges from or to node i."""
    src, dst = _edge_index(len(nodes)).numpy()
    nodes_i = np.arange(len(nodes))[:, None]
    return (src[None] == nodes_i) | (dst[None] == nodes_i)


@lru_cache(maxsize=256)
def _batch(
    nodes: tuple[str, ...], world: World, features: str, k: int
) -> tuple[torch.Tensor, np.ndarray, torch.Tensor]:
    """[K N, node_dim] node features, [2, K E] edge index and [K N] graph of each node, of K
    graphs (read only, shared)."""
    t = _template(nodes, world, features)
    offsets = np.repeat(np.arange(k) * len(nodes), len(nodes) ** 2)
    batch = torch.arange(k).repeat_interleave(len(nodes))
    return torch.from_numpy(np.tile(t.x, (k, 1))), np.tile(t.edge_index, k) + offsets, batch


@lru_cache(maxsize=4)
def _state_edges(
    state: SymbolicSceneGraph, world: World, features: str
) -> tuple[np.ndarray, np.ndarray]:
    """[E, edge_dim] features of the state with no goal and no query, and [E] active edges
    (`world` keys the cache: states of two worlds with the same literals compare equal)."""
    t = _template(state.nodes, world, features)
    slots = Slots.of(state.nodes)
    attr = t.attr.copy()
    for lit in state.literals:
        attr[slots.slot(lit)] = 1.0
    return attr, t.self_loop | attr[:, :_GOAL_COL].any(1) | attr[:, _FIXTURE_COL:].any(1)


@lru_cache(maxsize=4096)
def _goal_slots(nodes: tuple[str, ...], goal: frozenset[Literal]) -> np.ndarray:
    """[L, 3] (edge, predicate, TRUE or FALSE) of a goal's literals, the last one per slot."""
    slots = Slots.of(nodes)
    values = {slots.slot(lit): TRUE if lit.positive else FALSE for lit in goal}
    return np.array([(e, p, v) for (e, p), v in values.items()], dtype=np.int64).reshape(-1, 3)


@dataclass(frozen=True)
class Computed:
    """K (goal, query) graphs over one state, as the network computes them: only the edges that
    pass messages (active) or are read out, in batch order (graph k's edge e is k E + e).

    Shapes: x [K N, node_dim]; edge_index [2, M]; edge_attr [M, edge_dim]; weight [M] (1 on
    active edges, 0 on read-out-only ones); graph, edge [M] (which graph, which of its E edges);
    row [K E] (the row of graph k's edge e, -1 where it is not computed); batch [K N] (the
    graph of each node).
    """

    x: torch.Tensor
    edge_index: torch.Tensor
    edge_attr: torch.Tensor
    weight: torch.Tensor
    graph: np.ndarray
    edge: np.ndarray
    row: np.ndarray
    batch: torch.Tensor

    @property
    def valid(self) -> np.ndarray:
        """[M, P] bool: the slots a literal can occupy."""
        return self.edge_attr.numpy()[:, _VALID_COL:_QUERY_COL] > 0

    @property
    def inputs(self) -> tuple[torch.Tensor, ...]:
        """The arguments of `EdgeClassifier.computed`."""
        return self.x, self.edge_index, self.edge_attr, self.weight, self.batch


def touching(nodes: tuple[str, ...], args: list[tuple[str, ...]]) -> np.ndarray:
    """[K, E] bool: the edges of graph k that start or end at one of the nodes args[k], a
    literal's arguments (one or two names)."""
    near, index = _touching(nodes), Slots.of(nodes)._index
    first, last = [index[a[0]] for a in args], [index[a[-1]] for a in args]
    return near[first] | near[last]


def encode_computed(
    state: SymbolicSceneGraph,
    goals: list[frozenset[Literal]],
    queries: list[Literal | None],
    readout: np.ndarray | None = None,
    features: str = "names",
) -> Computed:
    """`encode_many(state, goals, [[q] for q in queries], features)` with the `readout` edges
    ([K, E] bool) read out, cut to what the network computes (see `EdgeClassifier.forward`)."""
    nodes = state.nodes
    slots = Slots.of(nodes)
    base, base_active = _state_edges(state, state.world, features)
    k, e = len(goals), len(nodes) ** 2
    x, edge_index, batch = _batch(nodes, state.world, features, k)
    goal = [_goal_slots(nodes, g) for g in goals]
    ge, gp, gv = np.concatenate(goal).T
    ge = ge + np.repeat(np.arange(0, k * e, e), [len(g) for g in goal])  # k E + e
    asked = [
        (i * e + edge, p)
        for i, q in enumerate(queries)
        if q is not None
        for edge, p in [slots.slot(q)]
    ]
    qe, qp = np.array(asked, dtype=np.int64).reshape(-1, 2).T
    active = np.tile(base_active, k)
    active[ge] = True
    active[qe] = True
    kept = np.flatnonzero(active if readout is None else active | readout.reshape(-1))
    row = np.full(k * e, -1, dtype=np.int64)
    row[kept] = np.arange(len(kept))
    graph, edge = np.divmod(kept, e)
    attr = base[edge]
    at = row[ge]
    attr[at, _GOAL_COL + 3 * gp] = 0.0
    attr[at, _GOAL_COL + 3 * gp + gv] = 1.0
    attr[row[qe], _QUERY_COL + qp] = 1.0
    return Computed(
        x=x,
        # np.take, not edge_index[:, kept], whose rows numpy lays out strided: the network
        # would copy its index rows at every index_select
        edge_index=torch.from_numpy(np.take(edge_index, kept, axis=1)),
        edge_attr=torch.from_numpy(attr),
        weight=torch.from_numpy(active[kept].astype(np.float32)),
        graph=graph,
        edge=edge,
        row=row,
        batch=batch,
    )
