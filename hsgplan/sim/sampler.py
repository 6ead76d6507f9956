"""Seeded random initial configurations: collision-free, at rest, and mapping back to the
symbolic arrangement they were drawn from.

The arrangement is drawn symbolically first (`symbolic.generator.random_state`: mostly on the open
space, some stacked or on a shelf top, so that `Clear` matters), then each object gets a pose:
a free spot on its surface, found by rejection sampling against the bodies already placed, or
the centre of the object it is stacked on. After physics settles, f_m must give back the drawn
arrangement; otherwise the draw is repeated with the next attempt's random numbers.
"""

from __future__ import annotations

import math
import random

from hsgplan.domain.errors import UnsampledSceneError
from hsgplan.domain.parameters import place_inset
from hsgplan.domain.predicates import Predicate
from hsgplan.domain.scene import EntityKind
from hsgplan.domain.world import Kind, World
from hsgplan.scene_graph.geometry import Pose
from hsgplan.scene_graph.symbol_mapping import map_symbols
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.motion_plans import can_pick
from hsgplan.sim.scene import Scene
from hsgplan.symbolic.generator import random_state

TRIES_PER_CELL = 3
ATTEMPTS = 100
# Free space kept around each object so that the opening fingers fit beside it.
GAP = 0.01  # apart; whether the fingers fit is checked by the pick dry-runs below
JITTER = 0.01
YAW_JITTER = 0.1
STACK_JITTER = 0.005
REPAIRS = 3  # times the objects no grasp fits are put elsewhere before a draw is given up


def sample_scene(
    objects: tuple[str, ...],
    seed: int,
    p_elsewhere: float = 0.3,
    visuals: bool = True,
    *,
    world: World,
) -> tuple[Scene, SymbolicSceneGraph]:
    """A settled scene of `world` for the objects and the symbolic state it is in (`visuals`:
    `Scene`'s).

    The same seed gives the same scene: every random number comes from `seed`.
    """
    scene, state, _ = drawn_scene(objects, seed, p_elsewhere, visuals, world=world)
    return scene, state


def drawn_scene(
    objects: tuple[str, ...],
    seed: int,
    p_elsewhere: float = 0.3,
    visuals: bool = True,
    *,
    world: World,
    repairs: int = REPAIRS,
) -> tuple[Scene, SymbolicSceneGraph, int]:
    """`sample_scene` (with `repairs` of a draw, `_settled_as`), and how many arrangements
    were drawn for it."""
    rng = random.Random(f"scene-{seed}")
    scene = Scene(objects, seed=seed, visuals=visuals, world=world)
    for draw in range(1, ATTEMPTS + 1):
        state = random_state(objects, rng, p_elsewhere=p_elsewhere, world=world)
        for o in objects:
            scene.park(o)
        if place_all(scene, state, rng) and _settled_as(scene, state, rng, repairs):
            scene.robot.hold_position()
            return scene, state, draw
    scene.close()
    raise UnsampledSceneError(
        f"no collision-free arrangement of {len(objects)} objects found in {ATTEMPTS} attempts "
        f"(seed {seed})"
    )


def place_all(
    scene: Scene, state: SymbolicSceneGraph, rng: random.Random, placed: list[str] | None = None
) -> bool:
    """Pose every object the state puts `On` something (others are left where they are),
    clear of the objects in `placed`, which grows as objects are posed."""
    placed = [] if placed is None else placed
    # Supports before what stands on them: by tower level.
    for obj in sorted(state.objects, key=state.level):
        if state.location(obj).predicate is not Predicate.ON:
            continue
        below = state.location(obj).args[1]
        if scene.world.kind_of(below) is EntityKind.OBJECT:
            pose = _stacked_pose(scene, obj, below, rng)
        else:
            pose = free_spot(scene, obj, below, placed, rng)
            if pose is None:
                return False
        scene.set_pose(obj, pose)
        placed.append(obj)
    return True


def _stacked_pose(scene: Scene, obj: str, base: str, rng: random.Random) -> Pose:
    b, types = scene.pose(base), scene.world
    top = b.position[2] + types.object_type(base).height / 2
    jitter = [rng.uniform(-STACK_JITTER, STACK_JITTER) for _ in range(2)]
    yaw = b.yaw + rng.choice([0.0, math.pi / 2])
    return Pose.from_xyz_yaw(
        b.position[0] + jitter[0],
        b.position[1] + jitter[1],
        top + types.object_type(obj).height / 2 + 0.001,
        yaw,
    )


def free_spot(
    scene: Scene, obj: str, surface: str, placed: list[str], rng: random.Random
) -> Pose | None:
    """A random free spot cell of the surface, the object jittered and turned within it.

    Cells, not arbitrary points: scattered objects would fragment a surface so that its
    counted capacity could no longer be used. Cells are visited in a shuffled order, each with
    a few jittered tries and then its exact centre.
    """
    world = scene.world
    r, t = world.surface_rect(surface), world.object_type(obj)
    z = r.z + t.height / 2 + 0.001
    ix, iy = place_inset(obj, world)  # kept from the edges, as place bins are
    # Boxes lie long side along y, as they are placed (a cell is too short for them the other
    # way round); cans may stand any way.
    turns = [0.0, math.pi] if t.kind is Kind.BOX else [0.0, math.pi / 2]
    cells = [r.to_local(*c) for c in world.spot_cells(surface)]  # drawn in the surface's frame
    rng.shuffle(cells)
    for cx, cy in cells:
        for k in range(TRIES_PER_CELL + 1):
            jitter = JITTER if k < TRIES_PER_CELL else 0.0
            yaw = rng.choice(turns) + rng.uniform(-YAW_JITTER, YAW_JITTER) * (jitter > 0)
            x = min(max(cx + rng.uniform(-jitter, jitter), r.x_min + ix), r.x_max - ix)
            y = min(max(cy + rng.uniform(-jitter, jitter), r.y_min + iy), r.y_max - iy)
            pose = Pose.from_xyz_yaw(*r.to_world(x, y), z, r.direction(yaw))
            scene.set_pose(obj, pose)
            if not any(
                scene.bc.getClosestPoints(scene.bodies[obj], scene.bodies[o], GAP) for o in placed
            ) and not touches_arena(scene, obj):
                return pose
    return None


def touches_arena(scene: Scene, obj: str) -> bool:
    body = scene.bodies[obj]
    return any(
        # Objects are set 1 mm above their support, so the board they stand on is no hit.
        scene.bc.getClosestPoints(body, part, 0.0005)
        for parts in scene.arena.shelves.values()
        for part in parts
    )


def _settled_as(
    scene: Scene, state: SymbolicSceneGraph, rng: random.Random, repairs: int = REPAIRS
) -> bool:
    """Settled into the drawn arrangement, with every object graspable (a dry run), those under
    another one once it is lifted off: a plan may have to unstack them. An object on a surface
    with nothing on it that no grasp fits (its neighbours too close for the open fingers: on a
    crowded open space, nearly every failed draw at 12 objects) is put on another free spot
    of its surface, up to `repairs` times, before the whole draw is given up."""
    for repair in range(repairs + 1):
        scene.settle()
        if not _as_drawn(scene, state):
            return False
        stuck = [o for o in state.objects if not _graspable(scene, state, o)]
        if not stuck:
            return True
        if repair == repairs or not all(_movable(scene, state, o) for o in stuck):
            return False
        for obj in stuck:
            surface = state.location(obj).args[1]
            others = [o for o in state.objects if o != obj]
            pose = free_spot(scene, obj, surface, others, rng)
            if pose is None:
                return False
            scene.set_pose(obj, pose)
    return False


def _as_drawn(scene: Scene, state: SymbolicSceneGraph) -> bool:
    mapping = map_symbols(scene.scene_graph())
    if mapping.anomalies:
        return False
    return all(mapping.state.location(o) == state.location(o) for o in state.objects)


def _on_surface(scene: Scene, state: SymbolicSceneGraph, obj: str) -> bool:
    """Standing on a region or a shelf top (not on another object, nor inside a shelf)."""
    location = state.location(obj)
    return (
        location.predicate is Predicate.ON
        and scene.world.kind_of(location.args[1]) is not EntityKind.OBJECT
    )


def _movable(scene: Scene, state: SymbolicSceneGraph, obj: str) -> bool:
    """On a surface with nothing on it: it may be put elsewhere on that surface alone."""
    return _on_surface(scene, state, obj) and not state.resting_on(obj)


def _graspable(scene: Scene, state: SymbolicSceneGraph, obj: str) -> bool:
    above = state.resting_on(obj)
    saved = {o: scene.pose(o) for o in above}
    for i, o in enumerate(above):  # lifted off kinematically, put back exactly below
        scene.set_pose(o, Pose.from_xyz_yaw(-0.8, 0.6 - 0.2 * i, 0.5))
    ok = can_pick(scene, obj)
    for o, pose in saved.items():
        scene.set_pose(o, pose)
    return ok
