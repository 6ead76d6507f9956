"""What both PDDLStream-style algorithms (`agents/incremental.py`, `agents/focused.py`) share:
the problem so far (objects, certified facts, the streams' progress), the observed scene as its
first facts, what the goal tells the goal-directed streams, and a Fast Downward plan turned back
into the project's actions and parameters."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol

import numpy as np

from hsgplan.agents.streams import PoseTable, PoseValue, PushValue, observed_pose
from hsgplan.domain.actions import Action, Pick, Place, Push
from hsgplan.domain.goals import Goal
from hsgplan.domain.objects import EntityKind
from hsgplan.domain.parameters import PickParams, PlaceParams, PrimitiveParams, PushParams
from hsgplan.domain.predicates import Predicate
from hsgplan.domain.scene import World
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.symbolic.stream_pddl import Fact

if TYPE_CHECKING:
    from hsgplan.agents.streams import StreamWorld


@dataclass(frozen=True)
class StreamStep:
    action: Action
    params: PrimitiveParams


@dataclass(frozen=True)
class StreamPlan:
    """What a planning call came to: the steps (None when no plan was found), its seconds at
    the task and motion levels, the levels it went through and how many facts the last
    problem held."""

    steps: tuple[StreamStep, ...] | None
    task_seconds: float
    motion_seconds: float
    levels: int
    facts: int
    note: str = ""


class StreamPlanner(Protocol):
    """A PDDLStream-style algorithm: a plan from the observed scene to the goal, with the
    parameters that failed in this very scene (`banned`) left out."""

    def plan(
        self,
        sg: GeometricSceneGraph,
        state: SymbolicSceneGraph,
        goal: Goal,
        world: StreamWorld,
        seed: int = 0,
        banned: frozenset[PrimitiveParams] = frozenset(),
    ) -> StreamPlan: ...


@dataclass
class StreamProblem:
    """The objects and certified facts so far, and the streams' progress."""

    rng: np.random.Generator
    world: World  # the observed scene's: its surfaces, shelves and names
    facts: dict[Fact, None] = field(default_factory=dict)  # ordered, without repeats
    poses: dict[str, PoseValue] = field(default_factory=dict)
    table: PoseTable = field(default_factory=PoseTable)  # the poses' geometry, in that order
    level: dict[str, int] = field(default_factory=dict)  # pose or grasp name -> its level
    grasps: dict[str, str] = field(default_factory=dict)  # object -> its grasp's name
    confs: list[str] = field(default_factory=list)
    pushes: dict[str, PushValue] = field(default_factory=dict)
    observed: dict[str, str] = field(default_factory=dict)  # object -> its observed pose
    bins: dict[tuple[str, str], list[tuple[int, int]]] = field(default_factory=dict)
    push_streams: dict[tuple[str, str], Iterator] = field(default_factory=dict)
    done: set[tuple[str, ...]] = field(default_factory=set)  # stream instances evaluated
    below: dict[str, str] = field(default_factory=dict)  # stacked pose -> the pose under it
    stacks: dict[str, set[str]] | None = None  # b -> what stack-pose puts on b; None: anything
    sites: dict[str, str] = field(default_factory=dict)  # o -> what o's On goal puts it on
    shelves: dict[str, str] = field(default_factory=dict)  # o -> the shelf o's In goal names

    def add(self, *fact: str) -> None:
        self.facts[fact] = None

    def new_pose(self, value: PoseValue, level: int, below: str = "") -> str:
        """A pose object with its certified facts and its collision tests against every other
        object's poses; `below`: the pose of the object a stacked pose rests on."""
        name = f"p{len(self.poses)}"
        names = list(self.poses)
        for i in self.table.collisions(value):
            other = names[i]
            self.add("collide", value.obj, name, self.poses[other].obj, other)
            self.add("collide", self.poses[other].obj, other, value.obj, name)
        self.table.add(value)
        self.poses[name] = value
        self.level[name] = level
        self.add("pose", value.obj, name)
        if value.relation == "stacked":
            self.below[name] = below
            self.add("stacked", value.obj, name, value.support, below)
        elif value.relation in ("supported", "inside"):
            self.add(value.relation, value.obj, name, value.support)
        return name

    def new_conf(self) -> str:
        self.confs.append(f"q{len(self.confs)}")
        return self.confs[-1]


def aim(prob: StreamProblem, goal: Goal, goal_stacks: bool) -> None:
    """What the goal-restricted streams (`goal_stacks`, `goal_places`) take from the goal:
    where its On and In literals put each object, and what it stacks on what."""
    for lit in goal.literals:
        if lit.positive and lit.predicate is Predicate.ON:
            prob.sites[lit.subject] = lit.args[1]
        elif lit.positive and lit.predicate is Predicate.IN:
            prob.shelves[lit.subject] = lit.args[1]
    if goal_stacks:
        prob.stacks = {}
        for o, x in prob.sites.items():
            if goal.world.kind_of(x) is EntityKind.OBJECT:
                prob.stacks.setdefault(x, set()).add(o)


def goal_surface(prob: StreamProblem, obj: str) -> str | None:
    """The surface the goal puts an object on, or the prepush region of the shelf its In goal
    names; None when the goal places it nowhere."""
    if obj in prob.shelves:
        return prob.world.shelves[prob.shelves[obj]].prepush
    return prob.sites.get(obj)


def stackable(prob: StreamProblem, below: PoseValue, objects: list[str]) -> list[str]:
    """The objects stack-pose puts on the pose `below`: with `goal_stacks`, those the goal
    puts on its object, and only where that object's own On goal (if any) would have it."""
    if prob.stacks is None:
        return objects
    site = prob.sites.get(below.obj)
    if site is not None and below.support != site:
        return []
    return sorted(prob.stacks.get(below.obj, ()))


def add_grasp(prob: StreamProblem, obj: str, level: int) -> str:
    g = f"g_{obj}"
    prob.grasps[obj] = g
    prob.level[g] = level
    prob.add("grasp", obj, g)
    return g


def initial_problem(sg: GeometricSceneGraph, state: SymbolicSceneGraph, rng) -> StreamProblem:
    """Level 0: the observed poses (objects below first, so a stacked pose names the pose
    under it), the grasp of a held object, and whether the hand is empty."""
    prob = StreamProblem(rng, state.world)
    held = state.held()
    if held is None:
        prob.add("handempty")
    else:
        prob.add("atgrasp", held, add_grasp(prob, held, 0))
    pending = [o for o in state.objects if o != held]
    while pending:
        for o in list(pending):
            loc = state.location(o)
            x = loc.args[1] if len(loc.args) > 1 else ""
            if state.world.kind_of(x) is EntityKind.OBJECT and x in pending:
                continue  # its support first
            pending.remove(o)
            if loc.predicate is Predicate.IN:
                value = observed_pose(o, sg.pose(o), "inside", x, prob.world)
            elif x in state.world.surfaces:
                value = observed_pose(o, sg.pose(o), "supported", x, prob.world)
            elif x in prob.observed:
                value = observed_pose(o, sg.pose(o), "stacked", x, prob.world)
            else:
                value = observed_pose(o, sg.pose(o), "loose", "", prob.world)
            prob.observed[o] = prob.new_pose(value, 0, below=prob.observed.get(x, ""))
            prob.add("atpose", o, prob.observed[o])
    return prob


def start_problem(
    sg: GeometricSceneGraph, state: SymbolicSceneGraph, goal: Goal, seed: int, goal_stacks: bool
) -> StreamProblem:
    """The observed scene as a problem's first facts (`initial_problem`), its samplers drawing
    from `seed`, and what the goal tells the goal-directed streams (`aim`)."""
    prob = initial_problem(sg, state, np.random.default_rng(seed))
    aim(prob, goal, goal_stacks)
    return prob


def pddl_objects(prob: StreamProblem, state: SymbolicSceneGraph) -> dict[str, list[str]]:
    return {
        "obj": list(state.objects),
        "surface": [*state.world.regions, *state.world.shelves],
        "pose": list(prob.poses),
        "grasp": list(prob.grasps.values()),
        "conf": prob.confs,
        "push": list(prob.pushes),
    }


def params_at(prob: StreamProblem, p: str) -> PrimitiveParams | None:
    """The parameters that, in the observed scene, take the object up from pose p (its
    observed pose) or put it down there; None for a pose no such parameters name."""
    v = prob.poses[p]
    if prob.observed.get(v.obj) == p:
        return PickParams(v.obj)
    if v.relation == "stacked":
        # a place on an object puts it on that object where it stands now
        now = prob.observed.get(v.support) == prob.below[p]
        return PlaceParams(v.obj, v.support) if now else None
    if v.relation == "supported" and v.bins is not None:
        return PlaceParams(v.obj, v.support, *v.bins)
    return None


def decode_step(prob: StreamProblem, name: str, args: tuple[str, ...]) -> StreamStep:
    """A step of Fast Downward's plan as the project's action and parameters."""
    if name == "pick":
        return StreamStep(Pick(args[0]), PickParams(args[0]))
    if name == "place":
        o, p, s = args[:3]
        return StreamStep(Place(o, s), PlaceParams(o, s, *prob.poses[p].bins))
    if name == "stack":
        o, _, b = args[:3]
        return StreamStep(Place(o, b), PlaceParams(o, b))
    if name == "push":
        o, _, s, u = args[:4]
        params: PushParams = prob.pushes[u].params
        return StreamStep(Push(o, s), params)
    raise ValueError(f"unknown action '{name}' in a plan")
