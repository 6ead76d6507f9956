"""`hsgplan collect reach`: primitives executed in the simulated world from staged symbolic
states, the self-supervised labels of f_reach (format: `data/world_trials.py`).

Nothing here asks the hand-written rules whether an action applies: a state is drawn, staged
with physics, and each chosen action is planned and executed; what the world shows afterwards
is recorded. The world refuses in its own ways: a pick while the hand is closed on another
object has no plan, a place on a full surface finds no free spot, a pick from under another
object disturbs it, a push into a full interior finds no free slot.

States (`draw_reach_state`), from `random.Random(f"reach-{seed}-{index}")`: 2 to 6 objects as
the goal distribution draws them; one place is crowded in most states (a shelf top, a prepush
region or a shelf interior, drawn uniformly, or none with probability 1/6), and each object
goes there with probability 0.7 while it has room; otherwise onto a bare object that can carry
it (probability 0.3, where there is one), into a shelf interior it fits (0.1), or onto a
surface with room, uniformly. Then, with probability 1/2, one clear object not inside a shelf
is in the hand. Per state up to `ACTIONS_PER_STATE` distinct actions the heuristic names for
some literal (`planning.heuristic`) are executed, each from the staged state: the primitive
(pick, place, push) uniform among those named, then the action uniform within it.
"""

from __future__ import annotations

import random
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hsgplan.data.world_trials import NO_PARAMETERS, WorldTrial, state_json, trials_of
from hsgplan.domain.actions import Action
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.objects import objects_for_types, sort_objects
from hsgplan.domain.predicates import Literal, in_grasp, inside, on
from hsgplan.domain.room import Room
from hsgplan.domain.world import OBJECT_TYPES, SHELVES, SURFACES
from hsgplan.motion.sampler import candidates
from hsgplan.planning.heuristic import action_for, candidate_literals
from hsgplan.runner.items import run_items
from hsgplan.scene_graph.symbol_mapping import map_symbols
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.motion_plans import PlanFailure, plan_primitive
from hsgplan.sim.primitives import execute
from hsgplan.sim.scene import Scene
from hsgplan.sim.staging import stage

ACTIONS_PER_STATE = 6
MAX_PARAMS = 5  # parameter choices planned, best first, before the action counts as failed
STATES_PER_CHUNK = 8  # a unit of work: consecutive states in one fresh scene
MIN_OBJECTS, MAX_OBJECTS = 2, 6
P_CROWD, P_STACK, P_INSIDE, P_HOLD = 0.7, 0.3, 0.1, 0.5


def draw_reach_state(seed: int, index: int) -> SymbolicSceneGraph:
    """A staged state's symbolic arrangement (see the module docstring)."""
    rng = random.Random(f"reach-{seed}-{index}")
    n = rng.randint(MIN_OBJECTS, MAX_OBJECTS)
    objects = sort_objects(objects_for_types(rng.sample(list(OBJECT_TYPES), n)))
    order = list(objects)
    rng.shuffle(order)
    crowd = rng.choice([None, *SURFACES[1:], *(f"in:{s}" for s in SHELVES)])
    room = Room.left()
    placed: list[Literal] = []
    for o in order:
        shelf = crowd[3:] if crowd and crowd.startswith("in:") else None
        if shelf and shelf in room.free_interiors(o) and rng.random() < P_CROWD:
            placed.append(inside(o, shelf))
            room.put_inside(o, shelf)
            continue
        if crowd in room.top and room.top[crowd] > 0 and rng.random() < P_CROWD:
            where = crowd
        elif room.bases() and rng.random() < P_STACK:
            where = rng.choice(room.bases())
        elif room.free_interiors(o) and rng.random() < P_INSIDE:
            shelf = rng.choice(room.free_interiors(o))
            placed.append(inside(o, shelf))
            room.put_inside(o, shelf)
            continue
        else:
            where = rng.choice(room.free_tops())
        placed.append(on(o, where))
        room.put_on(o, where)
    state = SymbolicSceneGraph.from_literals(objects, placed)
    free = [
        o
        for o in state.objects
        if not state.resting_on(o) and state.location(o).predicate.value == "On"
    ]
    if free and rng.random() < P_HOLD:
        held = rng.choice(free)
        placed = [lit for lit in placed if lit.subject != held] + [in_grasp(held)]
        state = SymbolicSceneGraph.from_literals(objects, placed)
    return state


def choose_actions(state: SymbolicSceneGraph, rng: random.Random) -> list[Action]:
    """Up to `ACTIONS_PER_STATE` distinct actions the heuristic names in this state."""
    named = {action_for(lit, state) for lit in candidate_literals(state)}
    named = sorted((a for a in named if a is not None), key=str)
    by_kind: dict[str, list[Action]] = {}
    for a in named:
        by_kind.setdefault(type(a).__name__, []).append(a)
    chosen: list[Action] = []
    while by_kind and len(chosen) < ACTIONS_PER_STATE:
        kind = rng.choice(sorted(by_kind))
        chosen.append(by_kind[kind].pop(rng.randrange(len(by_kind[kind]))))
        if not by_kind[kind]:
            del by_kind[kind]
    return chosen


def _execute(scene: Scene, action: Action) -> str:
    """Plan the best parameter choices in turn and run the first that plans: the status."""
    status = NO_PARAMETERS
    for params in candidates(scene.scene_graph(), action)[:MAX_PARAMS]:
        plan = plan_primitive(scene, params)
        if isinstance(plan, PlanFailure):
            status = str(plan.status)
            continue
        return str(execute(scene, params, plan=plan).status)
    return status


def record_state(scene: Scene, seed: int, index: int) -> dict:
    """Stage one drawn state and execute its chosen actions: the logged result."""
    state = draw_reach_state(seed, index)
    for o in scene.objects:
        scene.remove_object(o)
    for o in state.objects:
        scene.add_object(o)
    rng = random.Random(f"reach-actions-{seed}-{index}")
    scene.rng = np.random.default_rng(rng.getrandbits(64))
    if not stage(scene, state, rng):
        return {"staged": False}
    snapshot, held = scene.snapshot(), scene.robot.held_body
    trials = []
    for action in choose_actions(state, rng):
        # constraints are not part of a saved state: a grasp made by the last trial is let go
        scene.robot.detach()
        scene.restore(snapshot)
        if held is not None:
            scene.robot.attach(held)
        status = _execute(scene, action)
        mapping = map_symbols(scene.scene_graph())
        after = None if mapping.anomalies else state_json(mapping.state)
        trials.append({"action": str(action), "status": status, "after": after})
    scene.bc.removeState(snapshot)
    scene.robot.detach()
    return {
        "staged": True,
        "objects": list(state.objects),
        "state": state_json(state),
        "trials": trials,
    }


@dataclass(frozen=True)
class ReachChunk:
    seed: int
    chunk: int

    @property
    def key(self) -> str:
        return f"{self.seed}/{self.chunk}"


def run_reach_chunk(chunk: ReachChunk) -> dict:
    """A chunk of consecutive states in a fresh scene: the worker entry point."""
    start = chunk.chunk * STATES_PER_CHUNK
    with Scene((), seed=chunk.seed) as scene:
        return {
            "states": [
                record_state(scene, chunk.seed, i) for i in range(start, start + STATES_PER_CHUNK)
            ]
        }


@dataclass(frozen=True)
class ReachSummary:
    states: int
    staged: int
    trials: int
    by_status: dict[str, int]
    seconds: float


def collect_reach(
    out: Path,
    states: int,
    seed: int = 0,
    workers: int = 2,
    ray: str | None = None,
    on_chunk: Callable[[], None] | None = None,
) -> ReachSummary:
    """Collect `states` staged states (rounded up to whole chunks) into the run folder `out`;
    a rerun keeps what was logged and runs only the missing chunks."""
    if states < 1:
        raise InvalidInputError(f"--states {states}: need at least one")
    start = time.perf_counter()
    chunks = [ReachChunk(seed, c) for c in range(-(-states // STATES_PER_CHUNK))]
    config = {"kind": "reach", "seed": seed, "actions": ACTIONS_PER_STATE, "params": MAX_PARAMS}
    results = run_items(
        run_reach_chunk,
        chunks,
        key=lambda c: c.key,
        run_dir=out,
        config=config,
        workers=workers,
        ray=ray,
        on_result=on_chunk and (lambda _: on_chunk()),
    )
    rows = [r for result in results for r in result["states"]]
    trials: list[WorldTrial] = [t for r in rows for t in trials_of(r)]
    return ReachSummary(
        len(rows),
        sum(bool(r.get("staged")) for r in rows),
        len(trials),
        dict(Counter(t.status for t in trials)),
        time.perf_counter() - start,
    )
