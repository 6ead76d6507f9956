"""Motion parameters chosen from geometry: the oracle's stand-in for the learned motion model.

It sees only the geometric scene graph. Place bins are ranked by clearance from the objects
already on the target surface (and, on a prepush region, by how well they line up with a free
slot inside the shelf); push bins aim the object at the nearest free slot, a few centimetres
inside the shelf's interior.
"""

from __future__ import annotations

import math

from hsgplan.domain.objects import object_type
from hsgplan.domain.parameters import (
    PickParams,
    PlaceParams,
    PrimitiveParams,
    PushParams,
    nearest_push_bins,
    place_xy,
)
from hsgplan.domain.transition import Action, Pick, Place, Push
from hsgplan.domain.world import (
    INTERIOR_CAPACITY,
    PLACE_BINS,
    PLACE_LONG_AXIS_YAW,
    SHELVES,
    SPOT,
    SURFACES,
    Rect,
    surface_rect,
)
from hsgplan.scene_graph.geometric import GeometricSceneGraph

MIN_CLEARANCE = 0.015  # m between footprints (as circles) for a bin to be considered at all
# How far past the open front the pushed object's near side ends: inside, and shallow enough
# that the leaning hand stays out of the shelf (measured: 21 cm across, it meets the side walls
# once the fingertips go deeper than about 2 cm at the outer slots).
PUSH_DEPTH = 0.02
PUSH_LEAD = 0.01  # the fingertip starts this far behind the object


def _half_extents(obj: str, yaw: float) -> tuple[float, float]:
    """Half-sizes along world x and y of the box bounding an object's footprint at a yaw."""
    fx, fy = object_type(obj).footprint
    c, s = abs(math.cos(yaw)), abs(math.sin(yaw))
    return (c * fx + s * fy) / 2, (s * fx + c * fy) / 2


def spot_cells(rect: Rect) -> list[tuple[float, float]]:
    """Centres of the SPOT cells a surface is counted in (its capacity), centred on it."""
    nx, ny = int(rect.width_x // SPOT), int(rect.width_y // SPOT)
    x0 = rect.center[0] - nx * SPOT / 2
    y0 = rect.center[1] - ny * SPOT / 2
    return [(x0 + SPOT * (i + 0.5), y0 + SPOT * (j + 0.5)) for i in range(nx) for j in range(ny)]


def interior_slots(shelf: str) -> list[float]:
    """y of each spot in a shelf's interior row, evenly spread across its width."""
    r = SHELVES[shelf].interior
    n = INTERIOR_CAPACITY[shelf]
    return [r.y_min + r.width_y * (k + 0.5) / n for k in range(n)]


def free_slots(sg: GeometricSceneGraph, shelf: str, ignore: str = "") -> list[float]:
    r = SHELVES[shelf].interior
    taken = [
        n.pose.position[1] for n in sg.nodes
        if n.name != ignore and r.contains(*n.pose.position[:2]) and n.pose.position[2] < r.z + 0.1
    ]
    return [y for y in interior_slots(shelf) if all(abs(y - t) > 0.05 for t in taken)]


def _on_rect(
    sg: GeometricSceneGraph, rect: Rect, ignore: str
) -> list[tuple[float, float, float, float]]:
    """(x, y, half x, half y) of the objects standing on a rectangle's level within it."""
    out = []
    for n in sg.nodes:
        x, y, _ = n.pose.position
        if n.name != ignore and rect.contains(x, y, margin=0.05) and abs(n.bottom_z - rect.z) < 0.03:
            out.append((x, y, *_half_extents(n.name, n.pose.yaw)))
    return out


def place_candidates(
    sg: GeometricSceneGraph, obj: str, target: str, next_push: bool = False
) -> list[PlaceParams]:
    """Place bins on a surface, best first; bins too close to other objects are left out.

    Bins are ranked by how close they come to the centre of a free spot cell (so that the
    surface's whole capacity stays usable) or, on a prepush region before a push, by how well
    they line up with a free slot inside the shelf.
    """
    if target not in SURFACES:
        return [PlaceParams(obj, target)]
    rect = surface_rect(target)
    others = _on_rect(sg, rect, ignore=obj)
    hx, hy = _half_extents(obj, PLACE_LONG_AXIS_YAW)
    free = [
        c for c in spot_cells(rect)
        if all(abs(c[0] - ox) > SPOT / 2 or abs(c[1] - oy) > SPOT / 2 for ox, oy, _, _ in others)
    ]
    slots = []
    if next_push:
        shelf = next(s for s, sh in SHELVES.items() if sh.prepush == target)
        slots = free_slots(sg, shelf) or interior_slots(shelf)
    ranked = []
    for xb in range(PLACE_BINS):
        for yb in range(PLACE_BINS):
            x, y = place_xy(obj, target, xb, yb)
            gap = min(
                (max(abs(x - ox) - hx - ohx, abs(y - oy) - hy - ohy) for ox, oy, ohx, ohy in others),
                default=1.0,
            )
            if gap < MIN_CLEARANCE:
                continue
            if slots:
                cost = min(abs(y - s) for s in slots) + 0.3 * abs(x - rect.center[0])
            elif free:
                cost = min(math.hypot(x - cx, y - cy) for cx, cy in free)
            else:
                cost = -min(gap, 0.1)
            ranked.append((cost, xb, yb))
    return [PlaceParams(obj, target, xb, yb) for _, xb, yb in sorted(ranked)]


def push_candidates(sg: GeometricSceneGraph, obj: str, shelf: str) -> list[PushParams]:
    """Pushes aimed at the free interior slots, nearest slot first."""
    x, y, _ = sg.pose(obj).position
    r = SHELVES[shelf].interior
    reach = max(_half_extents(obj, sg.pose(obj).yaw))
    slots = sorted(free_slots(sg, shelf, ignore=obj), key=lambda s: abs(s - y))
    out = []
    for slot in slots:
        tx = r.x_min + PUSH_DEPTH + reach
        angle = math.atan2(slot - y, tx - x)
        dist = math.hypot(tx - x, slot - y) + PUSH_LEAD
        out.append(PushParams(obj, *nearest_push_bins(angle, dist)))
    return out


def candidates(
    sg: GeometricSceneGraph, action: Action, following: Action | None = None
) -> list[PrimitiveParams]:
    """Every parameter choice for a symbolic action, best first."""
    if isinstance(action, Pick):
        return [PickParams(action.obj)]
    if isinstance(action, Place):
        next_push = isinstance(following, Push) and action.target == SHELVES[following.shelf].prepush
        return list(place_candidates(sg, action.obj, action.target, next_push))
    return list(push_candidates(sg, action.obj, action.shelf))
