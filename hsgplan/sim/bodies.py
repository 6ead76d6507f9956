"""The grocery objects as rigid bodies: cans are cylinders, boxes are boxes."""

from __future__ import annotations

from pybullet_utils.bullet_client import BulletClient

from hsgplan.domain.scene import Kind, ObjectType
from hsgplan.scene_graph.geometry import Pose


def spawn_object(bc: BulletClient, t: ObjectType, pose: Pose) -> int:
    """Create the body of an object of type `t` at a pose (its geometric centre)."""
    if t.kind is Kind.CAN:
        radius, height = t.size[0] / 2, t.height
        col = bc.createCollisionShape(bc.GEOM_CYLINDER, radius=radius, height=height)
        vis = bc.createVisualShape(
            bc.GEOM_CYLINDER, radius=radius, length=height, rgbaColor=t.color
        )
    else:
        half = [s / 2 for s in t.size]
        col = bc.createCollisionShape(bc.GEOM_BOX, halfExtents=half)
        vis = bc.createVisualShape(bc.GEOM_BOX, halfExtents=half, rgbaColor=t.color)
    body = bc.createMultiBody(
        t.mass, col, vis, basePosition=pose.position, baseOrientation=pose.orientation
    )
    bc.changeDynamics(
        body, -1, lateralFriction=t.friction, spinningFriction=0.001, rollingFriction=0.0005
    )
    return body
