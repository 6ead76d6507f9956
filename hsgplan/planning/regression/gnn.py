"""Graph networks for the regression planner: per-edge predicate classifiers over scene graphs.

Scene graphs are directed, with one edge per ordered object pair and a self loop per object that
carries its unary predicates, so every predicate lives on an edge and one per-edge head predicts
all of them. The same network serves reachability (classes=2: no / yes per predicate) and
preimages (classes=3: don't care / true / false per predicate).
"""

from __future__ import annotations

import warnings
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import torch
import torch.nn.functional as F
from torch import Tensor, nn
from torch_geometric.data import Data
from torch_geometric.nn import MessagePassing

from hsgplan.checkpoint import load_trained
from hsgplan.domain.scene import FEATURES


def graph_max(x: Tensor, batch: Tensor | None) -> Tensor:
    """Each node's graph's elementwise maximum over its nodes, [N, F] -> [N, F]. `batch` [N]
    names each node's graph (None: one graph)."""
    if batch is None:
        return x.amax(0, keepdim=True).expand_as(x)
    size = int(batch.max()) + 1
    out = x.new_full((size, x.size(1)), float("-inf"))
    out = out.scatter_reduce(0, batch.unsqueeze(1).expand_as(x), x, reduce="amax")
    return out.index_select(0, batch)


def mlp(in_dim: int, hidden: int, out_dim: int) -> nn.Sequential:
    """The paper's shared module: two fully connected layers with a Leaky ReLU between them."""
    return nn.Sequential(nn.Linear(in_dim, hidden), nn.LeakyReLU(), nn.Linear(hidden, out_dim))


class RelationalLayer(MessagePassing):
    r"""One interaction-network step over a directed graph with edge features.

    For an edge i -> j the edge update is e'_ij = MLP_e([x_i, x_j, e_ij]); each node then sums
    the updated edges it receives and those it sends, x'_i = MLP_n([x_i, \sum_j e'_ji,
    \sum_j e'_ij]): an object must learn both what rests on it and what it rests on (the
    query sits on its outgoing edge). Sums rather than means because counts carry meaning (how
    many objects a shelf holds). Self loops are ordinary edges and are neither added nor
    removed. An optional weight per edge scales what it passes on (0 silences it, while its
    own update is still computed and read out). Where an input and output width match, the
    update is residual.

    With `pool`, each node also sees the elementwise maximum of all node states in its graph.
    Messages travel only along related pairs, so without it an object cannot know that another
    one, related to nothing, is in the hand (and a pick would then fail); a maximum, unlike a
    sum or a mean, does not change when more objects like those already there are added.

    Args:
        node_dim: width of the input node features.
        edge_dim: width of the input edge features.
        hidden: width of the hidden layers and of both outputs.
        pool: whether nodes see the graph's max-pooled node states.

    Shapes:
        x: [N, node_dim]; edge_index: [2, E] (row 0 source, row 1 target); edge_attr:
        [E, edge_dim]; edge_weight: [E] or None; batch: [N] or None (one graph) ->
        (x_new [N, hidden], edge_new [E, hidden]).
    """

    def __init__(self, node_dim: int, edge_dim: int, hidden: int, pool: bool = False) -> None:
        super().__init__(aggr="add")
        self.node_dim_in = node_dim  # `node_dim` is taken: MessagePassing's propagation axis
        self.edge_dim = edge_dim
        self.hidden = hidden
        self.pool = pool
        self.edge_mlp = mlp(2 * node_dim + edge_dim, hidden, hidden)
        self.node_mlp = mlp(node_dim * (2 if pool else 1) + 2 * hidden, hidden, hidden)

    def forward(
        self,
        x: Tensor,
        edge_index: Tensor,
        edge_attr: Tensor,
        edge_weight: Tensor | None = None,
        batch: Tensor | None = None,
    ) -> tuple[Tensor, Tensor]:
        edge_new = self.edge_updater(edge_index, x=x, edge_attr=edge_attr)
        sent = edge_new if edge_weight is None else edge_new * edge_weight.unsqueeze(-1)
        # One propagation for both directions: each edge also runs backwards, carrying its
        # update in the second half of the channels, so a node sums [incoming, outgoing].
        zero = torch.zeros_like(sent)
        both = torch.cat([torch.cat([sent, zero], 1), torch.cat([zero, sent], 1)])
        sums = self.propagate(
            torch.cat([edge_index, edge_index.flip(0)], 1),
            edge_attr=both,
            size=(x.size(0), x.size(0)),
        )
        parts = [x, sums, graph_max(x, batch)] if self.pool else [x, sums]
        x_new = self.node_mlp(torch.cat(parts, dim=-1))
        if self.node_dim_in == self.hidden:
            x_new = x_new + x
        if self.edge_dim == self.hidden:
            edge_new = edge_new + edge_attr
        return x_new, edge_new

    def edge_update(self, x_i: Tensor, x_j: Tensor, edge_attr: Tensor) -> Tensor:
        # PyG names the source x_j and the target x_i; the paper's order is [source, target].
        return self.edge_mlp(torch.cat([x_j, x_i, edge_attr], dim=-1))

    def message(self, edge_attr: Tensor) -> Tensor:
        return edge_attr

    def __repr__(self) -> str:
        return (
            f"{type(self).__name__}(node_dim={self.node_dim_in}, edge_dim={self.edge_dim}, "
            f"hidden={self.hidden}, pool={self.pool})"
        )


@dataclass(frozen=True)
class EdgeClassifierConfig:
    """Sizes of an `EdgeClassifier`; stored next to trained weights as JSON."""

    node_dim: int
    edge_dim: int
    predicates: int = 4
    classes: int = 3
    hidden: int = 256
    rounds: int = 3
    pool: bool = False  # max-pooled graph context in every layer (see `RelationalLayer`)
    features: str = "names"  # what a node is (`domain.scene.FEATURES`), as the graphs are encoded

    def __post_init__(self) -> None:
        for name in ("node_dim", "edge_dim", "predicates", "hidden"):
            if not isinstance(getattr(self, name), int) or getattr(self, name) < 1:
                raise ValueError(f"{name} must be a positive integer, got {getattr(self, name)!r}")
        if not isinstance(self.classes, int) or self.classes < 2:
            raise ValueError(f"classes must be an integer >= 2, got {self.classes!r}")
        if not isinstance(self.rounds, int) or self.rounds < 0:
            raise ValueError(f"rounds must be a non-negative integer, got {self.rounds!r}")
        if not isinstance(self.pool, bool):
            raise ValueError(f"pool must be true or false, got {self.pool!r}")
        if self.features not in FEATURES:
            raise ValueError(f"features must be one of {FEATURES}, got {self.features!r}")

    def to_json(self) -> dict:
        return asdict(self)

    @staticmethod
    def from_json(d: dict) -> EdgeClassifierConfig:
        known = {f.name for f in fields(EdgeClassifierConfig)}
        unknown = sorted(set(d) - known)
        if unknown:
            # A typo in a saved config would otherwise silently fall back to a default size.
            raise ValueError(f"unknown EdgeClassifierConfig keys: {', '.join(unknown)}")
        try:
            return EdgeClassifierConfig(**d)
        except TypeError as e:
            raise ValueError(f"bad EdgeClassifierConfig: {e}") from e


class EdgeClassifier(nn.Module):
    """Per-edge, per-predicate classification of a graph after rounds of message passing.

    Node and edge features are encoded to `hidden`, passed through `rounds` relational layers
    (separate weights per round), and each edge is classified from [x_src, x_dst, e]. If the
    graph has an `active` edge mask, only active edges pass messages; every edge is classified.
    An inactive edge's state depends on nothing but its own features and its two nodes, so
    with a `readout` mask as well only active and read-out edges are computed (the planner
    asks about a few slots of many graphs); the others get all-zero logits.

    Args:
        config: the sizes, see `EdgeClassifierConfig`.

    Shapes:
        data.x: [N, node_dim]; data.edge_index: [2, E]; data.edge_attr: [E, edge_dim];
        optional data.active: [E] bool; optional data.readout: [E] bool -> logits
        [E, predicates, classes]. A `Batch` works the same, edges in batch order.
    """

    def __init__(self, config: EdgeClassifierConfig) -> None:
        super().__init__()
        self.config = config
        h = config.hidden
        self.node_encoder = mlp(config.node_dim, h, h)
        self.edge_encoder = mlp(config.edge_dim, h, h)
        self.layers = nn.ModuleList(
            RelationalLayer(h, h, h, config.pool) for _ in range(config.rounds)
        )
        self.head = mlp(3 * h, h, config.predicates * config.classes)
        # the computation on plain tensors, over these same modules; kept in a list so that it
        # is not registered twice (see `script`)
        self._core: list[nn.Module] = [_Core(self)]

    def script(self) -> EdgeClassifier:
        """Switch to inference with TorchScript: the same outputs (the weights are frozen in),
        measured about 2.5 times faster on small graphs, where Python's per-operation cost
        dominates. Training needs the eager module; load a fresh one for it.

        `optimize_for_inference` freezes and also stores each weight pre-transposed (a
        matmul and a bias add instead of a transpose per linear layer per call): 20% off a
        planner call. Its outputs agree with the frozen module's to rounding (the test holds
        them within 1e-6; it may fuse operations in another order, and MKL multiplies matrices
        of fewer than five rows another way)."""
        self.eval()
        scripted = torch.jit.script(_InferenceCore(self).eval())
        with warnings.catch_warnings():
            # torch 2.13 points to torch.compile instead, which costs seconds to compile per
            # graph shape, and the planner's shapes change at every call
            warnings.simplefilter("ignore", DeprecationWarning)
            self._core = [torch.jit.optimize_for_inference(scripted)]
        return self

    def forward(self, data: Data) -> Tensor:
        edge_index, edge_attr = data.edge_index, data.edge_attr
        active = data.active if "active" in data else None
        keep = None
        if active is not None and "readout" in data:
            keep = (active | data.readout).nonzero().squeeze(1)
            edge_index, edge_attr, active = edge_index[:, keep], edge_attr[keep], active[keep]
        weight = active.float() if active is not None else None
        batch = data.batch if "batch" in data else None
        logits = self._core[0](data.x.float(), edge_index, edge_attr.float(), weight, batch)
        logits = logits.view(-1, self.config.predicates, self.config.classes)
        if keep is None:
            return logits
        full = logits.new_zeros(data.edge_index.shape[1], *logits.shape[1:])
        return full.index_copy(0, keep, logits)

    def computed(
        self, x: Tensor, edge_index: Tensor, edge_attr: Tensor, weight: Tensor, batch: Tensor
    ) -> Tensor:
        """`forward` on edges already cut to the computed ones (`encoding.encode_computed`):
        [M, predicates, classes] logits, one row per given edge. The planner's path, which
        skips building and cutting a `Data` per call."""
        logits = self._core[0](x, edge_index, edge_attr, weight, batch)
        return logits.view(-1, self.config.predicates, self.config.classes)


class _Core(nn.Module):
    """An `EdgeClassifier`'s computation on plain tensors (so TorchScript can compile it),
    sharing its modules."""

    def __init__(self, net: EdgeClassifier) -> None:
        super().__init__()
        self.node_encoder = net.node_encoder
        self.edge_encoder = net.edge_encoder
        self.layers = net.layers
        self.head = net.head

    def forward(
        self,
        x: Tensor,
        edge_index: Tensor,
        edge_attr: Tensor,
        edge_weight: Tensor | None,
        batch: Tensor | None,
    ) -> Tensor:
        x = self.node_encoder(x)
        e = self.edge_encoder(edge_attr)
        for layer in self.layers:
            x, e = layer(x, edge_index, e, edge_weight, batch)
        return self.head(torch.cat([x[edge_index[0]], x[edge_index[1]], e], dim=-1))


class _InferenceCore(nn.Module):
    """`_Core` without PyG's propagate, for `EdgeClassifier.script`: TorchScript runs PyG's
    argument checks and a doubled edge list at every layer, which cost a third of a planner
    call. The same operations on the same operands, and the sums over the edges in the same
    order (`index_add_` adds rows one edge after another, as PyG's `scatter_add_` does, and
    measured faster), so the same numbers: a test holds it bit for bit to the PyG version."""

    def __init__(self, net: EdgeClassifier) -> None:
        super().__init__()
        self.node_encoder = net.node_encoder
        self.edge_encoder = net.edge_encoder
        self.edge_mlps = nn.ModuleList(layer.edge_mlp for layer in net.layers)
        self.node_mlps = nn.ModuleList(layer.node_mlp for layer in net.layers)
        self.head = net.head
        self.pool = net.config.pool

    def forward(
        self,
        x: Tensor,
        edge_index: Tensor,
        edge_attr: Tensor,
        edge_weight: Tensor | None,
        batch: Tensor | None,
    ) -> Tensor:
        x = self.node_encoder(x)
        e = self.edge_encoder(edge_attr)
        src, dst = edge_index[0], edge_index[1]
        n, h = x.size(0), e.size(1)
        # TorchScript's zip takes no strict=; both lists come from the same layers
        for edge_mlp, node_mlp in zip(self.edge_mlps, self.node_mlps):  # noqa: B905
            edge_new = edge_mlp(torch.cat([x.index_select(0, src), x.index_select(0, dst), e], -1))
            sent = edge_new if edge_weight is None else edge_new * edge_weight.unsqueeze(-1)
            received = sent.new_zeros(n, h).index_add_(0, dst, sent)
            sent_out = sent.new_zeros(n, h).index_add_(0, src, sent)
            # every layer is hidden -> hidden, so both updates are residual
            if self.pool:
                parts = [x, received, sent_out, graph_max(x, batch)]
            else:
                parts = [x, received, sent_out]
            x = node_mlp(torch.cat(parts, dim=-1)) + x
            e = edge_new + e
        return self.head(torch.cat([x.index_select(0, src), x.index_select(0, dst), e], dim=-1))


def masked_cross_entropy(logits: Tensor, target: Tensor, mask: Tensor) -> Tensor:
    """Mean cross entropy over the (edge, predicate) entries where `mask` is set.

    Args:
        logits: [E, P, C] raw scores.
        target: [E, P] class indices (long); values under a cleared mask are never read.
        mask: [E, P] bool.

    Returns:
        A scalar; 0 with a gradient path when nothing is masked in, so a batch without labels
        adds nothing to the loss instead of producing NaN.
    """
    picked = logits[mask]
    if picked.numel() == 0:
        return logits.sum() * 0.0
    return F.cross_entropy(picked, target[mask])


def load_network(folder: Path) -> EdgeClassifier:
    """A trained network from its folder; a missing or corrupted one raises InvalidInputError."""
    model, _ = load_trained(folder, EdgeClassifierConfig.from_json, EdgeClassifier, "network")
    return model
