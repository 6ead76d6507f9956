"""PDDLStream's incremental algorithm (Garrett et al., 2020) over the kitchen-storage streams.

Level 0 is what is observed: each object's pose (`(atpose o p0)`, with how it rests there) or
its grasp. Every level then evaluates each stream once on every combination of inputs that
existed when the level began (a sampler gives its next few samples; a stream is not evaluated
twice on the same inputs), adds what the streams certified as new objects and facts, tests
every new pose against every other object's poses (the collision test, cheap, at once) and asks
Fast Downward for a plan over all of it (`symbolic/stream_pddl.py`). A plan is returned as the
project's actions and their parameters; no plan means one level deeper, with more samples and
the last level's outputs as new inputs. The streams (`agents/streams.py`):

- grasp(o) -> g: the top-down grasp (one per object);
- place-pose(o, surface) -> p: the next place bins, `place_samples` a level (`goal_place_samples`
  on the surface the goal puts o on);
- stack-pose(o, b, pb) -> p: o on b's top at b's pose pb;
- kin(o, p, g) -> q: inverse kinematics and a path for the grasp at p (not for poses inside a
  shelf, from which nothing is taken up);
- push(o, p, shelf) -> (u, p2, q): pushes from a prepush pose into the shelf's slots.

Evaluated on every input (`stream`, the default), the streams make the problem explode with
the levels, the stack poses fastest (one per object on every pose of every other object): the
third level of a 6-object goal held some 2,000 poses and 240,000 facts, and 8- and 10-object
goals found no plan within the limits. As PDDLStream's users write streams with what they know
of the domain, `GOAL_DIRECTED` (the `stream-goal` baseline) takes two streams' inputs from the
goal (`goal_stacks`, `goal_places`):

- stack-pose(o, b, pb) only where the goal has On(o, b), and only on poses pb where b's own
  On goal (if it has one) would have it. A tower the goal does not name is never needed: the
  open space alone holds every object a goal may name (12 cells, its `surface_capacity`, and
  `MAX_OBJECTS` 12), nothing starts held or in an interior (`symbolic/generator.py`), so any
  object can wait there; an observed tower stays at its observed poses (level 0).
- place-pose(o, s) only on the open space (where anything waits) and on o's goal surface, or
  the prepush region of the shelf its In goal names; every surface for an object the goal
  does not place.

Measured on 6- to 10-object goals with those streams, a level with a plan had it from Fast
Downward within 1.2 s; a level without one (no collision-free arrangement of the goal's poses
among its samples, checked by enumeration) ran until `fd_timeout_s`, the search unable to prove
there is none (the FF heuristic does not see collisions). So `GOAL_DIRECTED` bounds a call at
10 s and allows more levels, and samples more poses on the goal's surface a level (the shelf
tops are where arrangements are tight), which makes the levels without a plan fewer. The
problem's size is bounded too (`max_facts`).

Times: the task level is Fast Downward's (writing the problem, translation and search), the
motion level the streams' (sampling, inverse kinematics, push planning, collision tests) and
turning the plan into parameters.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

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
from hsgplan.symbolic.stream_pddl import DOMAIN, STREAM_SEARCH, problem_text


@dataclass(frozen=True)
class IncrementalConfig:
    """Args:
    place_samples: new poses per object and surface at each level.
    goal_place_samples: new poses per object on the surface its goal names, or the prepush
        region of the shelf its In goal names (`goal_places`).
    push_samples: new pushes per prepush pose and shelf at each level.
    max_levels: levels before the planner gives up.
    max_facts: facts a problem may hold; past them the planner gives up rather than write it
        (the level after one of 290,000 facts held 3.8 million, 180 MB of PDDL, which Fast
        Downward's translator did not read within a minute).
    time_limit_s: seconds (streams and Fast Downward together) before it gives up.
    fd_timeout_s: seconds one Fast Downward call may take.
    goal_stacks: stack-pose(o, b, pb) only for the goal's On(o, b), on b's poses where b's
        own goal has it (the module docstring says why nothing is lost).
    goal_places: place-pose(o, s) only on the open space and o's goal surface.
    """

    place_samples: int = 2
    push_samples: int = 1
    max_levels: int = 5
    max_facts: int = 1_000_000
    time_limit_s: float = 900.0
    fd_timeout_s: float = 60.0
    goal_stacks: bool = False
    goal_places: bool = False
    goal_place_samples: int = 4


# The `stream-goal` baseline's settings (the module docstring says why).
GOAL_DIRECTED = IncrementalConfig(
    max_levels=12, fd_timeout_s=10.0, goal_stacks=True, goal_places=True
)


class IncrementalPlanner:
    """Args:
    config: samples per level and the limits (`IncrementalConfig`).
    """

    def __init__(self, config: IncrementalConfig | None = None) -> None:
        self.config = config or IncrementalConfig()

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
        motion += time.perf_counter() - t0
        for level in range(1, cfg.max_levels + 1):
            if time.perf_counter() - start > cfg.time_limit_s:
                return StreamPlan(None, task, motion, level - 1, len(prob.facts), "time limit")
            t0 = time.perf_counter()
            self._evaluate(prob, level, world, banned)
            motion += time.perf_counter() - t0
            if len(prob.facts) > cfg.max_facts:
                return StreamPlan(None, task, motion, level, len(prob.facts), "too many facts")
            t0 = time.perf_counter()
            try:
                text = problem_text(pddl_objects(prob, state), prob.facts, goal)
                found = solve_pddl(DOMAIN, text, STREAM_SEARCH, cfg.fd_timeout_s)
            except NoPlanError:
                task += time.perf_counter() - t0
                continue
            task += time.perf_counter() - t0
            t0 = time.perf_counter()
            steps = tuple(decode_step(prob, name, args) for name, args in found.steps)
            motion += time.perf_counter() - t0
            return StreamPlan(steps, task, motion, level, len(prob.facts))
        return StreamPlan(None, task, motion, cfg.max_levels, len(prob.facts), "level limit")

    def _evaluate(
        self,
        prob: StreamProblem,
        level: int,
        world: StreamWorld,
        banned: frozenset[PrimitiveParams],
    ) -> None:
        """Every stream once on the inputs that existed before this level."""
        cfg = self.config
        poses = [p for p in prob.poses if prob.level[p] < level]
        objects = sorted({v.obj for v in prob.poses.values()} | set(prob.grasps))
        grasped = {o for o, g in prob.grasps.items() if prob.level[g] < level}
        for o in objects:
            if o not in prob.grasps:
                add_grasp(prob, o, level)
        for o in objects:
            for s, samples in place_surfaces(prob, o, cfg):
                order = prob.bins.setdefault((o, s), bin_order(o, s, prob.rng, prob.world))
                for _ in range(min(samples, len(order))):
                    prob.new_pose(surface_pose(o, s, order.pop(0), prob.world), level)
        for pb in poses:
            for o in stackable(prob, prob.poses[pb], objects):
                if ("stack", o, pb) in prob.done:
                    continue
                prob.done.add(("stack", o, pb))
                value = stack_pose(o, prob.poses[pb])
                if value is not None:
                    prob.new_pose(value, level, below=pb)
        for p in poses:
            v = prob.poses[p]
            if v.obj in grasped and ("kin", p) not in prob.done and v.relation != "inside":
                prob.done.add(("kin", p))
                params = params_at(prob, p)
                if params is None or params not in banned:
                    q = world.kin(v)
                    if q is not None:
                        prob.add("kin", v.obj, p, prob.grasps[v.obj], prob.new_conf())
        for p in poses:
            shelf = push_shelf(prob.poses[p])
            if shelf is None:
                continue
            stream = prob.push_streams.setdefault((p, shelf), world.pushes(prob.poses[p], shelf))
            taken = 0
            for push, _ in stream:
                if push.params in banned:
                    continue
                u = f"u{len(prob.pushes)}"
                prob.pushes[u] = push
                end = prob.new_pose(push.end, level)
                prob.add("pushable", push.params.obj, p, shelf, u, end, prob.new_conf())
                taken += 1
                if taken >= cfg.push_samples:
                    break


def place_surfaces(prob: StreamProblem, obj: str, cfg: IncrementalConfig) -> list[tuple[str, int]]:
    """The surfaces place-pose samples for an object, and how many poses on each a level:
    with `goal_places`, the open space (where anything may wait) and the surface the goal
    puts it on, or the prepush region of the shelf its In goal names."""
    goal = goal_surface(prob, obj)
    if not cfg.goal_places or goal is None:
        return [(s, cfg.place_samples) for s in prob.world.surfaces]
    wanted = [("open_space", cfg.place_samples)]
    if goal in prob.world.surfaces and goal != "open_space":
        wanted.append((goal, cfg.goal_place_samples))
    return wanted
