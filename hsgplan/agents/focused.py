"""PDDLStream's focused algorithm (Garrett et al., 2020) over the kitchen-storage streams: plan
first with optimistic stream outputs, then evaluate only the streams the plan uses.

The streams and the domain are the incremental algorithm's (`agents/streams.py`,
`symbolic/stream_pddl.py`). Where the incremental algorithm evaluates every stream on every
input at each level, the focused one evaluates nothing before it has a plan:

1. The optimistic problem: the certified facts so far, and for every stream instance not yet
   exhausted an optimistic output (a new object named `x...`) with the facts the stream would
   certify: place-pose(o, s) a pose of o on s, stack-pose(o, pb) o on the pose pb, kin(o, p)
   an arm configuration for the grasp at p, push(o, p, shelf) a push and the pose inside the
   shelf it ends at. Optimistic outputs are inputs of further instances up to the problem's
   complexity (an output's is one more than its inputs' largest; certified objects have 0).
   Optimistic poses collide with nothing: the collision test is evaluated with the pose.
2. Fast Downward plans over it. A plan that names only certified objects is returned.
3. Otherwise the plan's stream plan (the instances that made the optimistic objects it names,
   and theirs) is evaluated in order, each optimistic input bound to the certified output that
   replaced it: a sampler gives its next sample, the collision test runs against every
   certified pose, and what fails (no inverse kinematics, no push left) certifies nothing.
   Then it plans again, with the new facts.
4. No plan at a complexity: the next complexity, up to `max_complexity`.

PDDLStream's adaptive variant also keeps the skeletons of earlier plans to come back to; this
one replans from the facts, which the binding of each evaluated stream plan makes cheap here
(a plan's samplers are few and mostly certified by the first sample).

Times: the task level is Fast Downward's (writing each problem, translation and search), the
motion level the streams'.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterator
from dataclasses import dataclass, field

from hsgplan.agents.stream_problem import (
    StreamPlan,
    StreamProblem,
    add_grasp,
    decode_step,
    goal_surface,
    params_at,
    pddl_objects,
    stackable,
    start_problem,
)
from hsgplan.agents.streams import (
    PoseValue,
    StreamWorld,
    bin_order,
    push_shelf,
    stack_pose,
    surface_pose,
)
from hsgplan.domain.goals import Goal
from hsgplan.domain.parameters import PrimitiveParams
from hsgplan.planning.fast_downward import NoPlanError, solve_pddl
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.symbolic.stream_pddl import DOMAIN, STREAM_SEARCH, Fact, problem_text


@dataclass(frozen=True)
class FocusedConfig:
    """Args:
    max_complexity: the largest complexity of an optimistic object before it gives up.
    time_limit_s: seconds (streams and Fast Downward together) before it gives up.
    fd_timeout_s: seconds one Fast Downward call may take.
    disabled_timeout_s: seconds a call may take while samplers are disabled: a search over the
        samples so far, which Fast Downward can rarely prove has no plan (its heuristic does
        not see collisions), gives way to more samples this soon.
    max_facts: facts an optimistic problem may hold; past them it gives up.
    goal_stacks: stack-pose(o, b, pb) only for the goal's On(o, b) (`agents/incremental.py`).
    goal_places: place-pose(o, s) only on the open space and o's goal surface.
    """

    max_complexity: int = 6
    time_limit_s: float = 900.0
    fd_timeout_s: float = 10.0
    disabled_timeout_s: float = 2.0
    max_facts: int = 1_000_000
    goal_stacks: bool = False
    goal_places: bool = False


# The `stream-focused-goal` baseline's streams: the goal-directed ones of `stream-goal`.
FOCUSED_GOAL_DIRECTED = FocusedConfig(goal_stacks=True, goal_places=True)

Instance = tuple[str, ...]  # ("place", o, s) | ("stack", o, pb) | ("kin", p) | ("push", p, shelf)


@dataclass
class _Optimistic:
    """One optimistic problem: its facts beyond the certified ones, and for every optimistic
    object the instance that makes it and its complexity."""

    facts: list[Fact] = field(default_factory=list)
    maker: dict[str, Instance] = field(default_factory=dict)
    outputs: dict[Instance, list[str]] = field(default_factory=dict)  # in the order made
    poses: dict[str, PoseValue] = field(default_factory=dict)
    complexity: dict[str, int] = field(default_factory=dict)
    objects: dict[str, list[str]] = field(default_factory=dict)  # PDDL type -> names

    def new(self, kind: str, instance: Instance, level: int) -> str:
        name = f"x{kind}{len(self.maker)}"
        self.maker[name] = instance
        self.outputs.setdefault(instance, []).append(name)
        self.complexity[name] = level
        self.objects.setdefault(kind, []).append(name)
        return name


class FocusedPlanner:
    """Args:
    config: the complexity and time limits and which streams are goal-directed
        (`FocusedConfig`).
    """

    def __init__(self, config: FocusedConfig | None = None) -> None:
        self.config = config or FocusedConfig()

    def plan(
        self,
        sg: GeometricSceneGraph,
        state: SymbolicSceneGraph,
        goal: Goal,
        world: StreamWorld,
        seed: int = 0,
        banned: frozenset[PrimitiveParams] = frozenset(),
    ) -> StreamPlan:
        """A plan from the observed scene to the goal; `banned`: parameters that failed in
        this very scene, whose stream outputs are left out."""
        cfg, start = self.config, time.perf_counter()
        task = motion = 0.0
        t0 = time.perf_counter()
        prob = start_problem(sg, state, goal, seed, cfg.goal_stacks)
        for o in state.objects:
            if o not in prob.grasps:
                add_grasp(prob, o, 0)
        exhausted: set[Instance] = set()  # samplers with no sample left
        disabled: set[Instance] = set()  # samplers evaluated since the last plan not found
        pushes: dict[Instance, Iterator] = {}
        motion += time.perf_counter() - t0
        complexity = 0
        while complexity <= cfg.max_complexity:
            if time.perf_counter() - start > cfg.time_limit_s:
                return StreamPlan(None, task, motion, complexity, len(prob.facts), "time limit")
            t0 = time.perf_counter()
            opt = _optimistic(prob, state, complexity, exhausted | disabled, cfg)
            size = len(prob.facts) + len(opt.facts)
            if size > cfg.max_facts:
                return StreamPlan(None, task, motion, complexity, size, "too many facts")
            objects = pddl_objects(prob, state)
            for kind, names in opt.objects.items():
                objects[kind] = objects[kind] + names
            try:
                text = problem_text(objects, [*prob.facts, *opt.facts], goal)
                limit = cfg.disabled_timeout_s if disabled else cfg.fd_timeout_s
                found = solve_pddl(DOMAIN, text, STREAM_SEARCH, limit)
            except NoPlanError:
                task += time.perf_counter() - t0
                if disabled:
                    disabled.clear()
                else:
                    complexity += 1
                continue
            task += time.perf_counter() - t0
            t0 = time.perf_counter()
            named = {a for _, args in found.steps for a in args if a in opt.maker}
            if not named:
                steps = tuple(decode_step(prob, name, args) for name, args in found.steps)
                motion += time.perf_counter() - t0
                return StreamPlan(steps, task, motion, complexity, len(prob.facts))
            disabled |= _evaluate(prob, opt, named, world, banned, exhausted, pushes)
            motion += time.perf_counter() - t0
        return StreamPlan(None, task, motion, cfg.max_complexity, len(prob.facts), "complexity")


def _optimistic(
    prob: StreamProblem,
    state: SymbolicSceneGraph,
    limit: int,
    off: set[Instance],
    cfg: FocusedConfig,
) -> _Optimistic:
    """Every stream instance not yet evaluated on certified and optimistic inputs, with an
    optimistic output, up to complexity `limit`; samplers in `off` (exhausted or disabled)
    offer none."""
    opt = _Optimistic()
    if limit < 1:
        return opt
    objects = list(state.objects)
    queue: list[tuple[str, PoseValue, int]] = [(p, v, 0) for p, v in prob.poses.items()]
    for o in objects:
        for s in _surfaces(prob, o, cfg):
            inst = ("place", o, s)
            if inst in off:
                continue
            p = opt.new("pose", inst, 1)
            value = _sketch(surface_pose(o, s, (0, 0), prob.world))
            opt.poses[p] = value
            opt.facts += [("pose", o, p), ("supported", o, p, s)]
            queue.append((p, value, 1))
    while queue:
        p, v, level = queue.pop(0)
        if level + 1 > limit:
            continue
        certified = p in prob.poses
        if v.relation != "inside" and not (certified and ("kin", p) in prob.done):
            q = opt.new("conf", ("kin", p), level + 1)
            opt.facts.append(("kin", v.obj, p, prob.grasps[v.obj], q))
        for o in stackable(prob, v, objects):
            if certified and ("stack", o, p) in prob.done:
                continue
            value = stack_pose(o, v)
            if value is None:
                continue
            above = opt.new("pose", ("stack", o, p), level + 1)
            opt.poses[above] = _sketch(value)
            opt.facts += [("pose", o, above), ("stacked", o, above, v.obj, p)]
            queue.append((above, opt.poses[above], level + 1))
        shelf = push_shelf(v)
        if shelf is not None and ("push", p, shelf) not in off:
            inst = ("push", p, shelf)
            u = opt.new("push", inst, level + 1)
            end = opt.new("pose", inst, level + 1)
            q = opt.new("conf", inst, level + 1)
            opt.poses[end] = PoseValue(
                v.obj, math.nan, math.nan, v.z, v.yaw, "inside", shelf, world=v.world
            )
            opt.facts += [("pose", v.obj, end), ("inside", v.obj, end, shelf)]
            opt.facts.append(("pushable", v.obj, p, shelf, u, end, q))
    return opt


def _sketch(value: PoseValue) -> PoseValue:
    """An optimistic pose: where on the surface is not known until it is sampled."""
    return PoseValue(
        value.obj,
        math.nan,
        math.nan,
        value.z,
        value.yaw,
        value.relation,
        value.support,
        world=value.world,
    )


def _surfaces(prob: StreamProblem, obj: str, cfg: FocusedConfig) -> list[str]:
    goal = goal_surface(prob, obj)
    if not cfg.goal_places or goal is None:
        return list(prob.world.surfaces)
    return ["open_space"] + ([goal] if goal in prob.world.surfaces and goal != "open_space" else [])


def _evaluate(
    prob: StreamProblem,
    opt: _Optimistic,
    named: set[str],
    world: StreamWorld,
    banned: frozenset[PrimitiveParams],
    exhausted: set[Instance],
    pushes: dict[Instance, Iterator],
) -> set[Instance]:
    """The stream plan of the optimistic objects `named`: their instances and those of their
    optimistic inputs, in order of complexity, each input bound to what replaced it; the
    samplers it evaluated."""
    plan: set[Instance] = set()
    todo = [opt.maker[n] for n in named]
    while todo:
        inst = todo.pop()
        if inst in plan:
            continue
        plan.add(inst)
        todo += [opt.maker[a] for a in inst[1:] if a in opt.maker]
    level = {inst: opt.complexity[opt.outputs[inst][0]] for inst in plan}
    bound: dict[str, str] = {}
    samplers: set[Instance] = set()
    for inst in sorted(plan, key=lambda i: (level[i], i)):
        args = tuple(bound.get(a, a) for a in inst[1:])
        if any(a in opt.maker for a in args):
            continue  # an input's stream certified nothing
        made = _run(prob, (inst[0], *args), world, banned, exhausted, pushes)
        bound.update(zip(opt.outputs[inst], made, strict=False))
        if inst[0] in ("place", "push"):
            samplers.add((inst[0], *args))
    return samplers


def _run(
    prob: StreamProblem,
    inst: Instance,
    world: StreamWorld,
    banned: frozenset[PrimitiveParams],
    exhausted: set[Instance],
    pushes: dict[Instance, Iterator],
) -> list[str]:
    """One evaluation of a stream instance on certified inputs: the certified objects it made,
    in the order of its optimistic outputs ([] when it certified nothing)."""
    kind = inst[0]
    if kind == "place":
        _, o, s = inst
        order = prob.bins.setdefault((o, s), bin_order(o, s, prob.rng, prob.world))
        if not order:
            exhausted.add(inst)
            return []
        p = prob.new_pose(surface_pose(o, s, order.pop(0), prob.world), 1)
        if not order:
            exhausted.add(inst)
        return [p]
    if kind == "stack":
        _, o, pb = inst
        prob.done.add(inst)
        value = stack_pose(o, prob.poses[pb])
        return [] if value is None else [prob.new_pose(value, 1, below=pb)]
    if kind == "kin":
        p = inst[1]
        prob.done.add(inst)
        v = prob.poses[p]
        params = params_at(prob, p)
        if (params is not None and params in banned) or world.kin(v) is None:
            return []
        q = prob.new_conf()
        prob.add("kin", v.obj, p, prob.grasps[v.obj], q)
        return [q]
    _, p, shelf = inst
    stream = pushes.setdefault(inst, world.pushes(prob.poses[p], shelf))
    for push, _ in stream:
        if push.params in banned:
            continue
        u = f"u{len(prob.pushes)}"
        prob.pushes[u] = push
        end = prob.new_pose(push.end, 1)
        q = prob.new_conf()
        prob.add("pushable", push.params.obj, p, shelf, u, end, q)
        return [u, end, q]
    exhausted.add(inst)
    return []
