"""Staging a drawn symbolic arrangement in a scene: objects on surfaces and stacked (as the
scene sampler poses them), inside a shelf, or already in the gripper.

Used to make the situations of self-supervised motion data. Unlike `sample_scene` it makes no
grasp dry-runs (only the one primitive tried in a staged scene matters) and reuses the scene's
robot: objects are added and removed, which costs a fraction of building a new client.
"""

from __future__ import annotations

import math
import random

import numpy as np

from hsgplan.domain.predicates import Predicate
from hsgplan.domain.world import GRIPPER_MAX_OPENING, Kind
from hsgplan.scene_graph.geometry import Pose, yaw_quat
from hsgplan.scene_graph.symbol_mapping import map_symbols
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.motion_plans import FLOOR_GAP, GRASP_DEPTH
from hsgplan.sim.robot import REST, TIP_OFFSET, topdown
from hsgplan.sim.sampler import place_all
from hsgplan.sim.scene import Scene

ATTEMPTS = 20
# Where a held object waits: the hand above the table's middle, pointing down.
HOLD_X, HOLD_Y, HOLD_Z = (0.30, 0.55), (-0.25, 0.25), (0.28, 0.38)
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
            y += rng.uniform(-INSIDE_JITTER, INSIDE_JITTER)
            scene.set_pose(o, Pose.from_xyz_yaw(x, y, t.height / 2 + 0.001, 0.0))
            placed.append(o)
    return all(
        state.location(o).predicate is not Predicate.IN or o in placed for o in state.objects
    )


def move_short_of(
    scene: Scene, state: SymbolicSceneGraph, obj: str, shelf: str, gap: float
) -> bool:
    """Set a staged object down again nearer a shelf, moved along x only, its centre `gap`
    short of the interior: where a push that fell short leaves it. False when it would not
    rest there as `state` says (it met a neighbour, or f_m reads it otherwise)."""
    before = scene.pose(obj)
    x = scene.world.shelves[shelf].interior.x_min - gap
    scene.set_pose(obj, Pose((x, *before.position[1:]), before.orientation))
    scene.settle()
    moved = np.subtract(scene.pose(obj).position[:2], (x, before.position[1]))
    mapping = map_symbols(scene.scene_graph())
    return (
        float(np.hypot(*moved)) < SHORT_OF_TOLERANCE
        and not mapping.anomalies
        and mapping.state == state
    )


def hold(scene: Scene, obj: str, rng: random.Random) -> bool:
    """Put an object in the gripper as a top-down pick would leave it, the hand somewhere
    above the table's middle. False if that hand pose has no IK solution."""
    t = scene.world.object_type(obj)
    closing = rng.uniform(-math.pi, math.pi) if t.kind is Kind.CAN else rng.choice([0, math.pi])
    target = Pose(
        (rng.uniform(*HOLD_X), rng.uniform(*HOLD_Y), rng.uniform(*HOLD_Z)), topdown(closing)
    )
    q = scene.robot.ik(target, scene.rng, seeds=[REST])
    if q is None:
        return False
    scene.robot.set_q(q)
    tcp = scene.robot.tcp()
    depth = min(GRASP_DEPTH, t.height - FLOOR_GAP)
    z = tcp.position[2] - TIP_OFFSET + depth - t.height / 2
    scene.set_pose(obj, Pose((tcp.position[0], tcp.position[1], z), yaw_quat(closing)))
    scene.robot.set_fingers(max(0.0, t.grasp_width - 0.002))
    scene.robot.attach(scene.bodies[obj])
    return True
