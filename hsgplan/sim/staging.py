"""Staging a drawn symbolic arrangement in a scene: objects on surfaces and stacked (as the
scene sampler poses them), inside a shelf, or already in the gripper.

Used to make the situations of self-supervised motion data. Unlike `sample_scene` it makes no
grasp dry-runs (only the one primitive tried in a staged scene matters) and reuses the scene's
robot: objects are added and removed, which costs a fraction of building a new client. A held
object is taken up by a pick under physics, so that what follows starts from a grasp the
fingers made.
"""

from __future__ import annotations

import math
import random

import numpy as np

from hsgplan.domain.parameters import PickParams
from hsgplan.domain.predicates import Predicate
from hsgplan.domain.world import GRIPPER_MAX_OPENING, Kind
from hsgplan.scene_graph.geometry import Pose, yaw_quat
from hsgplan.scene_graph.symbol_mapping import map_symbols
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.motion_plans import PlanFailure, plan_primitive
from hsgplan.sim.primitives import run_path, run_plan
from hsgplan.sim.robot import REST
from hsgplan.sim.sampler import place_all
from hsgplan.sim.scene import Scene

ATTEMPTS = 20
# Where a held object is picked from (the table's middle) and how high the hand then waits.
HOLD_X, HOLD_Y, HOLD_Z = (0.30, 0.55), (-0.25, 0.25), (0.28, 0.38)
HOLD_CLEAR = 0.15  # m: no other object's centre this near the spot it is picked from
# Objects inside a shelf stand in one of its slots, this far behind the open front (beyond
# their half width): where pushes leave them, and somewhat deeper.
INSIDE_DEPTH = (0.01, 0.06)
INSIDE_JITTER = 0.01
SHORT_OF_TOLERANCE = 0.005  # m an object moved short of a shelf may settle from where it was put


def stage(scene: Scene, state: SymbolicSceneGraph, rng: random.Random) -> bool:
    """Give the scene's objects (exactly `state.objects`) poses that f_m maps to `state`,
    settled under physics. False when no try out of `ATTEMPTS` worked."""
    if set(scene.objects) != set(state.objects):
        raise ValueError("the scene must hold exactly the state's objects")
    for _ in range(ATTEMPTS):
        scene.robot.detach()
        scene.robot.set_q(REST)
        scene.robot.set_fingers(GRIPPER_MAX_OPENING)
        for o in state.objects:
            scene.park(o)
        placed: list[str] = []
        if not _put_inside(scene, state, rng, placed) or not place_all(scene, state, rng, placed):
            continue
        held = state.held()
        if held is not None and not hold(scene, held, rng):
            continue
        scene.settle()
        mapping = map_symbols(scene.scene_graph())
        if not mapping.anomalies and mapping.state == state:
            return True
    return False


def _put_inside(
    scene: Scene, state: SymbolicSceneGraph, rng: random.Random, placed: list[str]
) -> bool:
    world = scene.world
    for shelf in world.interior_capacity:
        inside = state.inside(shelf)
        if not inside:
            continue
        slots = rng.sample(world.interior_slots(shelf), len(inside))
        r = world.shelves[shelf].interior
        for o, y in zip(inside, slots, strict=True):
            t = world.object_type(o)
            x = r.x_min + t.size[0] / 2 + rng.uniform(*INSIDE_DEPTH)
            y += rng.uniform(-INSIDE_JITTER, INSIDE_JITTER)  # in the shelf's frame
            at = (*r.to_world(x, y), t.height / 2 + 0.001)
            scene.set_pose(o, Pose.from_xyz_yaw(*at, r.direction(0.0)))
            placed.append(o)
    return all(
        state.location(o).predicate is not Predicate.IN or o in placed for o in state.objects
    )


def move_short_of(
    scene: Scene, state: SymbolicSceneGraph, obj: str, shelf: str, gap: float
) -> bool:
    """Set a staged object down again nearer a shelf, moved along the shelf's x only, its
    centre `gap` short of the interior: where a push that fell short leaves it. False when it
    would not rest there as `state` says (it met a neighbour, or f_m reads it otherwise)."""
    before = scene.pose(obj)
    r = scene.world.shelves[shelf].interior
    at = r.to_world(r.x_min - gap, r.to_local(*before.position[:2])[1])
    scene.set_pose(obj, Pose((*at, before.position[2]), before.orientation))
    scene.settle()
    moved = np.subtract(scene.pose(obj).position[:2], at)
    mapping = map_symbols(scene.scene_graph())
    return (
        float(np.hypot(*moved)) < SHORT_OF_TOLERANCE
        and not mapping.anomalies
        and mapping.state == state
    )


def hold(scene: Scene, obj: str, rng: random.Random) -> bool:
    """Put an object in the gripper by a pick the fingers make, as an episode's would: the
    object stood on the table's middle, clear of the others, picked under physics (held by a
    grasp's constraint or by friction, at whatever offset the closing fingers left), and the
    hand driven up with it. False where that spot is crowded, the pick plans nothing or
    takes nothing up, or the object slips out on the way up."""
    t = scene.world.object_type(obj)
    yaw = rng.uniform(-math.pi, math.pi) if t.kind is Kind.CAN else rng.choice([0, math.pi])
    x, y = rng.uniform(*HOLD_X), rng.uniform(*HOLD_Y)
    for o in scene.objects:
        p = scene.pose(o).position
        if o != obj and math.hypot(p[0] - x, p[1] - y) < HOLD_CLEAR:
            return False
    scene.set_pose(obj, Pose((x, y, t.height / 2 + 0.001), yaw_quat(yaw)))
    scene.settle()
    plan = plan_primitive(scene, PickParams(obj))
    if isinstance(plan, PlanFailure):
        return False
    run_plan(scene, plan)
    if scene.held() != obj:
        return False
    tcp = scene.robot.tcp()
    up = Pose((*tcp.position[:2], rng.uniform(*HOLD_Z)), tcp.orientation)
    q = scene.robot.ik(up, scene.rng, seeds=[scene.robot.q()])
    if q is None or not run_path(scene, [scene.robot.q(), q]):
        return False
    scene.feel_hold()
    return scene.held() == obj
