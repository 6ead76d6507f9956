"""Fast Downward through unified-planning: the paper's algorithmic (search-based) planner.

It writes demonstrations for the learned planner and is the search baseline that the learned
planner is timed against.
"""

from __future__ import annotations

import contextlib
import tempfile
import time
from collections.abc import Iterable
from dataclasses import dataclass

import unified_planning as up
from unified_planning.engines import PlanGenerationResultStatus as Status
from unified_planning.shortcuts import OneshotPlanner

from hsgplan.domain.actions import Action, intended_literal
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import Goal
from hsgplan.planning.base import TaskDecision
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.symbolic.pddl import build_problem, decode
from hsgplan.symbolic.transition import apply

up.shortcuts.get_environment().credits_stream = None


class NoPlanError(InvalidInputError):
    """The planner proved the goal unreachable from the state, or gave up within its time."""


@dataclass(frozen=True)
class Plan:
    """A sequence of actions and the symbolic state after each (`states[0]` is the start).

    `seconds` is the planner's wall time, translation and search included.
    """

    actions: tuple[Action, ...]
    states: tuple[SymbolicSceneGraph, ...]
    seconds: float
    planner: str

    def __len__(self) -> int:
        return len(self.actions)


# Weighted A* (w=2) over the FF heuristic with preferred operators: as fast as LAMA's first
# solution here but with plans close to optimal (LAMA's were up to 40% longer on 6 objects),
# while A* with LM-cut gives shortest plans but stops scaling past 8 objects.
SATISFICING_SEARCH = "let(hff,ff(),lazy_wastar([hff],preferred=[hff],w=2))"


# Up to this many objects A* with LM-cut answers within about half a second (measured by
# `hsgplan bench symbolic`), so `optimal=None` buys shortest plans there at little cost.
AUTO_OPTIMAL_MAX_OBJECTS = 6


class FastDownwardPlanner:
    """Plans with Fast Downward.

    Args:
        optimal: True for shortest plans (A* with LM-cut); False for weighted A* with FF,
            which scales to 12 objects but may take detours; None (default) for the former
            up to `AUTO_OPTIMAL_MAX_OBJECTS` objects in the scene and the latter beyond.
        timeout_s: wall time after which planning gives up with `NoPlanError`.
    """

    def __init__(self, optimal: bool | None = None, timeout_s: float = 60.0) -> None:
        self.optimal = optimal
        self.timeout_s = timeout_s
        self.name = {None: "fd-auto", True: "fd-optimal", False: "fd-wastar"}[optimal]

    def _optimal_for(self, state: SymbolicSceneGraph) -> bool:
        if self.optimal is None:
            return len(state.objects) <= AUTO_OPTIMAL_MAX_OBJECTS
        return self.optimal

    def _engine(self, optimal: bool):
        if optimal:
            return OneshotPlanner(name="fast-downward-opt")
        return OneshotPlanner(
            name="fast-downward", params={"fast_downward_search_config": SATISFICING_SEARCH}
        )

    def plan(self, state: SymbolicSceneGraph, goal: Goal, banned: Iterable[Action] = ()) -> Plan:
        """Plan from the state to the goal, using none of the `banned` ground actions; every
        step is replayed in the transition model."""
        start = time.perf_counter()
        missing = [o for o in goal.objects if o not in state.objects]
        if missing:
            raise InvalidInputError(f"the goal names '{missing[0]}', which is not in the scene")
        if goal.satisfied_by(state):
            return Plan((), (state,), time.perf_counter() - start, self.name)
        problem = build_problem(state, goal, banned).problem
        optimal = self._optimal_for(state)
        # Fast Downward's driver writes `output.sas` into the working directory: planners
        # running side by side (test workers, data-collection pools) must not share one.
        with (
            tempfile.TemporaryDirectory(prefix="hsgplan-fd-") as tmp,
            contextlib.chdir(tmp),
            self._engine(optimal) as engine,
        ):
            result = engine.solve(problem, timeout=self.timeout_s)
        seconds = time.perf_counter() - start
        if result.status not in (Status.SOLVED_SATISFICING, Status.SOLVED_OPTIMALLY):
            reason = {
                Status.UNSOLVABLE_PROVEN: "no sequence of pick, place and push reaches it",
                Status.TIMEOUT: f"no plan found within {self.timeout_s:.0f} s",
            }.get(result.status, f"the planner stopped with {result.status.name}")
            raise NoPlanError(f"goal '{goal}' from '{state}': {reason}")
        actions = tuple(
            decode(a.action.name, [str(p) for p in a.actual_parameters])
            for a in result.plan.actions
        )
        states = [state]
        for a in actions:
            states.append(apply(states[-1], a))
        return Plan(actions, tuple(states), seconds, "fd-optimal" if optimal else "fd-wastar")


class FastDownwardTaskPlanner:
    """Fast Downward behind the task-planner interface: the next action of its plan, serving
    the literal that action makes true.

    With `follow_plan` (the default) it compares the observed state with the state its plan
    predicted and goes on with the rest of the plan while they agree (a suffix of a shortest
    plan is a shortest plan from there, so Fast Downward would answer the same), planning
    again only when the world departs from it; without, it plans from every state.
    """

    name = "fd"

    def __init__(self, follow_plan: bool = True, planner: FastDownwardPlanner | None = None):
        self.planner = planner or FastDownwardPlanner()
        self.follow_plan = follow_plan
        self.plan: Plan | None = None

    def reset(self, goal: Goal | None, seed: int) -> None:
        self.plan = None

    def next_action(self, state: SymbolicSceneGraph, goal: Goal) -> TaskDecision:
        start = time.perf_counter()
        plan = self._remaining(state) if self.follow_plan else None
        if plan is None:
            try:
                plan = self.plan = self.planner.plan(state, goal)
            except NoPlanError as e:
                return TaskDecision(None, None, time.perf_counter() - start, f"no plan: {e}")
        if not plan.actions:
            return TaskDecision(None, None, time.perf_counter() - start, "the goal holds")
        action = plan.actions[0]
        following = plan.actions[1] if len(plan.actions) > 1 else None
        seconds = time.perf_counter() - start
        return TaskDecision(action, intended_literal(action), seconds, following=following)

    def _remaining(self, state: SymbolicSceneGraph) -> Plan | None:
        """The rest of the current plan, if the state is one the plan passes through."""
        if self.plan is None or state not in self.plan.states[:-1]:
            return None
        i = self.plan.states.index(state)
        return Plan(self.plan.actions[i:], self.plan.states[i:], 0.0, self.plan.planner)
