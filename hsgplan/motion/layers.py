"""The message-passing layer of the motion GNN."""

from __future__ import annotations

import torch
from torch import nn
from torch_geometric.nn import MessagePassing


def mlp(sizes: list[int], dropout: float = 0.0) -> nn.Sequential:
    """Linear layers with ReLU between them (none after the last), and with `dropout` a
    dropout after each ReLU (none without, so that networks trained before keep their
    layers' numbering)."""
    layers: list[nn.Module] = []
    for a, b in zip(sizes, sizes[1:], strict=False):
        layers += [nn.Linear(a, b), nn.ReLU()]
        if dropout > 0:
            layers.append(nn.Dropout(dropout))
    return nn.Sequential(*layers[: -2 if dropout > 0 else -1])


class GroundedConv(MessagePassing):
    """One round over the grounded scene graph: a two-layer network makes a message from
    each (receiver, sender, edge) triple, messages are summed, and a two-layer network
    updates the receiver from its features and the sum.

    Args:
        node_dim: features per node coming in.
        edge_dim: features per edge.
        hidden: units of every hidden layer (the paper: 256).
        out_dim: features per node going out.

    Shapes:
        x: [N, node_dim], edge_index: [2, E], edge_attr: [E, edge_dim] -> [N, out_dim]
    """

    def __init__(self, node_dim: int, edge_dim: int, hidden: int, out_dim: int) -> None:
        super().__init__(aggr="sum")
        self.message_net = mlp([2 * node_dim + edge_dim, hidden, hidden])
        self.update_net = mlp([node_dim + hidden, hidden, out_dim])

    def forward(
        self, x: torch.Tensor, edge_index: torch.Tensor, edge_attr: torch.Tensor
    ) -> torch.Tensor:
        summed = self.propagate(edge_index, x=x, edge_attr=edge_attr)
        return self.update_net(torch.cat([x, summed], dim=-1))

    def message(self, x_i: torch.Tensor, x_j: torch.Tensor, edge_attr: torch.Tensor):
        return torch.relu(self.message_net(torch.cat([x_i, x_j, edge_attr], dim=-1)))
