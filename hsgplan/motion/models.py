"""The motion networks: the paper's GNN and the MLP baseline, both scoring every bin pair.

Both embed the grounded scene graph and the subgoal separately (`embed`-d each, 32 in the
paper), concatenate the two and score the primitive's bins with a two-layer head; every layer
has `hidden` units (256 in the paper). The paper's sentence, "we discretize each dimension
into 10 discrete bins … 21 discrete bins for each", has two readings, both kept: the head
scores the bin pairs jointly (`mlp`: 10 x 10 for place, 21 x 21 for push, so that a choice of
x never goes with an incompatible y), or one softmax per dimension (`per-dim`: 10 + 10 or
21 + 21 outputs, a pair scored by the sum of its two log-probabilities; cross-entropy over
those pairs is the sum of the two dimensions' cross-entropies).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path

import torch
from torch import nn
from torch_geometric.nn import global_max_pool
from torch_geometric.utils import to_dense_batch

from hsgplan.checkpoint import load_trained
from hsgplan.domain.errors import InvalidInputError, a
from hsgplan.motion.layers import GroundedConv, mlp
from hsgplan.scene_graph.grounding import EDGE_DIM, QUERY_DIM, TYPES, dims

MODELS = ("gnn", "mlp")
REFERENCE_A = slice(-6, -3)  # a node's reference-A position: the last six features but three
HEADS = ("mlp", "per-dim", "bins")


@dataclass(frozen=True)
class MotionNetConfig:
    """What builds a motion network; saved as `config.json` beside its weights."""

    model: str
    primitive: str
    bins: tuple[int, int]
    hidden: int = 256
    embed: int = 32
    rounds: int = 2
    node_dim: int = dims("names")[0]
    edge_dim: int = EDGE_DIM
    subgoal_dim: int = dims("names")[1]
    slots: int = len(TYPES)  # the MLP's fixed input: one node slot per object type
    # The head: "mlp", the paper's joint reading (the embeddings, concatenated, through an MLP
    # onto every bin pair), "per-dim", its per-dimension reading (the same MLP onto each
    # dimension's bins, a softmax each), or "bins" (beyond the paper): each bin is scored from
    # where it would put the object (the GNN: `BinQueryHead`; the MLP: `FlatBinHead`).
    head: str = "mlp"
    query_dim: int = QUERY_DIM
    # what a node is (`domain.scene.FEATURES`): "names", the paper's one-hots over the kitchen's
    # names, or "geometry" (kind, size, the role of its region), which reads any scene
    features: str = "names"
    # dropout after every hidden layer of the networks' MLPs (0: none, the paper's)
    dropout: float = 0.0

    def __post_init__(self) -> None:
        if self.model not in MODELS:
            raise InvalidInputError(f"model '{self.model}': one of {', '.join(MODELS)}")
        if self.head not in HEADS:
            raise InvalidInputError(f"head '{self.head}': one of {', '.join(HEADS)}")
        if (self.node_dim, self.subgoal_dim) != dims(self.features):
            raise InvalidInputError(
                f"node_dim {self.node_dim}, subgoal_dim {self.subgoal_dim}: the {self.features} "
                f"features are {dims(self.features)[0]} and {dims(self.features)[1]} wide"
            )
        if self.model == "mlp" and self.features != "names":
            raise InvalidInputError("the mlp keeps a slot per object type: features 'names' only")
        if not 0 <= self.dropout < 1:
            raise InvalidInputError(f"dropout {self.dropout!r}: from 0 up to (not) 1")
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
        batch.u [B, subgoal_dim], batch.mover [N] bool (one per graph), batch.batch [N],
        only [B] (optional: one flattened bin pair per graph)
        -> logits [B, bins[0] * bins[1]], or [B, 1] for the `only` bins
    """

    def __init__(self, config: MotionNetConfig) -> None:
        super().__init__()
        c = config
        dims = [c.node_dim] + [c.hidden] * c.rounds
        self.convs = nn.ModuleList(
            GroundedConv(a, c.edge_dim, c.hidden, b) for a, b in zip(dims, dims[1:], strict=False)
        )
        self.graph_embed = nn.Linear(2 * c.hidden, c.embed)
        self.subgoal_embed = mlp([c.subgoal_dim, c.hidden, c.embed], c.dropout)
        if c.head == "bins":
            self.head = BinQueryHead(c.hidden, c.embed, c.query_dim, c.embed, c.dropout)
        else:
            self.head = _pair_head(c)

    def forward(self, batch, only: torch.Tensor | None = None) -> torch.Tensor:
        h = batch.x
        for conv in self.convs:
            h = torch.relu(conv(h, batch.edge_index, batch.edge_attr))
        if isinstance(self.head, BinQueryHead):
            return self.head(h, batch, self.subgoal_embed(batch.u), only)
        pooled = global_max_pool(h, batch.batch)
        graph = self.graph_embed(torch.cat([h[batch.mover], pooled], dim=-1))
        return _pick(self.head(torch.cat([graph, self.subgoal_embed(batch.u)], dim=-1)), only)


class FlatMotionNet(nn.Module):
    """The MLP baseline: node and edge attributes flattened into one vector (a slot per
    object type and per ordered pair of types, zeros where absent), then fully connected
    layers of the same width as the GNN's.

    Shapes: as `GraphMotionNet` (`only` included).
    """

    def __init__(self, config: MotionNetConfig) -> None:
        super().__init__()
        c = config
        self.slots = c.slots
        flat = c.slots * c.node_dim + c.slots * (c.slots - 1) * c.edge_dim
        self.subgoal_embed = mlp([c.subgoal_dim, c.hidden, c.embed], c.dropout)
        if c.head == "bins":
            self.graph_embed = mlp([flat, c.hidden, c.hidden], c.dropout)
            self.head = FlatBinHead(c.hidden, c.embed, c.query_dim, c.slots, c.hidden, c.dropout)
        else:
            self.graph_embed = mlp([flat, c.hidden, c.hidden, c.embed], c.dropout)
            self.head = _pair_head(c)

    def _slot_positions(self, batch) -> tuple[torch.Tensor, torch.Tensor]:
        """Each slot's reference-A position [B, slots, 3] and whether its type is present
        [B, slots]."""
        kind = batch.x[:, : self.slots].argmax(dim=1)
        b = int(batch.u.shape[0])
        positions = batch.x.new_zeros(b, self.slots, 3)
        positions[batch.batch, kind] = batch.x[:, REFERENCE_A]
        present = torch.zeros(b, self.slots, dtype=torch.bool, device=batch.x.device)
        present[batch.batch, kind] = True
        return positions, present

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

    def forward(self, batch, only: torch.Tensor | None = None) -> torch.Tensor:
        graph = self.graph_embed(self.flatten(batch))
        if isinstance(self.head, FlatBinHead):
            positions, present = self._slot_positions(batch)
            subgoal = self.subgoal_embed(batch.u)
            return self.head(torch.relu(graph), positions, present, batch, subgoal, only)
        return _pick(self.head(torch.cat([graph, self.subgoal_embed(batch.u)], dim=-1)), only)


def _pair_head(c: MotionNetConfig) -> nn.Module:
    """The paper's head onto every bin pair (`mlp`) or onto each dimension's bins (`per-dim`)."""
    if c.head == "per-dim":
        return PerDimensionHead(
            mlp([2 * c.embed, c.hidden, c.hidden, c.bins[0] + c.bins[1]], c.dropout), c.bins
        )
    return mlp([2 * c.embed, c.hidden, c.hidden, c.bins[0] * c.bins[1]], c.dropout)


class PerDimensionHead(nn.Module):
    """One softmax per dimension, given as the log-probability of every bin pair [B, x * y]:
    the sum of its x bin's and its y bin's, so a pair's score ranks as the joint head's."""

    def __init__(self, net: nn.Module, bins: tuple[int, int]) -> None:
        super().__init__()
        self.net = net
        self.bins = bins

    def forward(self, h: torch.Tensor) -> torch.Tensor:
        out = self.net(h)
        x = torch.log_softmax(out[:, : self.bins[0]], dim=-1)
        y = torch.log_softmax(out[:, self.bins[0] :], dim=-1)
        return (x.unsqueeze(2) + y.unsqueeze(1)).flatten(1)


def _pick(logits: torch.Tensor, only: torch.Tensor | None) -> torch.Tensor:
    return logits if only is None else logits.gather(1, only.view(-1, 1))


class BinQueryHead(nn.Module):
    """Scores each bin pair from every node seen from that bin: a two-layer network reads a
    node's embedding with its offset from where the bin would put the moved object (its
    reference-A features minus the bin's query position), the strongest reading over the
    nodes goes with the bin's own features and the subgoal embedding through another
    two-layer network to one logit. Clearance is local and the same everywhere, so what is
    learnt on one surface carries over to the others.

    Args:
        hidden: node embedding width; embed: subgoal embedding width;
        query_dim: features per bin (`grounding.QUERY_DIM`); width: the head's hidden units.

    Shapes:
        h [N, hidden], batch.query [B * bins, query_dim], subgoal [B, embed] -> [B, bins];
        with `only` [B] (a bin per graph) -> [B, 1], scoring that bin alone (training on
        single trials need not score the other bins).
    """

    def __init__(
        self, hidden: int, embed: int, query_dim: int, width: int = 64, dropout: float = 0.0
    ) -> None:
        super().__init__()
        self.read = mlp([hidden + 3, width, width], dropout)
        self.score = mlp([width + query_dim + embed, width, 1], dropout)

    def forward(
        self, h: torch.Tensor, batch, subgoal: torch.Tensor, only: torch.Tensor | None = None
    ) -> torch.Tensor:
        nodes, mask = to_dense_batch(h, batch.batch)  # [B, N, hidden]
        pos, _ = to_dense_batch(batch.x[:, REFERENCE_A], batch.batch)
        b, n = mask.shape
        query = batch.query.view(b, -1, batch.query.shape[-1])  # [B, bins, query_dim]
        if only is not None:
            query = query[torch.arange(b), only.view(-1)].unsqueeze(1)  # [B, 1, query_dim]
        bins = query.shape[1]
        offset = pos[:, None, :, :] - query[:, :, None, :3]  # [B, bins, N, 3]
        seen = torch.relu(
            self.read(torch.cat([nodes[:, None].expand(b, bins, n, -1), offset], dim=-1))
        )
        seen = seen.masked_fill(~mask[:, None, :, None], float("-inf")).amax(dim=2)
        wide = subgoal[:, None, :].expand(b, bins, -1)
        return self.score(torch.cat([seen, query, wide], dim=-1)).squeeze(-1)


class FlatBinHead(nn.Module):
    """The MLP's bin head, given what `BinQueryHead` reads but in fixed slots: each bin is
    scored by a three-layer network from the scene's flat embedding, every slot's offset
    from where the bin would put the moved object (zeros for an absent type), the bin's own
    features and the subgoal embedding. No pooling over nodes: that is the graph's share.

    Args:
        hidden: width of the flat scene embedding; embed: subgoal embedding width;
        query_dim: features per bin; slots: object types; width: the head's hidden units.

    Shapes:
        scene [B, hidden], positions [B, slots, 3], present [B, slots] bool,
        batch.query [B * bins, query_dim], subgoal [B, embed] -> [B, bins];
        with `only` [B] -> [B, 1].
    """

    def __init__(
        self, hidden: int, embed: int, query_dim: int, slots: int, width: int, dropout: float = 0.0
    ) -> None:
        super().__init__()
        self.score = mlp([hidden + 3 * slots + query_dim + embed, width, width, 1], dropout)

    def forward(
        self,
        scene: torch.Tensor,
        positions: torch.Tensor,
        present: torch.Tensor,
        batch,
        subgoal: torch.Tensor,
        only: torch.Tensor | None = None,
    ) -> torch.Tensor:
        b = scene.shape[0]
        query = batch.query.view(b, -1, batch.query.shape[-1])  # [B, bins, query_dim]
        if only is not None:
            query = query[torch.arange(b), only.view(-1)].unsqueeze(1)
        bins = query.shape[1]
        offset = positions[:, None, :, :] - query[:, :, None, :3]  # [B, bins, slots, 3]
        offset = offset * present[:, None, :, None]
        inputs = [
            scene[:, None].expand(b, bins, -1),
            offset.flatten(2),
            query,
            subgoal[:, None].expand(b, bins, -1),
        ]
        return self.score(torch.cat(inputs, dim=-1)).squeeze(-1)


def build(config: MotionNetConfig) -> nn.Module:
    return GraphMotionNet(config) if config.model == "gnn" else FlatMotionNet(config)


def load_motion_net(
    folder: Path, primitive: str | None = None, model_name: str | None = None
) -> nn.Module:
    """A trained network from its folder; a missing or corrupted one, or one trained for
    another primitive or model than asked (a push network in a place folder), raises
    InvalidInputError."""
    model, config = load_trained(folder, MotionNetConfig.from_json, build, "motion network")
    for what, asked, found in (
        ("primitive", primitive, config.primitive),
        ("model", model_name, config.model),
    ):
        if asked is not None and asked != found:
            raise InvalidInputError(
                f"'{folder}' holds {a(found)} network where {a(asked)} one belongs ({what})"
            )
    model.config = config
    return model
