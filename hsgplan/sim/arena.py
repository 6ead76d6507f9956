"""The static part of the scene: the table, its region markers and the shelves, as its world
describes them."""

from __future__ import annotations

from dataclasses import dataclass

from pybullet_utils.bullet_client import BulletClient

from hsgplan.domain.scene import OPEN_SPACE, Rect, Shelf, World, shelf_boards

TABLE_THICKNESS = 0.05
TABLE_COLOR = (0.82, 0.74, 0.62, 1.0)
SHELF_COLOR = (0.45, 0.30, 0.18, 1.0)
OPEN_SPACE_COLOR = (0.70, 0.78, 0.70, 1.0)
PREPUSH_COLOR = (0.72, 0.70, 0.86, 1.0)  # every other region: a shelf's prepush region


@dataclass(frozen=True)
class Arena:
    """Body ids of the static scene. Shelves are several boxes each (walls and top board)."""

    table: int
    shelves: dict[str, tuple[int, ...]]
    markers: tuple[int, ...]

    @property
    def obstacles(self) -> tuple[int, ...]:
        return (self.table,) + tuple(b for parts in self.shelves.values() for b in parts)


def _box(bc: BulletClient, center, half, color, friction: float | None, yaw: float = 0.0) -> int:
    """A fixed box turned by `yaw` about z; `friction` None: paint, with no collision shape."""
    col = bc.createCollisionShape(bc.GEOM_BOX, halfExtents=half) if friction is not None else -1
    vis = bc.createVisualShape(bc.GEOM_BOX, halfExtents=half, rgbaColor=color)
    turned = {"baseOrientation": bc.getQuaternionFromEuler((0.0, 0.0, yaw))} if yaw else {}
    body = bc.createMultiBody(0, col, vis, basePosition=center, **turned)
    if friction is not None:
        bc.changeDynamics(body, -1, lateralFriction=friction)
    return body


def _slab(bc: BulletClient, r: Rect, z0: float, z1: float, color, friction: float | None) -> int:
    center = (*r.center, (z0 + z1) / 2)
    half = (r.width_x / 2, r.width_y / 2, (z1 - z0) / 2)
    return _box(bc, center, half, color, friction, r.yaw)


def build_shelf(bc: BulletClient, shelf: Shelf, friction: float) -> tuple[int, ...]:
    """The shelf's boards (`scene.shelf_boards`) as fixed boxes."""
    return tuple(
        _slab(bc, b.rect, b.z_min, b.z_max, SHELF_COLOR, friction) for b in shelf_boards(shelf)
    )


def build_arena(bc: BulletClient, world: World) -> Arena:
    friction = world.fixture_friction
    table = _slab(bc, world.table, -TABLE_THICKNESS, 0.0, TABLE_COLOR, friction)
    # Region markers are paint on the table: visible in pictures, absent from physics.
    markers = tuple(
        _slab(bc, r, 0.0, 0.0005, OPEN_SPACE_COLOR if name == OPEN_SPACE else PREPUSH_COLOR, None)
        for name, r in world.region_list
    )
    shelves = {s.name: build_shelf(bc, s, friction) for s in world.shelf_list}
    return Arena(table, shelves, markers)
