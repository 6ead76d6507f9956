"""`hsgplan collect reach`: primitives executed in the simulated world from staged symbolic
states, the self-supervised labels of f_reach (format: `data/world_trials.py`).

Nothing here asks the hand-written rules (transition model, feasibility, PDDL) whether an action
applies: a state is drawn, staged under physics, and each chosen action is planned and executed
from it; what the world shows afterwards is recorded. The world refuses in its own ways: a pick
while the hand holds another object or a place of an object not held is invalid, a place on a
full surface finds no free spot, a push into a full interior finds no free slot.

States (`draw_reach_state`), from `random.Random(f"reach-{seed}-{index}")`:
- n objects, n uniform in 2..8, drawn as the goal generator draws them (distinct types up to
  six, the six and uniform duplicates beyond);
- with probability `P_HOLD` (1/2) one of them, uniform, is in the hand (clear, not inside);
- with probability `P_CROWDED_STATE` (5/6) one place is to be crowded, uniform among the
  world's shelf tops, prepush regions and shelf interiors;
- the others, in uniformly shuffled order, go: to the crowded place with probability `P_CROWD`
  while it has room (and, for an interior, the object fits); otherwise onto a bare object that
  can carry it with probability `P_STACK` (towers of at most the world's `max_tower_levels`);
  otherwise to a kind of place uniform among the open space, a shelf top, a prepush region and
  a shelf interior (those with room for it), and within the kind uniformly.
Every state is within the world's limits (capacities, towers, fit), counted with `Room`.

Per staged state, up to `ACTIONS_PER_STATE` distinct actions among those the heuristic names for
the state's candidate literals (`planning.heuristic`) are executed, each from the staged state
again: a stratum uniform among those present (pick, push, a place of the held object on a
surface, on an object, a place of an object not held), then the action uniform within it. An
action's parameter choices (`motion.sampler.candidates`, best first) are planned in turn, at
most `MAX_PARAMS`, and the first that plans is executed.

The states are drawn and staged in the kitchen, or in the world of a scene file (`scene`): its
object types, shelves and regions; given a folder of scene files, state k in the k-th. A work
item is one state, `(seed, index)`; each worker process stages its states in one scene per
world (a new physics client costs more than staging and running a state). Staging resets
everything a state's trials depend on, so a state's row does not depend on what its process ran
before.
"""

from __future__ import annotations

import functools
import random
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hsgplan.data.world_trials import NO_PARAMETERS, UNSTAGED, WorldTrial, state_row, trials_of
from hsgplan.domain.actions import Action, Place
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.objects import draw_objects
from hsgplan.domain.predicates import Literal, in_grasp, inside, on
from hsgplan.domain.room import Room
from hsgplan.domain.scene import OPEN_SPACE, World
from hsgplan.domain.scene_file import default_world, read_world, read_worlds
from hsgplan.motion.sampler import candidates
from hsgplan.planning.heuristic import action_for, candidate_literals
from hsgplan.runner.items import run_items
from hsgplan.runner.run_folder import claim, logged_rows
from hsgplan.scene_graph.symbol_mapping import map_symbols
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.motion_plans import PlanFailure, plan_primitive
from hsgplan.sim.primitives import execute
from hsgplan.sim.scene import Scene
from hsgplan.sim.staging import stage

ACTIONS_PER_STATE = 6
MAX_PARAMS = 5  # parameter choices planned, best first, before the action counts as refused
MIN_OBJECTS, MAX_OBJECTS = 2, 8
P_HOLD, P_CROWDED_STATE, P_CROWD, P_STACK = 0.5, 5 / 6, 0.85, 0.35


@dataclass(frozen=True)
class _Places:
    """A world's places, as the state distribution groups them."""

    tops: tuple[str, ...]
    prepush: tuple[str, ...]
    # a place to crowd: ("on", surface) or ("in", shelf)
    crowdable: tuple[tuple[str, str], ...]

    @staticmethod
    def of(world: World) -> _Places:
        tops = tuple(world.shelves)
        prepush = tuple(r for r in world.regions if r != OPEN_SPACE)
        inside_ = tuple(("in", s) for s in world.interior_capacity)
        return _Places(tops, prepush, (*(("on", s) for s in tops + prepush), *inside_))


def draw_reach_state(seed: int, index: int, world: World) -> SymbolicSceneGraph:
    """A state to stage in `world` (the distribution is in the module docstring)."""
    rng = random.Random(f"reach-{seed}-{index}")
    places = _Places.of(world)
    objects = draw_objects(rng.randint(MIN_OBJECTS, MAX_OBJECTS), rng, world)
    order = list(objects)
    rng.shuffle(order)
    literals = [in_grasp(order.pop())] if rng.random() < P_HOLD else []
    crowd = rng.choice(places.crowdable) if rng.random() < P_CROWDED_STATE else None
    room = Room.left(world=world)
    literals += [_put(o, room, crowd, places, rng) for o in order]
    return SymbolicSceneGraph.from_literals(objects, literals, limits=False, world=world)


def _put(
    o: str, room: Room, crowd: tuple[str, str] | None, places: _Places, rng: random.Random
) -> Literal:
    if crowd is not None:
        how, where = crowd
        free = room.free_interiors(o) if how == "in" else room.free_tops()
        if where in free and rng.random() < P_CROWD:
            return _count(o, room, how, where)
    if room.bases() and rng.random() < P_STACK:
        return _count(o, room, "on", rng.choice(room.bases()))
    kinds = [("on", room.free_tops(k)) for k in ((OPEN_SPACE,), places.tops, places.prepush)]
    kinds.append(("in", room.free_interiors(o)))
    how, free = rng.choice([(h, p) for h, p in kinds if p])
    return _count(o, room, how, rng.choice(free))


def _count(o: str, room: Room, how: str, where: str) -> Literal:
    if how == "in":
        room.put_inside(o, where)
        return inside(o, where)
    room.put_on(o, where)
    return on(o, where)


def choose_actions(
    state: SymbolicSceneGraph, rng: random.Random, k: int = ACTIONS_PER_STATE
) -> list[Action]:
    """Up to k distinct actions the heuristic names in this state, stratified: pick, push,
    a place of the held object on a surface, on an object, and a place of an object not held.
    Places of an object not in the hand are most of what the heuristic names and the world
    refuses them all alike; the held object's places onto a full surface are the rare
    questions, so they get strata of their own."""
    named = sorted({action_for(lit, state) for lit in candidate_literals(state)} - {None}, key=str)
    by_kind: dict[str, list[Action]] = {}
    for a in named:
        by_kind.setdefault(_stratum(a, state), []).append(a)
    chosen: list[Action] = []
    while by_kind and len(chosen) < k:
        kind = rng.choice(sorted(by_kind))
        chosen.append(by_kind[kind].pop(rng.randrange(len(by_kind[kind]))))
        if not by_kind[kind]:
            del by_kind[kind]
    return chosen


def _stratum(action: Action, state: SymbolicSceneGraph) -> str:
    if not isinstance(action, Place):
        return type(action).__name__
    if state.held() != action.obj:
        return "place not held"
    return "place on surface" if action.target in state.world.surfaces else "place on object"


def execute_action(scene: Scene, action: Action, max_params: int = MAX_PARAMS) -> tuple[str, bool]:
    """Plan the best parameter choices in turn and execute the first that plans: its status and
    True; when none plans, nothing moves: the last planning failure's status (`no_parameters`
    without a choice) and False."""
    status = NO_PARAMETERS
    for params in candidates(scene.scene_graph(), action)[:max_params]:
        plan = plan_primitive(scene, params)
        if isinstance(plan, PlanFailure):
            status = str(plan.status)
            continue
        return str(execute(scene, params, plan=plan).status), True
    return status, False


def run_trials(
    scene: Scene,
    state: SymbolicSceneGraph,
    actions: list[Action],
    rng: random.Random,
    max_params: int = MAX_PARAMS,
) -> dict:
    """Stage `state` in the scene (its objects replace the scene's) and execute each action
    from it: the logged row, `UNSTAGED` when the state could not be staged."""
    for o in scene.objects:
        scene.remove_object(o)
    for o in state.objects:
        scene.add_object(o)
    scene.rng = np.random.default_rng(rng.getrandbits(64))
    if not stage(scene, state, rng):
        return dict(UNSTAGED)
    # the next state is staged over whatever the last trial left
    return state_row(state, trials_from_here(scene, state, actions, max_params, put_back=False))


def trials_from_here(
    scene: Scene,
    state: SymbolicSceneGraph,
    actions: list[Action],
    max_params: int = MAX_PARAMS,
    put_back: bool = True,
) -> list[WorldTrial]:
    """Execute each action from the scene as it stands, which shows `state`; with `put_back`,
    the scene is left as it was (the hand's grasp included), else with the hand empty."""
    robot = scene.robot
    snapshot, grip = scene.snapshot(), robot.grip()
    kept = {k: getattr(robot, k) for k in ("closing", "released")}
    trials = []
    for action in actions:
        scene.back_to(snapshot, grip)  # the hand's hold is no part of the saved state
        status, executed = execute_action(scene, action, max_params)
        after: SymbolicSceneGraph | None = state
        if executed:
            mapping = map_symbols(scene.scene_graph())
            after = None if mapping.anomalies else mapping.state
        trials.append(WorldTrial(state, action, status, after))
    if put_back:
        scene.back_to(snapshot, grip)
        for k, v in kept.items():
            setattr(robot, k, v)
    scene.bc.removeState(snapshot)
    if not put_back:
        robot.detach()
    return trials


def record_reach_state(
    scene: Scene,
    seed: int,
    index: int,
    actions_per_state: int = ACTIONS_PER_STATE,
    max_params: int = MAX_PARAMS,
) -> dict:
    """Draw state `index` of `seed` in the scene's world, stage it and execute its chosen
    actions: the logged row."""
    state = draw_reach_state(seed, index, scene.world)
    actions = choose_actions(
        state, random.Random(f"reach-actions-{seed}-{index}"), actions_per_state
    )
    return run_trials(
        scene, state, actions, random.Random(f"reach-stage-{seed}-{index}"), max_params
    )


@dataclass(frozen=True)
class ReachItem:
    """One state to stage: the unit of work and of what an interruption loses."""

    seed: int
    index: int
    actions_per_state: int = ACTIONS_PER_STATE
    max_params: int = MAX_PARAMS
    scene: str | None = None  # a scene file's path (None: the kitchen)

    @property
    def key(self) -> str:
        return f"{self.seed}/{self.index}"


@functools.cache
def _process_scene(scene: str | None) -> Scene:
    world = default_world() if scene is None else read_world(Path(scene))
    return Scene((), visuals=False, world=world)


def run_reach_item(item: ReachItem) -> dict:
    """The worker entry point (pool or Ray): one state, in this process's scene of its world."""
    return record_reach_state(
        _process_scene(item.scene), item.seed, item.index, item.actions_per_state, item.max_params
    )


@dataclass(frozen=True)
class ReachSummary:
    states: int  # states asked for, logged before or run now
    staged: int
    trials: int
    by_status: dict[str, int]
    ran: int  # states run by this call (the others were logged)
    seconds: float


def collect_reach(
    out: Path,
    states: int,
    seed: int = 0,
    workers: int = 2,
    ray: str | None = None,
    on_item: Callable[[dict], None] | None = None,
    *,
    actions_per_state: int = ACTIONS_PER_STATE,
    max_params: int = MAX_PARAMS,
    scene: Path | None = None,
) -> ReachSummary:
    """Stage states 0..`states`-1 of `seed` and execute primitives from each, logged to the run
    folder `out`. A rerun keeps what is logged and runs only the missing states, so `states`
    may grow; a folder made with other settings (the scene file among them) is refused.
    `on_item` sees each state's row. `scene`: stage them in this scene file's world, or round a
    folder of them, state k in the k-th file (default: the kitchen); the path is kept in the
    folder's configuration, where readers find it (`evaluation.reach_eval.collection_worlds`)."""
    for name, value in (
        ("--states", states),
        ("actions per state", actions_per_state),
        ("parameter choices", max_params),
    ):
        if value < 1:
            raise InvalidInputError(f"{name} {value}: need at least one")
    start = time.perf_counter()
    config = {
        "kind": "reach",
        "unit": "state",
        "seed": seed,
        "actions_per_state": actions_per_state,
        "max_params": max_params,
    }
    worlds: dict[str | None, World] = {None: default_world()}
    if scene is not None:  # a kitchen collection records no scene, as before scenes were given
        worlds = {str(p): w for p, w in read_worlds(scene).items()}
        config["scene"] = str(scene)
    files, in_turn = list(worlds), list(worlds.values())
    refusal = (
        f"'{out}' holds a reach collection made with other settings (seed, "
        "actions per state, parameter choices, scene, or an older layout); use another --out"
    )
    items = [
        ReachItem(seed, i, actions_per_state, max_params, files[i % len(files)])
        for i in range(states)
    ]
    rows, ran = run_collection(out, run_reach_item, items, config, refusal, workers, ray, on_item)
    trials: list[WorldTrial] = [
        t for i, row in enumerate(rows) for t in trials_of(row, in_turn[i % len(in_turn)])
    ]
    return ReachSummary(
        states,
        sum(row.get("staged", True) is not False for row in rows),
        len(trials),
        dict(sorted(Counter(t.status for t in trials).items())),
        ran,
        time.perf_counter() - start,
    )


def run_collection(
    out: Path, work, items: list, config: dict, refusal: str, workers: int, ray: str | None, on_item
) -> tuple[list[dict], int]:
    """Every item's row of a collection of executed primitives in the run folder `out` (made
    with `config`, else refused with `refusal`), and how many of them ran now: those logged
    before are read back."""
    # claimed here first for a refusal that says what differs, and to count what is logged
    claim(out, "reach", config, refusal)
    logged = {str(row.get("key")) for row in logged_rows(out) if isinstance(row, dict)}
    rows = run_items(
        work,
        items,
        key=lambda item: item.key,
        run_dir=out,
        kind="reach",
        config=config,
        workers=workers,
        ray=ray,
        on_result=on_item,
    )
    return rows, sum(item.key not in logged for item in items)
