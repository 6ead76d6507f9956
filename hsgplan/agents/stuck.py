"""When the task planner finds nothing: the goal's own literals, offered to the checks.

The regression planner stops ("regression stuck") when f_reach finds every literal it regressed
to out of reach. In scenes more crowded than those it learned from it does so on a last goal
literal or two whose primitives the motion planner finds in reach: a box to take from a shelf
top holding five others. Under the recovery rule `stuck_goal_literals` an agent that checks its
actions (`agents/hierarchical.py`) then offers, for each goal literal that does not hold, in the
goal's order, the action the paper's heuristic names for it (`planning/heuristic.py`), taking
up first an object that must be moved and is not held, to the same checks as the planner's
actions. What it reads: the goal, the observed state and what the hand holds; no domain rule.
"""

from __future__ import annotations

from dataclasses import dataclass

from hsgplan.domain.actions import Action, Pick, Place, Push
from hsgplan.domain.goals import Goal
from hsgplan.domain.predicates import Literal, in_grasp, on
from hsgplan.planning.heuristic import action_for
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph


@dataclass(frozen=True)
class GoalAction:
    """An action offered for a goal literal, the action it is for (a pick's place, a place's
    push) and the literal it serves next."""

    action: Action
    following: Action | None
    subgoal: Literal


def goal_actions(state: SymbolicSceneGraph, goal: Goal, held: str | None) -> list[GoalAction]:
    """The actions offered for the goal's unsatisfied literals, in the goal's order; none for a
    literal that needs the hand while it holds another object."""
    out: list[GoalAction] = []
    for lit in goal.unsatisfied(state):
        action, subgoal = action_for(lit, state), lit
        if isinstance(action, Push):
            prepush = state.world.shelves[action.shelf].prepush
            if prepush is None:
                continue
            if not state.holds(on(action.obj, prepush)):  # put there to be pushed
                action, subgoal = Place(action.obj, prepush), on(action.obj, prepush)
        if isinstance(action, Place) and held != action.obj:
            if held is None:
                out.append(GoalAction(Pick(action.obj), action, in_grasp(action.obj)))
            continue
        if action is not None and (held is None or isinstance(action, Place)):
            out.append(GoalAction(action, None, subgoal))
    return list(dict.fromkeys(out))
