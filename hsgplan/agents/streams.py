"""The streams of the PDDLStream-style baseline: samplers and tests over continuous values,
computed with the project's own geometry and robot.

As in PDDLStream, a stream sees only its inputs: inverse kinematics and push planning run in
the episode's scene with every object parked out of reach but the one the stream is about (its
collisions with the others are the collision test's business, `PoseTable`), so what a stream
certifies holds wherever the other objects are. Poses on a surface are the place bins' centres,
drawn in a random order as PDDLStream draws samples (the surface's spot cells first); a pose on
another object is its top's centre; the grasp is the top-down one the pick primitive takes; a
push is aimed at one of the shelf interior's slots (`motion.sampler.push_candidates`), its end
pose at that slot.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np

from hsgplan.domain.parameters import (
    PickParams,
    PushParams,
    extent_along,
    place_centre,
    place_xy,
    place_yaw,
)
from hsgplan.domain.world import (
    PLACE_BINS,
    REACH_MAX_Z,
    Kind,
    World,
)
from hsgplan.motion.sampler import (
    HAND_DROP,
    HAND_HALF_LENGTH,
    HAND_HALF_WIDTH,
    MIN_CLEARANCE,
    PUSH_DEPTH,
    push_candidates,
)
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.motion_plans import PlanFailure, plan_primitive
from hsgplan.sim.robot import REST
from hsgplan.sim.scene import Scene

# How far two objects' height ranges may overlap and still count as one above the other (a
# placed object is let go a few millimetres above its support and settles).
Z_TOLERANCE = 0.005


@dataclass(frozen=True)
class PoseValue:
    """Where an object's centre would be, and how it rests there.

    `relation`: "supported" (on surface `support`, at place bins `bins`), "stacked" (on the
    object `support`), "inside" (shelf `support`'s interior) or "loose" (an observed pose that
    is none of these, e.g. a toppled object). `world`: the scene's, whose type sizes `obj`
    (not compared: a value is its pose).
    """

    obj: str
    x: float
    y: float
    z: float
    yaw: float
    relation: str
    support: str
    bins: tuple[int, int] | None = None
    world: World = field(kw_only=True, compare=False, hash=False, repr=False)

    @property
    def pose(self) -> Pose:
        return Pose.from_xyz_yaw(self.x, self.y, self.z, self.yaw)

    @property
    def bottom(self) -> float:
        return self.z - self.world.object_type(self.obj).height / 2

    @property
    def top(self) -> float:
        return self.z + self.world.object_type(self.obj).height / 2


@dataclass(frozen=True)
class PushValue:
    """A push's parameters and the pose inside the shelf it is aimed at."""

    params: PushParams
    end: PoseValue


def observed_pose(obj: str, pose: Pose, relation: str, support: str, world: World) -> PoseValue:
    """An observed pose in a scene of `world`; on a surface, with the place bins nearest it (a
    plan may put the object back where it stands)."""
    x, y, z = pose.position
    bins = None
    if relation == "supported":
        grid = [(xb, yb) for xb in range(PLACE_BINS) for yb in range(PLACE_BINS)]
        bins = min(grid, key=lambda b: math.dist(place_xy(obj, support, *b, world), (x, y)))
    return PoseValue(obj, x, y, z, pose.yaw, relation, support, bins, world=world)


def bin_order(
    obj: str, surface: str, rng: np.random.Generator, world: World
) -> list[tuple[int, int]]:
    """The place bins in the order a pose sampler draws them: first, for each of the surface's
    spot cells (in a random order), the bin nearest its centre, so that the first poses on a
    surface stand apart as its capacity counts them; then every other bin, in a random order.
    (Measured on one 6-object goal: with every bin drawn uniformly, no plan was found within
    three levels, and the fourth held 3.8 million facts; cells first, the third had a plan.)"""
    grid = [(xb, yb) for xb in range(PLACE_BINS) for yb in range(PLACE_BINS)]
    cells = world.spot_cells(surface)
    first: list[tuple[int, int]] = []
    for i in rng.permutation(len(cells)):
        centre = cells[i]
        nearest = min(grid, key=lambda b: math.dist(place_xy(obj, surface, *b, world), centre))
        if nearest not in first:
            first.append(nearest)
    return first + [grid[i] for i in rng.permutation(len(grid)) if grid[i] not in first]


def surface_pose(obj: str, surface: str, bins: tuple[int, int], world: World) -> PoseValue:
    """The pose a place at these bins puts the object in (standing, long side along the
    surface's y)."""
    x, y, z = place_centre(obj, surface, *bins, world)
    yaw = place_yaw(surface, world)
    return PoseValue(obj, x, y, z, yaw, "supported", surface, bins, world=world)


def stack_pose(obj: str, below: PoseValue) -> PoseValue | None:
    """The pose of `obj` on the centre of `below`'s top, if that object can carry it and the
    tower stays within the arm's reach."""
    if below.obj == obj or below.relation not in ("supported", "stacked"):
        return None
    world = below.world
    if not world.can_support(world.object_type(below.obj).name):
        return None
    height = world.object_type(obj).height
    if below.top + height > REACH_MAX_Z:
        return None
    z = below.top + height / 2
    return PoseValue(obj, below.x, below.y, z, below.yaw, "stacked", below.obj, world=world)


def _half_extents(p: PoseValue) -> tuple[float, float]:
    fx, fy = p.world.object_type(p.obj).footprint
    c, s = abs(math.cos(p.yaw)), abs(math.sin(p.yaw))
    return (c * fx + s * fy) / 2, (s * fx + c * fy) / 2


class PoseTable:
    """Every pose so far, as arrays: the collision test (PDDLStream's `CFree`, negated) of a
    new pose against all of them at once (thousands of poses by the third level).

    Two objects collide when their height ranges overlap and their footprints stand closer
    than the fingers need (`MIN_CLEARANCE`), or when the top-down hand taking the lower one
    would sweep into the other: a box is grasped across its narrow side with the hand long
    along it, so a neighbour that rises above the box by more than the fingers reach down
    (`HAND_DROP`) must stay out of the hand's footprint; cans are grasped from whichever side
    is free. Footprints that overlap with no overlap in height are a tower, which is free.
    """

    _COLUMNS = 11  # object id, x, y, bottom, top, half x, half y, box, cos, sin, reach

    def __init__(self) -> None:
        self._rows = np.zeros((64, self._COLUMNS))
        self._size = 0
        self._ids: dict[str, int] = {}

    def __len__(self) -> int:
        return self._size

    def _row(self, p: PoseValue) -> np.ndarray:
        hx, hy = _half_extents(p)
        box = p.world.object_type(p.obj).kind is Kind.BOX
        oid = self._ids.setdefault(p.obj, len(self._ids))
        c, s = math.cos(p.yaw), math.sin(p.yaw)
        return np.array([oid, p.x, p.y, p.bottom, p.top, hx, hy, box, c, s, max(hx, hy)])

    def add(self, p: PoseValue) -> None:
        if self._size == len(self._rows):
            self._rows = np.concatenate([self._rows, np.zeros_like(self._rows)])
        self._rows[self._size] = self._row(p)
        self._size += 1

    def collisions(self, p: PoseValue) -> np.ndarray:
        """Indices (in the order added) of the poses of other objects that `p` collides with."""
        oid, x, y, bottom, top, hx, hy, box, c, s, reach = self._row(p)
        r = self._rows[: self._size].T
        dx, dy = r[1] - x, r[2] - y
        gap = np.maximum(np.abs(dx) - r[5] - hx, np.abs(dy) - r[6] - hy)
        overlap = np.minimum(r[4], top) - np.maximum(r[3], bottom) > Z_TOLERANCE
        # the hand at p (p the lower) or at the other pose (the other the lower)
        sweep_p = (
            (box > 0)
            & (r[4] - top >= HAND_DROP)
            & (np.abs(c * dx + s * dy) < HAND_HALF_LENGTH + r[10])
            & (np.abs(-s * dx + c * dy) < HAND_HALF_WIDTH + r[10])
        )
        sweep_other = (
            (r[7] > 0)
            & (top - r[4] >= HAND_DROP)
            & (np.abs(r[8] * dx + r[9] * dy) < HAND_HALF_LENGTH + reach)
            & (np.abs(-r[9] * dx + r[8] * dy) < HAND_HALF_WIDTH + reach)
        )
        hand = (gap > 0) & (sweep_p | sweep_other)
        hit = ((overlap & (gap < MIN_CLEARANCE)) | hand) & (r[0] != oid)
        return np.flatnonzero(hit)


def collides(a: PoseValue, b: PoseValue) -> bool:
    """The collision test of two poses (`PoseTable`)."""
    table = PoseTable()
    table.add(b)
    return len(table.collisions(a)) > 0


def push_shelf(p: PoseValue) -> str | None:
    """The shelf whose prepush region a pose rests on, if the object fits into it."""
    world = p.world
    for name, shelf in world.shelves.items():
        if p.relation == "supported" and p.support == shelf.prepush:
            return name if world.fits_inside(world.object_type(p.obj).name, name) else None
    return None


class StreamWorld:
    """The episode's scene as the streams use it: call it inside a `Trial`, which puts every
    object, the arm and the grasp back when it closes.

    Args:
        scene: the episode's scene (the trial's).
    """

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        scene.robot.detach()
        for i, name in enumerate(scene.objects):
            scene.set_pose(name, _far(i))
        self._shown: str | None = None

    def _show(self, pose: PoseValue) -> None:
        scene = self.scene
        if self._shown is not None:
            scene.set_pose(self._shown, _far(scene.objects.index(self._shown)))
        scene.set_pose(pose.obj, pose.pose)
        self._shown = pose.obj
        scene.robot.set_q(REST)

    def kin(self, pose: PoseValue) -> tuple[float, ...] | None:
        """The inverse-kinematics stream: the arm's joints holding the object at the pose
        with the top-down grasp (the pick primitive's, which a place at that pose repeats),
        a collision-free approach and a path from rest; None where there is none."""
        self._show(pose)
        plan = plan_primitive(self.scene, PickParams(pose.obj))
        if isinstance(plan, PlanFailure):
            return None
        return tuple(float(v) for v in plan.q_at)

    def pushes(self, start: PoseValue, shelf: str) -> Iterator[tuple[PushValue, tuple[float, ...]]]:
        """The push stream: pushes from the pose into each of the shelf's slots, nearest
        first, those the arm can carry out (with the joints it starts from)."""
        world = self.scene.world
        interior = world.shelves[shelf].interior
        sg = GeometricSceneGraph.from_poses({start.obj: start.pose}, world=world)
        local_y = interior.to_local(start.x, start.y)[1]  # slots run along the shelf's y
        slots = sorted(world.interior_slots(shelf), key=lambda s: abs(s - local_y))
        for slot, params in zip(slots, push_candidates(sg, start.obj, shelf), strict=True):
            self._show(start)
            plan = plan_primitive(self.scene, params)
            if isinstance(plan, PlanFailure):
                continue
            depth = extent_along(start.obj, start.yaw - interior.yaw, 0.0, world)
            end = PoseValue(
                start.obj,
                *interior.to_world(interior.x_min + PUSH_DEPTH + depth, slot),
                start.z,
                start.yaw,
                "inside",
                shelf,
                world=world,
            )
            yield PushValue(params, end), tuple(float(v) for v in plan.q_at)


def _far(i: int) -> Pose:
    # Far outside the arena and apart: an obstacle to nothing the arm can reach.
    return Pose.from_xyz_yaw(20.0 + 2.0 * i, 20.0, 1.0)
