"""What every task planner offers the agent: the next action for a symbolic state and a goal,
with the subgoal it serves.

Task planners are the learned regression planner and the forward baseline
(`planning/regression/planner.py`, `forward.py`) and Fast Downward
(`planning/fast_downward.py`); the registry (`hsgplan.agents.registry`) names them.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Protocol

from hsgplan.domain.actions import Action, push_after
from hsgplan.domain.goals import Goal
from hsgplan.domain.predicates import Literal
from hsgplan.domain.scene import World
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph


@dataclass(frozen=True)
class TaskDecision:
    """The next action (None with a reason when there is none), the subgoal it serves, the time
    the decision took, and the action the planner expects to take after it where it knows one
    (the motion level uses it: a place that a push follows puts the object where the push can
    start)."""

    action: Action | None
    subgoal: Literal | None
    seconds: float
    note: str = ""
    following: Action | None = None

    @staticmethod
    def none(note: str, start: float) -> TaskDecision:
        """No action, and why, decided since `start` (`time.perf_counter`)."""
        return TaskDecision(None, None, time.perf_counter() - start, note)

    @staticmethod
    def taken(action: Action, subgoal: Literal, start: float, world: World) -> TaskDecision:
        """`action` for `subgoal`, decided since `start` (`time.perf_counter`), with the push
        that follows it where it is a place onto a prepush region."""
        seconds = time.perf_counter() - start
        return TaskDecision(action, subgoal, seconds, following=push_after(action, world))


class TaskPlanner(Protocol):
    name: str

    def reset(self, goal: Goal, seed: int) -> None:
        """A new episode towards `goal`, seeded."""

    def next_action(
        self, state: SymbolicSceneGraph, goal: Goal, refused: frozenset[Action] = frozenset()
    ) -> TaskDecision:
        """The next action from `state` towards `goal`, never one of `refused` (actions an
        agent found it cannot carry out from here: it asks again without them)."""
