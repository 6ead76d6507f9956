"""The geometric scene graph s_g: one node per object with its type and SE(3) pose.

The graph is fully connected (the paper's choice, so message passing sees every object); edge
attributes are relative poses, computed when the graph is turned into tensors. Where s_g comes
from (simulator ground truth today, pose estimation later) is not its concern.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from hsgplan.domain.scene import ObjectType, World
from hsgplan.scene_graph.geometry import Pose

if TYPE_CHECKING:
    from torch_geometric.data import Data


@dataclass(frozen=True)
class GeometricNode:
    """An object: its instance name, type, and the pose of its geometric centre."""

    name: str
    type: ObjectType
    pose: Pose

    @property
    def type_name(self) -> str:
        return self.type.name

    @property
    def bottom_z(self) -> float:
        """Height of the lowest point, for an object standing as it rests (not toppled)."""
        return self.pose.position[2] - self.type.height / 2

    @property
    def top_z(self) -> float:
        return self.pose.position[2] + self.type.height / 2


@dataclass(frozen=True)
class GeometricSceneGraph:
    """Object poses plus the robot's grasp state (which object, if any, is held), in a world
    (not compared: the same poses in two worlds are equal graphs)."""

    nodes: tuple[GeometricNode, ...]
    held: str | None = None
    world: World = field(kw_only=True, compare=False, hash=False, repr=False)

    @staticmethod
    def from_poses(
        poses: dict[str, Pose], held: str | None = None, *, world: World
    ) -> GeometricSceneGraph:
        names = world.sort_objects(poses)
        nodes = tuple(GeometricNode(n, world.object_type(n), poses[n]) for n in names)
        return GeometricSceneGraph(nodes, held, world=world)

    @property
    def objects(self) -> tuple[str, ...]:
        return tuple(n.name for n in self.nodes)

    def node(self, name: str) -> GeometricNode:
        for n in self.nodes:
            if n.name == name:
                return n
        raise KeyError(name)

    def pose(self, name: str) -> Pose:
        return self.node(name).pose

    def to_data(self) -> Data:
        """The graph as `torch_geometric.data.Data`, fully connected without self loops.

        Shapes:
            x: [N, T + 7] type one-hot over the world's `entity_types`, position (3),
                quaternion (4).
            edge_index: [2, N * (N - 1)] every ordered pair of distinct objects.
            edge_attr: [E, 7] pose of the target in the source's frame (position, quaternion).
            names: list of N object names.
        """
        import torch
        from torch_geometric.data import Data

        n, types = len(self.nodes), self.world.entity_types
        x = torch.zeros(n, len(types) + 7)
        for i, node in enumerate(self.nodes):
            x[i, types.index(node.type_name)] = 1.0
            x[i, len(types) :] = torch.tensor(node.pose.position + node.pose.orientation)
        pairs = [(i, j) for i in range(n) for j in range(n) if i != j]
        attrs = []
        for i, j in pairs:
            rel = self.nodes[j].pose.relative_to(self.nodes[i].pose)
            attrs.append(rel.position + rel.orientation)
        edge_index = torch.tensor(pairs, dtype=torch.long).reshape(-1, 2).t().contiguous()
        edge_attr = torch.tensor(attrs, dtype=torch.float).reshape(-1, 7)
        return Data(x=x, edge_index=edge_index, edge_attr=edge_attr, names=list(self.objects))
