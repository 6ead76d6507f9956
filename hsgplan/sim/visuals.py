"""What a simulated body looks like and where its parts are, read from the physics client:
for recordings of an episode (`evaluation.recording`), which draw the true scene in a 3D
viewer. Reading changes nothing in the simulation."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from hsgplan.scene_graph.geometry import Pose

if TYPE_CHECKING:
    from pybullet_utils.bullet_client import BulletClient

BOX, CYLINDER, SPHERE, MESH = "box", "cylinder", "sphere", "mesh"
# PyBullet's geometry codes (pybullet.GEOM_*) by name
_KINDS = {2: SPHERE, 3: BOX, 4: CYLINDER, 5: MESH}


@dataclass(frozen=True)
class VisualPart:
    """One visual shape of a body's link.

    Attributes:
        link: the link's index (-1: the base).
        kind: box, cylinder, sphere or mesh.
        size: a box's full extents (x, y, z); a cylinder's (length, radius); a sphere's
            (radius,); a mesh's scale (x, y, z).
        mesh: a mesh's file, else None.
        local: the shape's pose in its link's frame (`link_pose`).
        rgba: its colour, each in [0, 1].
    """

    link: int
    kind: str
    size: tuple[float, ...]
    mesh: str | None
    local: Pose
    rgba: tuple[float, float, float, float]


def visual_parts(bc: BulletClient, body: int) -> tuple[VisualPart, ...]:
    """Every visual shape of `body` of a kind a viewer can draw."""
    parts = []
    for shape in bc.getVisualShapeData(body):
        _, link, geometry, size, mesh, position, orientation, rgba = shape[:8]
        if geometry not in _KINDS:
            continue  # a plane or a height field: nothing of this world's
        kind = _KINDS[geometry]
        mesh_file = mesh.decode() if kind == MESH and isinstance(mesh, bytes) else None
        extent = (size[0],) if kind == SPHERE else tuple(size[:2] if kind == CYLINDER else size)
        parts.append(
            VisualPart(
                link,
                kind,
                tuple(float(v) for v in extent),
                mesh_file,
                Pose(tuple(position), tuple(orientation)),
                tuple(float(v) for v in rgba),
            )
        )
    return tuple(parts)


def link_pose(bc: BulletClient, body: int, link: int) -> Pose:
    """The frame a link's visual shapes are placed in: the link's own (URDF) frame. PyBullet
    tracks a base by its centre of mass, which a URDF may set off its frame."""
    if link != -1:
        position, orientation = bc.getLinkState(body, link, computeForwardKinematics=True)[4:6]
        return Pose(tuple(position), tuple(orientation))
    position, orientation = bc.getBasePositionAndOrientation(body)
    inertial = bc.getDynamicsInfo(body, -1)[3:5]
    frame = Pose(tuple(position), tuple(orientation)).matrix()
    offset = Pose(tuple(inertial[0]), tuple(inertial[1])).matrix()
    return Pose.from_matrix(frame @ np.linalg.inv(offset))


def links_of(parts: tuple[VisualPart, ...]) -> tuple[int, ...]:
    """The links that have a visual shape, each once, in order."""
    return tuple(sorted({p.link for p in parts}))
