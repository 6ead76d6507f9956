"""The static part of the scene: the table, its region markers and the two shelves."""

from __future__ import annotations

from dataclasses import dataclass

from pybullet_utils.bullet_client import BulletClient

from hsgplan.domain.world import (
    FIXTURE_FRICTION,
    REGIONS,
    SHELVES,
    TABLE,
    Rect,
    Shelf,
    shelf_boards,
)

TABLE_THICKNESS = 0.05
TABLE_COLOR = (0.82, 0.74, 0.62, 1.0)
SHELF_COLOR = (0.45, 0.30, 0.18, 1.0)
REGION_COLORS = {
    "open_space": (0.70, 0.78, 0.70, 1.0),
    "prepush_a": (0.72, 0.70, 0.86, 1.0),
    "prepush_b": (0.72, 0.70, 0.86, 1.0),
}


@dataclass(frozen=True)
class Arena:
    """Body ids of the static scene. Shelves are several boxes each (walls and top board)."""

    table: int
    shelves: dict[str, tuple[int, ...]]
    markers: tuple[int, ...]

    @property
    def obstacles(self) -> tuple[int, ...]:
        return (self.table,) + tuple(b for parts in self.shelves.values() for b in parts)


def _box(bc: BulletClient, center, half, color, collide: bool = True) -> int:
    col = bc.createCollisionShape(bc.GEOM_BOX, halfExtents=half) if collide else -1
    vis = bc.createVisualShape(bc.GEOM_BOX, halfExtents=half, rgbaColor=color)
    body = bc.createMultiBody(0, col, vis, basePosition=center)
    if collide:
        bc.changeDynamics(body, -1, lateralFriction=FIXTURE_FRICTION)
    return body


def _slab(bc: BulletClient, r: Rect, z0: float, z1: float, color, collide=True) -> int:
    center = ((r.x_min + r.x_max) / 2, (r.y_min + r.y_max) / 2, (z0 + z1) / 2)
    half = (r.width_x / 2, r.width_y / 2, (z1 - z0) / 2)
    return _box(bc, center, half, color, collide)


def build_shelf(bc: BulletClient, shelf: Shelf) -> tuple[int, ...]:
    """The shelf's boards (`world.shelf_boards`) as fixed boxes."""
    return tuple(_slab(bc, b.rect, b.z_min, b.z_max, SHELF_COLOR) for b in shelf_boards(shelf))


def build_arena(bc: BulletClient) -> Arena:
    table = _slab(bc, TABLE, -TABLE_THICKNESS, 0.0, TABLE_COLOR)
    # Region markers are paint on the table: visible in pictures, absent from physics.
    markers = tuple(
        _slab(bc, r, 0.0, 0.0005, REGION_COLORS[name], collide=False) for name, r in REGIONS.items()
    )
    shelves = {name: build_shelf(bc, s) for name, s in SHELVES.items()}
    return Arena(table, shelves, markers)
