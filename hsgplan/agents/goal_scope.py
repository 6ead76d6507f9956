"""The goals each agent is for, checked before an episode starts.

An agent whose task planner is learned (every `regression` variant and the forward baseline)
learned from the goals the generator draws (`symbolic/generator.py`): `On` and `In` literals,
none negated. Outside them it has nothing to go on (a negated literal or `InGrasp` is a
subgoal its networks never regressed) and would act until the step limit; so such a goal is
refused in one line before anything runs, naming the planner that takes it. The agents that
plan with the rules (`oracle`, `search` and the stream baselines: Fast Downward over the
domain) take every literal the goal grammar allows (`docs/cli.md`, "Goals"). Every goal, of
every agent and command, names 2 to 12 objects (`symbolic.generator.check_size`).
"""

from __future__ import annotations

from dataclasses import dataclass

from hsgplan.agents.registry import LEARNED_PLANNERS, WHOLE_AGENTS, agent_parts
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import Goal
from hsgplan.domain.predicates import Predicate
from hsgplan.symbolic.generator import check_size


@dataclass(frozen=True)
class GoalScope:
    """What goals an agent takes: the predicates of its literals, and whether one may be
    negated."""

    predicates: frozenset[Predicate]
    negated: bool

    def problem(self, goal: Goal) -> str | None:
        """Why the goal is not one of these, in a few words; None when it is."""
        for lit in sorted(goal.literals, key=str):
            if lit.predicate not in self.predicates:
                return f"it has {lit.predicate.value} literals"
            if not lit.positive and not self.negated:
                return "it has negated literals"
        return None


LEARNED_GOALS = GoalScope(frozenset({Predicate.ON, Predicate.IN}), negated=False)
PLANNED_GOALS = GoalScope(frozenset(Predicate), negated=True)


def scope_of(agent: str) -> GoalScope:
    """The goals an agent (a registered name or `PLANNER+MOTION`) is for."""
    if agent in WHOLE_AGENTS:
        return PLANNED_GOALS
    return planner_scope(agent_parts(agent)[0])


def planner_scope(planner: str) -> GoalScope:
    """The goals a task planner is for."""
    return LEARNED_GOALS if planner in LEARNED_PLANNERS else PLANNED_GOALS


def goal_refusal(who: str, scope: GoalScope, goal: Goal, instead: str) -> str | None:
    """The one line that refuses a goal outside `who`'s scope (an agent's or a task
    planner's), pointing at `instead`; None when it is inside."""
    why = scope.problem(goal)
    if why is None:
        return None
    literals = " and ".join(p.value for p in Predicate if p in scope.predicates)
    takes = f"{literals} literals{'' if scope.negated else ', none negated'}"
    return f"{who} is not for this goal ({why}): it takes {takes}; {instead} takes it"


def check_goal(agent: str, goal: Goal) -> None:
    """Refuse, in one line, a goal of a size no command runs or one the agent is not for."""
    check_size(goal.size)
    if why := goal_refusal(f"the agent '{agent}'", scope_of(agent), goal, "the agent 'oracle'"):
        raise InvalidInputError(why)


def check_planner_goal(planner: str, goal: Goal) -> None:
    """The same for a task planner alone (`eval task`)."""
    check_size(goal.size)
    who = f"the task planner '{planner}'"
    if why := goal_refusal(who, planner_scope(planner), goal, "the task planner 'fd'"):
        raise InvalidInputError(why)
