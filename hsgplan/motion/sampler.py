"""Motion parameters chosen from geometry: the oracle's motion generator, a hand-written stand-in
for the learned ones.

It sees only the geometric scene graph. Place bins are ranked by clearance from the objects
already on the target surface (and, on a prepush region, by how well they line up with a free
slot inside the shelf); push bins aim the object at the nearest free slot, a few centimetres
inside the shelf's interior.
"""

from __future__ import annotations

import math

from hsgplan.domain.actions import Action, Pick, Place, Push
from hsgplan.domain.parameters import (
    PUSH_LEAD,
    PickParams,
    PlaceParams,
    PrimitiveParams,
    PushParams,
    extent_along,
    nearest_push_bins,
    place_xy,
)
from hsgplan.domain.world import (
    PLACE_BINS,
    PLACE_LONG_AXIS_YAW,
    Kind,
    ObjectType,
    Rect,
)
from hsgplan.motion.interface import DO_NOT_RETRY, DRY_RUNS, Feasibility, SingleShotMemory
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.sim.outcome import Outcome

MIN_CLEARANCE = 0.015
# The Panda hand, measured in PyBullet: about 21 cm long along the finger axis and 6 cm across,
# its lowest part some 6 cm above the fingertips, which reach at most 3.5 cm below a top.
HAND_HALF_LENGTH = 0.105
HAND_HALF_WIDTH = 0.03
HAND_DROP = 0.02  # m between footprints (as circles) for a bin to be considered at all
# How far past the open front the pushed object's near side ends: inside, and shallow enough
# that the leaning hand stays out of the shelf (measured: 21 cm across, it meets the side walls
# once the fingertips go deeper than about 2 cm at the outer slots).
PUSH_DEPTH = 0.02


def _half_extents(t: ObjectType, yaw: float) -> tuple[float, float]:
    """Half-sizes along world x and y of the box bounding a footprint at a yaw."""
    fx, fy = t.footprint
    c, s = abs(math.cos(yaw)), abs(math.sin(yaw))
    return (c * fx + s * fy) / 2, (s * fx + c * fy) / 2


def _hand_conflict(a, b) -> bool:
    """Whether grasping or placing the lower of two objects would sweep the hand into the other.

    Each is (x, y, half x, half y, top z, box yaw or None). The hand is long along the finger
    axis, which for a box is fixed (across its narrow side); a can can be grasped from any side,
    so only boxes are at risk. A neighbour matters when it rises above the lower object's top by
    more than the fingers reach down.
    """
    low, high = (a, b) if a[4] <= b[4] else (b, a)
    if low[5] is None or high[4] - low[4] < HAND_DROP:
        return False
    c, s = math.cos(low[5]), math.sin(low[5])
    dx, dy = high[0] - low[0], high[1] - low[1]
    along, across = abs(c * dx + s * dy), abs(-s * dx + c * dy)
    reach = max(high[2], high[3])
    return along < HAND_HALF_LENGTH + reach and across < HAND_HALF_WIDTH + reach


def _standing(t: ObjectType, x: float, y: float, yaw: float, bottom: float):
    box_yaw = yaw if t.kind is Kind.BOX else None
    return (x, y, *_half_extents(t, yaw), bottom + t.height, box_yaw)


def free_slots(sg: GeometricSceneGraph, shelf: str, ignore: str = "") -> list[float]:
    """The interior slots no object stands in (y in the shelf's own frame)."""
    r = sg.world.shelves[shelf].interior
    taken = [
        r.to_local(*n.pose.position[:2])[1]
        for n in sg.nodes
        if n.name != ignore and r.contains(*n.pose.position[:2]) and n.pose.position[2] < r.z + 0.1
    ]
    return [y for y in sg.world.interior_slots(shelf) if all(abs(y - t) > 0.05 for t in taken)]


def _on_rect(sg: GeometricSceneGraph, rect: Rect, ignore: str) -> tuple[list, list]:
    """`_standing` tuples of the objects resting on a rectangle, and of all objects above it
    (towers included, whose tops decide what the hand can sweep past), in the rectangle's own
    frame."""
    resting, above = [], []
    for n in sg.nodes:
        x, y, _ = n.pose.position
        if n.name == ignore or not rect.contains(x, y, margin=0.05) or n.bottom_z < rect.z - 0.03:
            continue
        item = _standing(n.type, *rect.to_local(x, y), n.pose.yaw - rect.yaw, n.bottom_z)
        above.append(item)
        if n.bottom_z < rect.z + 0.03:
            resting.append(item)
    return resting, above


def place_candidates(
    sg: GeometricSceneGraph,
    obj: str,
    target: str,
    next_push: bool = False,
    avoid: tuple[tuple[float, float], ...] = (),
) -> list[PlaceParams]:
    """Place bins on a surface, best first; bins too close to other objects are left out, and
    so are bins within `AVOID_RADIUS` of a spot in `avoid` (where pushes of `obj` failed).

    Bins where the hand would sweep into a taller neighbour (or a tall object would block a
    box's later grasp) go last. Otherwise bins are ranked by how close they come to the centre
    of a free spot cell (so that the surface's whole capacity stays usable) or, on a prepush
    region before a push, by how well they line up with a free slot inside the shelf. All of it
    is reckoned in the surface's own frame (which turns with its shelf).
    """
    world = sg.world
    if target not in world.surface_capacity:
        return [PlaceParams(obj, target)]
    rect, t = world.surface_rect(target), world.object_type(obj)
    others, above = _on_rect(sg, rect, ignore=obj)
    hx, hy = _half_extents(t, PLACE_LONG_AXIS_YAW)
    cell_x, cell_y = world.cell
    free = [
        c
        for c in (rect.to_local(*w) for w in world.spot_cells(target))
        if all(abs(c[0] - o[0]) > cell_x / 2 or abs(c[1] - o[1]) > cell_y / 2 for o in others)
    ]
    avoid = tuple(rect.to_local(*a) for a in avoid)
    slots = []
    if next_push:
        shelf = next(s.name for s in world.shelf_list if s.prepush == target)
        slots = free_slots(sg, shelf) or world.interior_slots(shelf)
    ranked = []
    for xb in range(PLACE_BINS):
        for yb in range(PLACE_BINS):
            x, y = rect.to_local(*place_xy(obj, target, xb, yb, world))
            gap = min(
                (max(abs(x - o[0]) - hx - o[2], abs(y - o[1]) - hy - o[3]) for o in others),
                default=1.0,
            )
            if gap < MIN_CLEARANCE or any(math.dist((x, y), a) < AVOID_RADIUS for a in avoid):
                continue
            # The primitive turns a box a quarter turn when the hand would not fit the
            # other way: blocked means blocked both ways.
            blocked = all(
                any(_hand_conflict(_standing(t, x, y, yaw, rect.z), o) for o in above)
                for yaw in (PLACE_LONG_AXIS_YAW, PLACE_LONG_AXIS_YAW + math.pi / 2)
            )
            if slots:
                cost = min(abs(y - s) for s in slots) + 0.3 * abs(x - (rect.x_min + rect.x_max) / 2)
            elif free:
                cost = min(math.hypot(x - cx, y - cy) for cx, cy in free)
            else:
                cost = -min(gap, 0.1)
            ranked.append((blocked, cost, xb, yb))
    return [PlaceParams(obj, target, xb, yb) for _, _, xb, yb in sorted(ranked)]


def push_candidates(sg: GeometricSceneGraph, obj: str, shelf: str) -> list[PushParams]:
    """Pushes aimed at the free interior slots, nearest slot first (in the shelf's frame)."""
    r = sg.world.shelves[shelf].interior
    x, y = r.to_local(*sg.pose(obj).position[:2])
    yaw = sg.pose(obj).yaw - r.yaw
    slots = sorted(free_slots(sg, shelf, ignore=obj), key=lambda s: abs(s - y))
    out = []
    for slot in slots:
        straight = math.atan2(slot - y, r.x_min - x)
        tx = r.x_min + PUSH_DEPTH + extent_along(obj, yaw, straight, sg.world)
        angle = math.atan2(slot - y, tx - x)
        dist = math.hypot(tx - x, slot - y) + PUSH_LEAD
        out.append(PushParams(obj, *nearest_push_bins(angle, dist)))
    return out


def candidates(
    sg: GeometricSceneGraph,
    action: Action,
    following: Action | None = None,
    avoid: tuple[tuple[float, float], ...] = (),
) -> list[PrimitiveParams]:
    """Every parameter choice for a symbolic action, best first (`avoid`: spots where pushes
    of the object failed, left out of a place that a push follows)."""
    if isinstance(action, Pick):
        return [PickParams(action.obj)]
    if isinstance(action, Place):
        next_push = (
            isinstance(following, Push)
            and action.target == sg.world.shelves[following.shelf].prepush
        )
        spots = avoid if next_push else ()
        return list(place_candidates(sg, action.obj, action.target, next_push, spots))
    return list(push_candidates(sg, action.obj, action.shelf))


# A place before a push stays this far from where a push of the object failed (m).
AVOID_RADIUS = 0.04


class GeometricSampler(SingleShotMemory):
    """The best-ranked candidate that passes a dry run (at most `DRY_RUNS` are checked) and
    has not failed for good in this scene; without a dry run, the best-ranked one. None when
    every candidate has failed here.

    Where a push failed for good it remembers the spot the object stood on, and a later place
    of that object before a push puts it elsewhere: an agent whose push has no parameters left
    takes the object up again (`agents/hierarchical.py`) and the region gets another try."""

    name = "sampler"

    def __init__(self) -> None:
        super().__init__()
        self.reset(0)

    def reset(self, seed: int) -> None:
        super().reset(seed)
        self.push_failed_at: dict[str, list[tuple[float, float]]] = {}
        self._sg: GeometricSceneGraph | None = None

    def observe(self, params: PrimitiveParams, outcome: Outcome) -> None:
        super().observe(params, outcome)
        if isinstance(params, PushParams) and outcome.status in DO_NOT_RETRY and self._sg:
            x, y, _ = self._sg.pose(params.obj).position
            self.push_failed_at.setdefault(params.obj, []).append((x, y))

    def propose(
        self,
        sg: GeometricSceneGraph,
        action: Action,
        following: Action | None = None,
        feasible: Feasibility | None = None,
    ) -> PrimitiveParams | None:
        self._sg = sg
        avoid = tuple(self.push_failed_at.get(action.obj, ()))
        options = self.untried(sg, candidates(sg, action, following, avoid))
        return next(
            (c for c in options[:DRY_RUNS] if feasible is None or feasible(c)),
            options[0] if options else None,
        )
