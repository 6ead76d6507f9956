"""The motion networks: the paper's GNN and the MLP baseline, both scoring every bin pair.

Both embed the grounded scene graph and the subgoal separately (`embed`-d each, 32 in the
paper), concatenate the two and score the primitive's bins with a two-layer head; every layer
has `hidden` units (256 in the paper). Logits cover the bin pairs jointly (10 x 10 for place,
21 x 21 for push), so that a choice of x never goes with an incompatible y.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import torch
from torch import nn
from torch_geometric.nn import global_max_pool

from hsgplan.domain.errors import InvalidInputError
from hsgplan.motion.layers import GroundedConv, mlp
from hsgplan.scene_graph.grounding import EDGE_DIM, NODE_DIM, SUBGOAL_DIM, TYPES

MODELS = ("gnn", "mlp")


@dataclass(frozen=True)
class MotionNetConfig:
    """What builds a motion network; saved as `config.json` beside its weights."""

    model: str
    primitive: str
    bins: tuple[int, int]
    hidden: int = 256
    embed: int = 32
    rounds: int = 2
    node_dim: int = NODE_DIM
    edge_dim: int = EDGE_DIM
    subgoal_dim: int = SUBGOAL_DIM
    slots: int = len(TYPES)  # the MLP's fixed input: one node slot per object type

    def __post_init__(self) -> None:
        if self.model not in MODELS:
            raise InvalidInputError(f"model '{self.model}': one of {', '.join(MODELS)}")
        for name in ("hidden", "embed", "rounds"):
            if not isinstance(getattr(self, name), int) or getattr(self, name) < 1:
                raise InvalidInputError(f"{name} {getattr(self, name)!r}: need a positive integer")

    def to_json(self) -> dict:
        return asdict(self)

    @staticmethod
    def from_json(d: dict) -> MotionNetConfig:
        return MotionNetConfig(**{**d, "bins": tuple(d["bins"])})


class GraphMotionNet(nn.Module):
    """The paper's model: `rounds` of message passing over ŝ_g, a read-out of the moved
    object's node and a max over all nodes, a fully connected subgoal embedding, an MLP head.

    Shapes:
        batch.x [N, node_dim], batch.edge_index [2, E], batch.edge_attr [E, edge_dim],
        batch.u [B, subgoal_dim], batch.mover [N] bool (one per graph), batch.batch [N]
        -> logits [B, bins[0] * bins[1]]
    """

    def __init__(self, config: MotionNetConfig) -> None:
        super().__init__()
        c = config
        dims = [c.node_dim] + [c.hidden] * c.rounds
        self.convs = nn.ModuleList(
            GroundedConv(a, c.edge_dim, c.hidden, b) for a, b in zip(dims, dims[1:], strict=False)
        )
        self.graph_embed = nn.Linear(2 * c.hidden, c.embed)
        self.subgoal_embed = mlp([c.subgoal_dim, c.hidden, c.embed])
        self.head = mlp([2 * c.embed, c.hidden, c.hidden, c.bins[0] * c.bins[1]])

    def forward(self, batch) -> torch.Tensor:
        h = batch.x
        for conv in self.convs:
            h = torch.relu(conv(h, batch.edge_index, batch.edge_attr))
        pooled = global_max_pool(h, batch.batch)
        graph = self.graph_embed(torch.cat([h[batch.mover], pooled], dim=-1))
        return self.head(torch.cat([graph, self.subgoal_embed(batch.u)], dim=-1))


class FlatMotionNet(nn.Module):
    """The MLP baseline: node and edge attributes flattened into one vector (a slot per
    object type and per ordered pair of types, zeros where absent), then fully connected
    layers of the same width as the GNN's.

    Shapes: as `GraphMotionNet`.
    """

    def __init__(self, config: MotionNetConfig) -> None:
        super().__init__()
        c = config
        self.slots = c.slots
        flat = c.slots * c.node_dim + c.slots * (c.slots - 1) * c.edge_dim
        self.graph_embed = mlp([flat, c.hidden, c.hidden, c.embed])
        self.subgoal_embed = mlp([c.subgoal_dim, c.hidden, c.embed])
        self.head = mlp([2 * c.embed, c.hidden, c.hidden, c.bins[0] * c.bins[1]])

    def flatten(self, batch) -> torch.Tensor:
        s = self.slots
        b = int(batch.u.shape[0])
        kind = batch.x[:, :s].argmax(dim=1)
        nodes = batch.x.new_zeros(b, s, batch.x.shape[1])
        nodes[batch.batch, kind] = batch.x
        src, dst = batch.edge_index
        ks, kd = kind[src], kind[dst]
        pair = ks * (s - 1) + kd - (kd > ks).long()
        edges = batch.edge_attr.new_zeros(b, s * (s - 1), batch.edge_attr.shape[1])
        edges[batch.batch[src], pair] = batch.edge_attr
        return torch.cat([nodes.flatten(1), edges.flatten(1)], dim=1)

    def forward(self, batch) -> torch.Tensor:
        graph = self.graph_embed(self.flatten(batch))
        return self.head(torch.cat([graph, self.subgoal_embed(batch.u)], dim=-1))


def build(config: MotionNetConfig) -> nn.Module:
    return GraphMotionNet(config) if config.model == "gnn" else FlatMotionNet(config)
