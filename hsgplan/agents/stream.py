"""The PDDLStream-style baselines: PDDLStream's incremental algorithm (`agents/incremental.py`)
or its focused one (`agents/focused.py`) plans over poses, grasps, configurations and pushes
that streams sample with the project's geometry and robot (`agents/streams.py`), Fast Downward
searching the grounded problems (`symbolic/stream_pddl.py`).

The agent plans once, from what it observes, and executes the plan step by step; when the
world departs from it (a primitive fails or the state is not the one the plan expects) it
plans again from what it observes then. A primitive that failed is left out of the next plan
while the scene is the one it failed in (every pose to the centimetre), so the planner does not
propose it again: it samples afresh (another seed) and must find another way.

Times: the task level is Fast Downward's (writing each level's problem, translation and
search), the motion level the streams' (sampling, inverse kinematics, push planning, collision
tests) and turning the plan into parameters.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from hsgplan.agents.base import Decision
from hsgplan.agents.incremental import IncrementalPlanner
from hsgplan.agents.stream_problem import StreamPlanner
from hsgplan.agents.streams import StreamWorld
from hsgplan.domain.actions import Action, intended_literal
from hsgplan.domain.goals import Goal
from hsgplan.domain.parameters import PrimitiveParams
from hsgplan.domain.predicates import Predicate
from hsgplan.motion.interface import Feasibility
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.lookahead import Lookahead
from hsgplan.sim.outcome import Outcome

SceneKey = tuple  # the held object and every pose, to the centimetre


@dataclass(frozen=True)
class Step:
    action: Action
    params: PrimitiveParams
    before: SymbolicSceneGraph  # the state the plan expects this step to start from


class StreamAgent:
    """Args:
    planner: the algorithm (`IncrementalPlanner`, the default, or `FocusedPlanner`) with its
        streams and limits.
    name: the agent's name in records (`agents/registry.py`'s `WHOLE_AGENTS`).
    """

    def __init__(self, planner: StreamPlanner | None = None, name: str = "stream") -> None:
        self.name = name
        self.planner = planner or IncrementalPlanner()
        self.reset(None, 0)

    def reset(self, goal: Goal | None, seed: int) -> None:
        self._queue: list[Step] = []
        self._seed = seed
        self._plans = 0
        self._failed: dict[SceneKey, set[PrimitiveParams]] = {}
        self._last: SceneKey = ()

    def observe(self, params: PrimitiveParams, outcome: Outcome) -> None:
        if not outcome.ok:
            self._queue = []
            self._failed.setdefault(self._last, set()).add(params)

    def decide(
        self,
        sg: GeometricSceneGraph,
        state: SymbolicSceneGraph,
        goal: Goal,
        feasible: Feasibility | None = None,
    ) -> Decision:
        self._last = scene_key(sg)
        if self._queue and self._queue[0].before == state:
            step = self._queue.pop(0)
            return Decision(step.action, step.params, 0.0, 0.0, "", intended_literal(step.action))
        if not isinstance(feasible, Lookahead):
            return Decision(None, None, 0.0, 0.0, "the stream baseline needs the world's scene")
        banned = frozenset(self._failed.get(self._last, ()))
        # a fresh draw of every sampler for every plan: a replan does not repeat the last one
        seed = self._seed * 1_000 + self._plans
        self._plans += 1
        with feasible.trial() as trial:
            found = self.planner.plan(sg, state, goal, StreamWorld(trial.scene), seed, banned)
        task, motion = found.task_seconds, found.motion_seconds
        if found.steps is None:
            note = f"no plan within {found.levels} levels ({found.note})"
            return Decision(None, None, task, motion, note)
        if not found.steps:
            return Decision(None, None, task, motion, "the goal holds")
        states = [state]
        for s in found.steps[:-1]:
            states.append(expected_after(states[-1], s.action))
        self._queue = [
            Step(s.action, s.params, b) for s, b in zip(found.steps, states, strict=True)
        ]
        step = self._queue.pop(0)
        return Decision(step.action, step.params, task, motion, "", intended_literal(step.action))


def expected_after(state: SymbolicSceneGraph, action: Action) -> SymbolicSceneGraph:
    """The symbolic state an action of a stream plan leads to: the object where the action
    takes it, everything else as it was. The plan's poses, not the transition model's counts,
    decide what is possible, so the world's limits are not checked here."""
    placements = {
        lit
        for lit in state.literals
        if lit.predicate is not Predicate.CLEAR and lit.subject != action.obj
    }
    placements.add(intended_literal(action))
    return SymbolicSceneGraph.from_literals(
        state.objects, placements, limits=False, world=state.world
    )


def scene_key(sg: GeometricSceneGraph) -> SceneKey:
    poses = tuple((n.name, *(round(v, 2) for v in n.pose.position)) for n in sg.nodes)
    return (sg.held, poses)


def make_stream_agent(name: str) -> StreamAgent:
    """A PDDLStream-style baseline by its registered name (`agents/registry.py`)."""
    from hsgplan.agents.focused import FOCUSED_GOAL_DIRECTED, FocusedPlanner
    from hsgplan.agents.incremental import GOAL_DIRECTED

    planners: dict[str, Callable[[], StreamPlanner]] = {
        "stream": IncrementalPlanner,
        "stream-goal": lambda: IncrementalPlanner(GOAL_DIRECTED),
        "stream-focused": FocusedPlanner,
        "stream-focused-goal": lambda: FocusedPlanner(FOCUSED_GOAL_DIRECTED),
    }
    return StreamAgent(planners[name](), name)
